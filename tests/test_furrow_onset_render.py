"""A pose's onset in every technique's render (issue 45, point 6): below the onset weight the
pose moves the face but its lines do not show — the forehead is the unwrinkled render of the
same pose — and above it the lines appear; deforming on the GPU (transform feedback) and with
the numpy reference alike. Rendered on a standalone EGL context."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.furrow_controls import FurrowControls
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.regions import landmark_pixels, region_difference

W, H = 400, 300
CHANGED = 4.0  # region difference (0-255, see regions.py) that counts as a visible change
SAME = 0.5  # ... and below which a region counts as unchanged
SHOWN = 2.0  # half a pose's lines: faint (the automatic mode's at half the compression)
POSE = "surprise"  # raises both brows: the forehead's lines
ONSET = 0.6


@pytest.fixture(params=["gpu", "cpu"])
def studio(request, sample, gl_context, monkeypatch):
    """The sample with an onset on the brow raise, deformed on the GPU or by numpy."""
    monkeypatch.setenv("WRINKLE_DEFORM", request.param)
    sample.furrows = sample.furrows.with_controls(POSE, FurrowControls(onset=ONSET))
    s = OffscreenStudio(sample, W, H, ctx=gl_context)
    assert s.renderer.deforms_on_gpu == (request.param == "gpu")
    yield s
    s.release()


def render(studio: OffscreenStudio, technique: str, weight: float) -> np.ndarray:
    return studio.render(RenderSettings(technique=technique), {POSE: weight})


@pytest.mark.parametrize("technique", ["t1", "t2", "strain"])
def test_below_the_onset_the_pose_moves_without_lines_and_above_it_they_appear(studio,
                                                                             technique):
    forehead = landmark_pixels(studio.scene.project, studio.camera, W, H)["forehead"]
    below = 0.5
    assert region_difference(render(studio, technique, below), render(studio, "none", below),
                             forehead) < SAME
    # the pose did move: the unwrinkled forehead at 0.5 is not the neutral's
    assert region_difference(render(studio, "none", below), render(studio, "none", 0.0),
                             forehead) > SAME
    assert region_difference(render(studio, technique, 1.0), render(studio, "none", 1.0),
                             forehead) > CHANGED


@pytest.mark.parametrize("technique", ["t1", "t2", "strain"])
def test_without_an_onset_the_same_weight_shows_lines(studio, technique):
    """What the onset holds back: at half the pose the lines show as they always did."""
    project = studio.scene.project
    project.furrows = project.furrows.with_controls(POSE, FurrowControls())
    studio.scene.reload_onsets()
    forehead = landmark_pixels(project, studio.camera, W, H)["forehead"]
    assert region_difference(render(studio, technique, 0.5), render(studio, "none", 0.5),
                             forehead) > SHOWN


def test_the_onset_for_all_poses_holds_back_every_pose(studio):
    project = studio.scene.project
    project.furrows = project.furrows.with_controls(POSE, FurrowControls())
    project.furrows = project.furrows.with_controls(None, FurrowControls(onset=0.7))
    studio.scene.reload_onsets()
    forehead = landmark_pixels(project, studio.camera, W, H)["forehead"]
    for technique in ("t1", "t2"):
        assert region_difference(render(studio, technique, 0.6), render(studio, "none", 0.6),
                                 forehead) < SAME


def test_past_the_onset_the_gpu_draws_what_the_numpy_reference_draws(sample, gl_context,
                                                                    monkeypatch):
    """Technique 2 and the automatic mode measure the drive (the pose through its onset) the
    same way whichever side deforms the face."""
    sample.furrows = sample.furrows.with_controls(POSE, FurrowControls(onset=ONSET))
    images = {}
    for deform in ("gpu", "cpu"):
        monkeypatch.setenv("WRINKLE_DEFORM", deform)
        with OffscreenStudio(sample, W, H, ctx=gl_context) as studio:
            images[deform] = {t: render(studio, t, 0.85) for t in ("t2", "strain", "none")}
            forehead = landmark_pixels(sample, studio.camera, W, H)["forehead"]
    for technique in ("t2", "strain"):
        assert region_difference(images["gpu"][technique], images["cpu"][technique],
                                 forehead) < SAME
        assert region_difference(images["gpu"][technique], images["gpu"]["none"],
                                 forehead) > CHANGED
