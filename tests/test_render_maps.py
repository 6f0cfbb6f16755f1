"""Several wrinkled maps, painted cone angles and not-face vertices, rendered on standalone EGL
and judged in named regions of the sample face (issue 10, issue 4)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.sample.maps import BROW_MAP, EYE_MAP
from studio.core.wrinkles.influence import InfluenceArea
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.regions import landmark_pixels, region_difference

W, H = 400, 300
CHANGED = 4.0  # region difference (see regions.py) that counts as a visible change
SAME = 0.5


@pytest.fixture
def studio(sample, gl_context):
    s = OffscreenStudio(sample, W, H, ctx=gl_context)
    s.camera.yaw = 0.0
    yield s
    s.release()


def render(studio: OffscreenStudio, technique: str, weights=None) -> np.ndarray:
    return studio.render(RenderSettings(technique=technique), weights or {})


def marks(studio: OffscreenStudio) -> dict[str, tuple[int, int]]:
    return landmark_pixels(studio.scene.project, studio.camera, W, H)


def only_areas_active(studio: OffscreenStudio, names: dict[str, float]) -> None:
    project = studio.scene.project
    project.influence.links = {}
    for area in project.influence.areas:
        area.activation = names.get(area.name, 0.0)
    studio.scene.reload_masks()


def test_each_area_shows_only_the_wrinkles_of_its_own_map(studio):
    project = studio.scene.project
    only_areas_active(studio, {"forehead left": 1.0, "eye corner left": 1.0})
    none, both = render(studio, "none"), render(studio, "t1")
    m = marks(studio)
    assert region_difference(none, both, m["forehead left"]) > CHANGED
    assert region_difference(none, both, m["eye corner left"]) > CHANGED
    # the eye-corner area pointed at the brow map: that map has no wrinkles at the eye corner
    corner = next(a for a in project.influence.areas if a.name == "eye corner left")
    assert corner.wrinkle_map == EYE_MAP
    corner.wrinkle_map = BROW_MAP
    studio.scene.reload_area_maps()
    swapped = render(studio, "t1")
    assert region_difference(none, swapped, m["eye corner left"]) < SAME
    assert region_difference(both, swapped, m["forehead left"]) < SAME


def test_technique_2_areas_reveal_their_own_maps(studio):
    weights = {"squeeze": 1.0}
    none, t2 = render(studio, "none", weights), render(studio, "t2", weights)
    m = marks(studio)
    assert region_difference(none, t2, m["eye corner left"]) > CHANGED
    corners = next(a for a in studio.scene.project.wdv.areas if a.name == "eye corners")
    corners.wrinkle_map = BROW_MAP
    studio.scene.reload_wdv()
    assert region_difference(none, render(studio, "t2", weights), m["eye corner left"]) < SAME


def test_the_blend_of_maps_does_not_depend_on_area_order(studio):
    """Two all-covering areas revealing different maps, activations summing past 1."""
    project = studio.scene.project
    shape = project.influence.areas[0].mask.shape
    first = InfluenceArea("a", np.ones(shape, np.float32), activation=0.8, wrinkle_map=BROW_MAP)
    second = InfluenceArea("b", np.ones(shape, np.float32), activation=0.7, wrinkle_map=EYE_MAP)
    project.influence.links = {}
    project.influence.areas = [first, second]
    studio.scene.reload_masks()
    forward = render(studio, "t1")
    project.influence.areas = [second, first]
    studio.scene.reload_masks()
    backward = render(studio, "t1")
    assert np.array_equal(forward, backward)
    m = marks(studio)
    none = render(studio, "none")
    assert region_difference(none, forward, m["forehead"]) > CHANGED  # each map shows its own
    assert region_difference(none, forward, m["eye corner left"]) > CHANGED


def test_painted_cone_angles_narrow_where_wrinkles_show(studio):
    """Surprise with a frown moves the forehead off its authored direction: a narrow painted
    cone then hides part of the wrinkles, on the painted side only."""
    project = studio.scene.project
    weights = {"surprise": 1.0, "frown": 1.0}
    none, wide = render(studio, "none", weights), render(studio, "t2", weights)
    forehead = next(a for a in project.wdv.areas if a.name == "forehead")
    left = project.mesh.rest[:, 0] > 0.0  # the character's left
    cones = np.zeros(project.mesh.n_welded, np.float32)  # 0: the area's own angle
    cones[left] = 3.0
    forehead.cone_angles_deg = cones
    studio.scene.reload_wdv()
    narrow = render(studio, "t2", weights)

    def shown(image: np.ndarray) -> int:
        return int((np.abs(image.astype(int) - none.astype(int)).max(axis=2) > 2).sum())

    assert shown(narrow) < 0.9 * shown(wide)
    m = marks(studio)
    assert region_difference(wide, narrow, m["forehead left"]) > SAME
    assert region_difference(wide, narrow, m["forehead right"]) < SAME  # unpainted side


@pytest.mark.parametrize("technique", ["t1", "t2", "strain"])
def test_not_face_vertices_never_wrinkle(studio, technique):
    project = studio.scene.project
    weights = {"surprise": 1.0}
    none = render(studio, "none", weights)
    project.not_face = project.mesh.rest[:, 1] > project.mesh.rest[:, 1].mean()  # upper half
    studio.scene.reload_mesh()
    m = marks(studio)
    flagged = render(studio, technique, weights)
    assert region_difference(none, flagged, m["forehead"]) < SAME
    project.not_face = None
    studio.scene.reload_mesh()
    assert region_difference(none, render(studio, technique, weights), m["forehead"]) > CHANGED
