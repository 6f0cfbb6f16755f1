"""Whether a pose gets a technique-1 mask depends on that pose alone, and the automatic set-up's
report gives one reason per pose that never contradicts itself (studio/core/setup/
auto_setup.py).

Anatomy places a brow pose's lines by the face's frame, and the frame is found from every pose
loaded: beside a few poses its box sat elsewhere, the lines' window held none of the pose's
compression, and the pose lost its mask — "no mask for browInnerUp (compresses no skin)", then
"browInnerUp: compresses 6.3 %" two lines later; with fifty poses loaded the same pose got one.
Here anatomy's placement is given as a frame found from few poses gives it: a window on skin
the pose does not compress, no line inside it (``wrinkle_synth.vertex_lines`` returns such a
placement when its window misses the pose's compression)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.setup import auto_setup as auto
from tests.test_auto_setup import grid_mesh, grid_project, squeezed, uv_texel

pytestmark = pytest.mark.core

SHAPE = (64, 64)


def _project():
    """The flat test face (UVs across it, x left to right): ``squeeze`` compresses its left
    half by 10 %, ``lift`` carries it up undeformed, ``other`` squeezes it top to bottom."""
    mesh = grid_mesh()
    rest = mesh.rest
    tall = rest.copy()
    tall[:, 1] *= 0.85
    return grid_project(squeeze=squeezed(rest), lift=rest + np.float32([0.0, 0.3, 0.0]),
                        other=tall)


def _misplaced(project) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Anatomy's placement for ``squeeze`` from a frame found elsewhere: its window on the
    right half (which the pose leaves alone), no line in it."""
    rest = project.mesh.rest
    return {"squeeze": (np.zeros(len(rest), bool), rest[:, 0] > 0.3)}


def test_a_pose_keeps_its_mask_where_anatomy_places_its_lines_on_skin_it_does_not_squeeze():
    """The pose compresses the left half: it gets a mask there and a link, whatever anatomy's
    misplaced window says, and vectors where it moves. Red before: no mask, no link, and the
    report said both "no mask for squeeze (compresses no skin)" and "squeeze: compresses"."""
    project = _project()
    report = auto.suggest_setup(project, mask_size=SHAPE[0], placed=_misplaced(project))
    masks = {area.name: area.mask for area in report.influence_areas}
    assert "squeeze" in masks, report.summary()
    assert masks["squeeze"][uv_texel(SHAPE, -0.5, 0.0)] > 0.9
    assert masks["squeeze"][uv_texel(SHAPE, 0.6, 0.0)] == 0.0
    assert report.links["squeeze"] == {"squeeze": 1.0}
    area = next(a for a in report.wdv_areas if a.pose == "squeeze")
    assert area.authored[project.mesh.rest[:, 0] < -0.5].all()


def _masked(report) -> set[str]:
    return set(report.links)


def test_whether_a_pose_is_masked_does_not_depend_on_the_others_loaded():
    """The same poses get masks set up one at a time as all at once, wherever anatomy placed
    their lines. Red before: squeeze got none either way."""
    project = _project()
    place = _misplaced(project)
    together = _masked(auto.suggest_setup(project, mask_size=SHAPE[0], placed=place))
    alone = set()
    for name in ("squeeze", "lift", "other"):
        alone |= _masked(auto.suggest_setup(project, mask_size=SHAPE[0], poses=[name],
                                            placed=place))
    assert together == alone == {"squeeze", "other"}


def test_the_report_gives_one_reason_per_pose_and_never_contradicts_itself():
    """Each pose has exactly one line; a pose the summary lists as getting no mask has a
    "no mask" line giving the same reason, and every pose with a "compresses" line has a
    mask. Red before: squeeze was in both."""
    project = _project()
    report = auto.suggest_setup(project, mask_size=SHAPE[0], placed=_misplaced(project))
    lines = report.pose_lines()
    assert [line.split(":")[0] for line in lines] == ["squeeze", "lift", "other"]
    summary = report.summary()
    for line in lines:
        pose = line.split(":")[0]
        if ": compresses" in line:
            assert pose in report.links and pose not in report.flat_poses, (line, summary)
        else:
            assert ": no mask, it " in line and pose in report.flat_poses, (line, summary)
    assert summary.endswith("no mask for lift (compresses no skin).")
    assert "moves the skin without deforming it" in lines[1]


def test_a_compression_under_a_texel_is_said_so_not_called_no_compression(monkeypatch):
    """A pose that compresses the skin, whose mask nonetheless comes out empty (its compression
    falls between the mask's texels), is reported with that reason in the summary and its
    line alike, never as compressing no skin."""
    project = _project()
    monkeypatch.setattr(auto, "mask_from_weights",
                        lambda mesh, weights, shape, *args: np.zeros(shape, np.float32))
    report = auto.suggest_setup(project, mask_size=SHAPE[0], placed={})
    assert report.no_mask["squeeze"] == auto.UNDER_A_TEXEL
    assert f"no mask for squeeze, other ({auto.UNDER_A_TEXEL})" in report.summary()
    assert f"squeeze: no mask, {auto.UNDER_A_TEXEL}" in report.pose_lines()
    assert "lift (compresses no skin)" in report.summary()
