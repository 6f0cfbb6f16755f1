"""The command line renders the timeline's animation: numbered frames, an animated GIF, and
one-line errors for ranges and outputs it cannot use."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from studio.cli import main
from studio.core.sample.synthetic import make_test_face
from studio.render.offscreen import default_camera
from tests.regions import landmark_pixels, region_difference
from tests.test_cli import TEST_FACE

SIZE = (240, 180)


@pytest.fixture(scope="module")
def marks():
    project = make_test_face()
    return landmark_pixels(project, default_camera(project), *SIZE)


def render(tmp_path, technique: str, frames: str, name: str) -> list:
    pattern = tmp_path / name / "frame_%04d.png"
    assert main(["render", *TEST_FACE, "--technique", technique, "--frames", frames, "--size",
                 f"{SIZE[0]}x{SIZE[1]}", "-o", str(pattern)]) == 0
    return sorted((tmp_path / name).iterdir())


def load(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def test_frames_0_12_4_are_three_numbered_pngs_where_the_wrinkles_rise(tmp_path, marks, capsys):
    # the sample's animation opens with the right brow raise: 0 at frame 0, full at frame 12,
    # linked (technique 1) to the forehead-right area
    t1 = render(tmp_path, "t1", "0:12:4", "t1")
    assert [p.name for p in t1] == ["frame_0000.png", "frame_0004.png", "frame_0008.png"]
    assert "3 frames" in capsys.readouterr().out
    none = render(tmp_path, "none", "0:12:4", "none")
    images = [load(p) for p in t1]
    plain = [load(p) for p in none]
    assert all(i.shape == (SIZE[1], SIZE[0], 3) for i in images)
    # at frame 0 the face is neutral: no wrinkles anywhere
    assert np.array_equal(images[0], plain[0])
    # by frame 8 the wrinkles show on the raised side of the forehead, not on the chin
    assert region_difference(images[2], plain[2], marks["forehead right"]) > 2.0
    assert region_difference(images[2], plain[2], marks["chin"]) == 0.0
    # and they grow over the frames
    grow = [region_difference(i, p, marks["forehead right"]) for i, p in zip(images, plain,
                                                                               strict=True)]
    assert grow[0] < grow[1] < grow[2]


def test_gif_has_one_frame_per_rendered_frame(tmp_path, capsys):
    out = tmp_path / "anim" / "surprise.gif"
    # the surprise rises from frame 72 to 84: every rendered frame differs
    assert main(["render", *TEST_FACE, "--technique", "t2", "--frames", "72:85:4", "--size",
                 "120x90", "--gif", str(out)]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 4
        assert gif.is_animated
        assert abs(gif.info["duration"] - 1000 * 4 / 24) < 10  # GIF counts in 1/100 s
        assert gif.size == (120, 90)
    assert str(out) in capsys.readouterr().out


@pytest.mark.parametrize(("args", "needle"), [
    (["--frames", "12:4"], "12:4"),
    (["--frames", "0:10:0"], "step"),
    (["--frames", "a:b"], "a:b"),
    (["--frames", "7"], "'7'"),
    (["--frames", "0:4", "-o", "OUT/frame.png"], "frame_%04d"),
    (["--frames", "0:4"], "-o"),
])
def test_bad_frame_ranges_and_outputs_are_one_line_and_exit_2(tmp_path, capsys, args, needle):
    args = [a.replace("OUT", str(tmp_path)) for a in args]
    with pytest.raises(SystemExit) as exit_info:
        raise SystemExit(main(["render", *TEST_FACE, *args, "--size", "64x48"]))
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_project_without_animation_says_so(tmp_path, capsys):
    from studio.core.animation.timeline import Timeline
    from studio.core.project.writer import save_project

    project = make_test_face(561, 64, 32)
    project.timeline = Timeline()
    path = tmp_path / "still.wrinkle"
    save_project(project, path)
    assert main(["render", str(path), "--frames", "0:4", "-o",
                 str(tmp_path / "f_%02d.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert "no animation" in err and len(err.splitlines()) == 1


def test_video_without_imageio_ffmpeg_is_one_line(tmp_path, capsys, monkeypatch):
    import studio.commands.render as render_command

    monkeypatch.setattr(render_command, "video_available", lambda: False)  # as if missing
    assert main(["render", *TEST_FACE, "--video", str(tmp_path / "a.mp4"), "--size", "64x48"]) == 2
    err = capsys.readouterr().err.strip()
    assert "imageio-ffmpeg" in err and len(err.splitlines()) == 1


def test_mp4_export_has_every_frame_at_its_size_and_decodes(tmp_path, capsys):
    """``render --video``: an H.264 MP4 that ffmpeg (imageio-ffmpeg's own) decodes back into
    the rendered frames — their number, size, and the wrinkles rising on the forehead."""
    import imageio_ffmpeg

    out = tmp_path / "surprise.mp4"
    assert main(["render", *TEST_FACE, "--technique", "t2", "--frames", "24:48", "--size", "96x64",
                 "--video", str(out)]) == 0
    assert "frames" in capsys.readouterr().out
    reader = imageio_ffmpeg.read_frames(str(out))
    meta = next(reader)
    assert tuple(meta["size"]) == (96, 64)
    frames = [np.frombuffer(f, np.uint8).reshape(64, 96, 3) for f in reader]
    assert len(frames) == 24
    assert all(f.std() > 10 for f in frames)  # a face, not a blank picture
    assert np.abs(frames[-1].astype(int) - frames[0]).max() > 10  # it moves
