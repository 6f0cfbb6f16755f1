"""The command line renders the sample headlessly and fails with one clear line and exit 2."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from studio.cli import main
from studio.core.sample.synthetic import make_test_face
from studio.render.offscreen import default_camera
from tests.regions import landmark_pixels, region_difference

SIZE = (360, 270)
TEST_FACE = ("--vertices", "2172")  # the procedural test face, whose regions are known


def render_png(tmp_path, *args: str) -> np.ndarray:
    out = tmp_path / f"{'_'.join(a.strip('-') for a in args)}.png"
    size = f"{SIZE[0]}x{SIZE[1]}"
    assert main(["render", *TEST_FACE, *args, "--size", size, "-o", str(out)]) == 0
    image = np.asarray(Image.open(out).convert("RGB"))
    assert image.shape == (SIZE[1], SIZE[0], 3)
    return image


@pytest.fixture(scope="module")
def marks():
    project = make_test_face()
    return landmark_pixels(project, default_camera(project), *SIZE)


def test_surprise_t2_differs_from_none_on_forehead_not_chin(tmp_path, marks):
    t2 = render_png(tmp_path, "--technique", "t2", "--pose", "surprise")
    none = render_png(tmp_path, "--technique", "none", "--pose", "surprise")
    assert region_difference(t2, none, marks["forehead"]) > 4.0
    assert region_difference(t2, none, marks["chin"]) < 0.5


def test_squeeze_t2_differs_at_both_eye_corners_seen_from_the_front(tmp_path):
    project = make_test_face()
    camera = default_camera(project)
    camera.yaw = 0.0
    front = landmark_pixels(project, camera, *SIZE)
    t2 = render_png(tmp_path, "--technique", "t2", "--pose", "squeeze", "--yaw", "0")
    none = render_png(tmp_path, "--technique", "none", "--pose", "squeeze", "--yaw", "0")
    assert region_difference(t2, none, front["eye corner right"]) > 4.0
    assert region_difference(t2, none, front["eye corner left"]) > 4.0
    assert region_difference(t2, none, front["chin"]) < 0.5


def test_neutral_t1_and_t2_equal_none(tmp_path):
    none = render_png(tmp_path, "--technique", "none")
    assert np.array_equal(render_png(tmp_path, "--technique", "t1"), none)
    assert np.array_equal(render_png(tmp_path, "--technique", "t2"), none)


def test_vertices_picks_the_sample_resolution(tmp_path):
    wired = render_png(tmp_path, "--vertices", "561", "--wireframe", "--technique", "none")
    fine = render_png(tmp_path, "--vertices", "5151", "--wireframe", "--technique", "none")
    # the coarse mesh has fewer edges to draw, so less of the face is darkened by them
    assert wired.mean() > fine.mean()


@pytest.mark.parametrize(("args", "needle"), [
    (["--pose", "grin"], "unknown pose 'grin'"),
    (["--size", "12xfoo"], "12xfoo"),
    (["--size", "0x10"], "0x10"),
    (["--weight", "3"], "--weight"),
    (["--vertices", "7"], "7"),
    (["--technique", "t3"], "t3"),
    (["--relief", "bumpy"], "bumpy"),
    (["--relief", "displace", "--relief-depth", "-1"], "-1"),
    (["--relief-depth", "deep"], "deep"),
])
def test_bad_arguments_give_one_line_and_exit_code_2(tmp_path, capsys, args, needle):
    with pytest.raises(SystemExit) as exit_info:
        code = main(["render", *args, "-o", str(tmp_path / "x.png")])
        raise SystemExit(code)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert needle in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.png").exists()


def test_missing_project_file_is_one_line(tmp_path, capsys):
    assert main(["render", str(tmp_path / "nope.wrinkle"), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert "nope.wrinkle" in err and len(err.splitlines()) == 1


def test_real_process_exit_code(tmp_path):
    result = subprocess.run([sys.executable, "-m", "studio.cli", "render", "--pose", "grin",
                             "-o", str(tmp_path / "x.png")], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.strip().startswith("wrinkle-studio: error:")


def test_render_with_displaced_wrinkles_writes_a_png_whose_profile_differs(tmp_path):
    profile = ("--technique", "t2", "--pose", "surprise", "--yaw", "90", "--pitch", "0")
    plain = render_png(tmp_path, *profile)
    displaced = render_png(tmp_path, *profile, "--relief", "displace", "--relief-depth", "0.06")
    parallax = render_png(tmp_path, *profile, "--relief", "parallax")
    assert not np.array_equal(displaced, plain) and not np.array_equal(parallax, plain)
    # the neutral face has no wrinkles to raise
    neutral = render_png(tmp_path, "--technique", "t2")
    assert np.abs(render_png(tmp_path, "--technique", "t2", "--relief", "displace").astype(int)
                  - neutral).max() <= 1

