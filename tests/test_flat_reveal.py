"""How much of an area's weight lands where its wrinkled map is flat (issue #28: the heat view
said "hot" while the picture did not change), on hand-built maps; and the heat-view choice in
the view model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.cli import build_parser
from studio.core.project.view_settings import ViewSettings
from studio.core.wrinkles.flat_reveal import (
    FLAGGED_SHARE,
    RevealMaps,
    reveal_maps,
    t1_reveal,
    t2_reveal,
    t2_weights,
)
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.shading import reveal_difference
from studio.core.wrinkles.textures import flat_normal_map
from studio.core.wrinkles.wdv import WdvArea, wrinkle_directions
from tests.hand_faces import grid_face, tilted_map

pytestmark = pytest.mark.core

SIZE = 64
RIGHT = (slice(None), slice(SIZE // 2, None))  # texels with u > 0.5: x > 0 on the grid


def two_map_face():
    """'wrinkles' tilted everywhere, 'wrinkles 2' only on the right half (the left is flat)."""
    return grid_face({"wrinkles": tilted_map(SIZE, 192),
                      "wrinkles 2": tilted_map(SIZE, 192, RIGHT)})


def half_mask(left: float, right: float, size: int = SIZE) -> np.ndarray:
    mask = np.full((size, size), left, np.float32)
    mask[:, size // 2:] = right
    return mask


def test_the_difference_of_two_texels_by_hand():
    """Neutral (128, 128) and wrinkled (192, 128): x = 2·192/255 − 1 = 0.5059 against 0.0039,
    z rebuilt as √(1 − x² − y²): |Δ| = √(0.5020² + 0.1374²) ≈ 0.520."""
    wrinkled = flat_normal_map(1)
    wrinkled[..., 0] = 192
    x_w, x_n = 2 * 192 / 255 - 1, 2 * 128 / 255 - 1
    z_w, z_n = math.sqrt(1 - x_w ** 2 - x_n ** 2), math.sqrt(1 - 2 * x_n ** 2)
    got = reveal_difference(flat_normal_map(1), wrinkled)
    assert got[0, 0] == pytest.approx(math.hypot(x_w - x_n, z_w - z_n), abs=1e-6)
    assert got[0, 0] == pytest.approx(0.520, abs=1e-3)
    assert reveal_difference(flat_normal_map(2), flat_normal_map(2)).max() == 0.0


@pytest.mark.parametrize(("left", "right", "wrinkle_map", "share"), [
    (1.0, 0.0, "wrinkles 2", 1.0),  # all on the flat half
    (0.0, 1.0, "wrinkles 2", 0.0),  # all on the furrow
    (1.0, 1.0 / 24.0, "wrinkles 2", 0.96),  # 2048 of 2048 + 2048 / 24 on the flat half
    (1.0, 1.0, "wrinkles 2", 0.5),
    (1.0, 0.0, "wrinkles", 0.0),  # the first map has furrows everywhere
    (1.0, 0.0, "", 0.0),  # "" is the first map, as in the renderer
])
def test_a_technique_1_area_s_share_on_flat_texels(left, right, wrinkle_map, share):
    project = two_map_face()
    area = InfluenceArea("forehead left", half_mask(left, right), wrinkle_map=wrinkle_map)
    reveal = t1_reveal(reveal_maps(project.textures), area)
    assert reveal.share == pytest.approx(share, abs=1e-6)
    assert reveal.flagged == (share >= FLAGGED_SHARE)
    assert reveal.map_name == (wrinkle_map or "wrinkles")


def test_the_reason_names_the_map_and_the_share():
    area = InfluenceArea("forehead left", half_mask(1.0, 1.0 / 24.0), wrinkle_map="wrinkles 2")
    reveal = t1_reveal(reveal_maps(two_map_face().textures), area)
    assert reveal.flagged
    assert reveal.reason() == ("reveals a flat part of 'wrinkles 2': 96 % of its weight shows "
                               "nothing")


def test_an_empty_mask_has_nothing_to_measure():
    area = InfluenceArea("empty", np.zeros((SIZE, SIZE)), wrinkle_map="wrinkles 2")
    assert t1_reveal(reveal_maps(two_map_face().textures), area) is None


def test_a_mask_at_another_resolution_than_the_map():
    """A 16² mask is read bilinearly like the renderer's, so its weight on the left quarter
    stays on the flat half; a 256² one is averaged down."""
    maps = reveal_maps(two_map_face().textures)
    quarter = np.zeros((16, 16), np.float32)
    quarter[:, :4] = 1.0
    assert t1_reveal(maps, InfluenceArea("a", quarter,
                                         wrinkle_map="wrinkles 2")).share == pytest.approx(1.0)
    assert t1_reveal(maps, InfluenceArea("a", half_mask(0.0, 1.0, 256),
                                         wrinkle_map="wrinkles 2")).share == pytest.approx(0.0)


def test_thin_furrows_of_a_large_map_are_not_lost_on_the_measure_s_grid():
    """A 1024² map with a one-texel furrow every fourth column (1, 5, 9, …) measured on a
    256² grid: each block of four columns holds a furrow, so nothing counts as flat (taking
    every fourth column would see none of them)."""
    lines = np.zeros((1024, 1024), bool)
    lines[:, 1::4] = True
    project = grid_face({"wrinkles": tilted_map(1024, 192, lines)})
    maps = RevealMaps(project.textures, grid=256)
    assert maps.shape == (256, 256)
    assert t1_reveal(maps, InfluenceArea("all", np.ones((64, 64)))).share == 0.0


def test_a_replaced_map_is_measured_again():
    project = two_map_face()
    area = InfluenceArea("forehead left", half_mask(1.0, 0.0), wrinkle_map="wrinkles 2")
    first = reveal_maps(project.textures)
    assert reveal_maps(project.textures) is first  # the same maps: measured once
    assert t1_reveal(first, area).flagged
    project.textures.set_wrinkle_map("wrinkles 2", tilted_map(SIZE, 192))
    assert not t1_reveal(reveal_maps(project.textures), area).flagged


def squint_area(project, side: float) -> tuple[WdvArea, np.ndarray]:
    """An area whose pose lifts the grid's vertices on one side (x · side > 0) by 0.05."""
    rest = project.mesh.rest
    moved = rest[:, 0] * side > 1e-9
    posed = rest.copy()
    posed[moved, 1] += 0.05
    result = wrinkle_directions(rest, posed, np.flatnonzero(moved))
    return WdvArea("squint", "squint", result.directions, result.lengths,
                   wrinkle_map="wrinkles 2"), posed


def test_technique_2_weights_are_the_visibility_at_the_key_pose():
    project = two_map_face()
    area, posed = squint_area(project, -1.0)
    rest = project.mesh.rest
    weights = t2_weights(area, rest, posed)
    np.testing.assert_allclose(weights, np.where(rest[:, 0] < -1e-9, 1.0, 0.0), atol=1e-6)
    half = t2_weights(area, rest, rest + (posed - rest) * 0.5)
    np.testing.assert_allclose(half, weights * 0.5, atol=1e-6)


@pytest.mark.parametrize(("side", "share"), [(-1.0, 1.0), (1.0, 0.0)])
def test_a_technique_2_area_s_share_over_its_triangles(side, share):
    """Vertices left of x = 0 (u < 0.5) weigh 1 and fade to 0 at x = 0 over their
    triangles: every bit of their weight lies on the flat half of 'wrinkles 2'."""
    project = two_map_face()
    area, posed = squint_area(project, side)
    reveal = t2_reveal(reveal_maps(project.textures), project.skin_mesh(), area, posed)
    assert reveal.share == pytest.approx(share, abs=1e-6)
    assert reveal.map_name == "wrinkles 2"


def test_a_technique_2_area_without_vectors_has_nothing_to_measure():
    project = two_map_face()
    n = project.mesh.n_welded
    area = WdvArea.empty("none", "squint", n)
    assert t2_reveal(reveal_maps(project.textures), project.skin_mesh(), area,
                     project.mesh.rest) is None


def test_both_heat_views_are_view_choices_saved_with_the_project_and_on_the_command_line():
    view = ViewSettings(debug_view="heat-shows")
    assert ViewSettings.from_dict(view.to_dict()).debug_view == "heat-shows"
    assert ViewSettings.from_dict({"debug_view": "heat"}).debug_view == "heat"
    for choice in ("heat", "heat-shows"):
        args = build_parser().parse_args(["render", "--view", choice, "-o", "x.png"])
        assert args.view == choice
