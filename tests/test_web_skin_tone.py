"""The web page's skin look carries each wrinkled map's cavity and colour (issue 46, point 4):
``export --web --look skin`` against ``render --look skin`` of the same pose, in headless
Chromium (see tests/test_web_player.py), within the tolerance the page and the studio are held
to without wrinkles, and the tone changes the same pixels on the page as in the studio."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from scripts.web_picture import changed
from studio.cli import main
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.skin_tone import cavity_map
from tests.test_web_player import open_page, overlap, pixels

SIZE = 800
POSE = "squeeze"
FLUSH = (128, 80, 76)  # a colour map that reddens what its map's weight reaches


def shots(tmp: Path, project, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(the page's, the studio's) skin look at the pose, technique 1."""
    project_file = tmp / f"{name}.wrinkle"
    save_project(project, project_file, backup=False)
    assert main(["export", str(project_file), "--web", str(tmp / name), "--look", "skin"]) == 0
    shot = tmp / f"{name}_page.png"
    open_page(tmp / name / "index.html", f"pose={POSE}&weight=1&technique=t1&ui=0", shot)
    render = tmp / f"{name}_studio.png"
    assert main(["render", str(project_file), "--pose", POSE, "--weight", "1", "--technique",
                 "t1", "--look", "skin", "--size", f"{SIZE}x{SIZE}", "--frame", "face",
                 "--yaw", "0", "-o", str(render)]) == 0
    return pixels(shot), pixels(render)


@pytest.fixture(scope="module")
def pictures(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("web_tone")
    plain = make_test_face(2172)
    toned = make_test_face(2172)
    textures = toned.textures
    for name, image in textures.wrinkle_maps.items():
        colour = np.empty((64, 64, 3), np.uint8)
        colour[...] = FLUSH
        textures.set_tone(name, cavity_map(textures.normal_neutral, image), colour)
    return shots(tmp, plain, "plain"), shots(tmp, toned, "toned")


def test_the_page_s_skin_look_with_cavity_and_colour_is_the_studio_s(pictures):
    _, (page, studio) = pictures
    assert changed(page, studio).mean() < 0.005


def test_the_tone_changes_the_same_pixels_on_the_page_as_in_the_studio(pictures):
    (page_plain, studio_plain), (page, studio) = pictures
    in_studio = changed(studio, studio_plain)
    on_page = changed(page, page_plain)
    assert in_studio.mean() > 0.003
    assert overlap(on_page, in_studio) > 0.8
