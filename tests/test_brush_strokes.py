"""Brush strokes in detail: rectangles and their union, falloff limits, pressure, clipping,
undo tiles, the UV mirror and how dabs are laid along a drag."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.brush import (
    Brush,
    Stroke,
    TileBackup,
    UvMirror,
    dab_rect,
    falloff,
    stamp,
    tile_changes,
    union,
)

pytestmark = pytest.mark.core

HARD = Brush(radius=2.0, hardness=1.0, flow=1.0, opacity=1.0, spacing=2.5)  # a dab every 5 px


# --------------------------------------------------------------------------- rectangles

def test_union_with_nothing_is_the_other_rectangle() -> None:
    """None stands for "nothing touched yet": the union is the other rectangle."""
    assert union(None, (1, 2, 3, 4)) == (1, 2, 3, 4)
    assert union((1, 2, 3, 4), None) == (1, 2, 3, 4)
    assert union(None, None) is None


@pytest.mark.parametrize(("a", "b", "expected"), [
    ((3, 40, 10, 5), (20, 8, 6, 60), (3, 8, 23, 60)),  # b reaches further right and down
    ((3, 40, 30, 50), (20, 8, 6, 60), (3, 8, 30, 82)),  # a does
])
def test_union_is_the_smallest_rectangle_holding_both(a, b, expected) -> None:
    """The union spans from the smaller x, y to the larger right and bottom edges, either way."""
    assert union(a, b) == expected
    assert union(b, a) == expected


def test_a_dab_off_one_side_of_the_mask_has_no_rectangle() -> None:
    """A dab entirely left of, or above, the mask (even just touching its edge) touches nothing."""
    assert dab_rect((16, 16), -50.0, 8.0, 4.0) is None
    assert dab_rect((16, 16), 8.0, -50.0, 4.0) is None
    assert dab_rect((16, 16), -5.0, 8.0, 4.0) is None  # reaches x = 0 exactly: no pixel
    assert dab_rect((16, 16), 8.0, -5.0, 4.0) is None
    assert dab_rect((16, 16), -4.4, 8.0, 4.0) == (0, 3, 1, 10)


# --------------------------------------------------------------------------- falloff

def test_falloff_of_a_brush_smaller_than_a_pixel() -> None:
    """A brush of radius 0.5 fades over its own radius, not over a pixel."""
    f = falloff(np.array([0.25, 0.5], np.float32), 0.5, 0.0)
    assert f.dtype == np.float32
    assert f.tolist() == [0.5, 0.0]


def test_hardness_1_and_above_is_a_hard_edge() -> None:
    """Hardness is capped just below 1: full strength inside the radius, 0 at it and beyond."""
    d = np.array([0.0, 4.9, 5.0, 6.0], np.float32)
    assert falloff(d, 5.0, 1.0).tolist() == [1.0, 1.0, 0.0, 0.0]
    assert falloff(d, 5.0, 2.0).tolist() == [1.0, 1.0, 0.0, 0.0]


# --------------------------------------------------------------------------- stamp

def test_pressure_scales_the_flow() -> None:
    """Half pressure goes half as far; no pressure (or less) changes nothing."""
    mask = np.zeros((8, 8), np.float32)
    stamp(mask, 4.0, 4.0, Brush(radius=2.0, hardness=1.0, flow=0.5), pressure=0.5)
    assert mask[4, 4] == 0.25
    stamp(mask, 4.0, 4.0, Brush(radius=2.0, hardness=1.0, flow=0.5), pressure=-1.0)
    assert mask[4, 4] == 0.25


def test_erase_is_scaled_by_opacity() -> None:
    """Erasing at opacity 0.5 and full flow halves the mask under the dab."""
    mask = np.ones((8, 8), np.float32)
    stamp(mask, 4.0, 4.0, Brush(radius=2.0, hardness=1.0, flow=1.0, opacity=0.5, erase=True))
    assert mask[4, 4] == 0.5 and mask[0, 0] == 1.0


def test_a_dab_brings_values_out_of_range_back_into_0_1() -> None:
    """Where a dab lands the mask is clipped to [0, 1]; elsewhere it is left alone."""
    mask = np.full((8, 8), 1.5, np.float32)
    mask[:, :4] = -0.5
    rect = stamp(mask, 4.0, 4.0, Brush(radius=2.0, hardness=1.0, flow=0.1))
    assert rect == (1, 1, 6, 6)
    assert mask[4, 4] == 1.0 and mask[4, 3] == 0.0
    assert mask[0, 0] == -0.5 and mask[0, 7] == 1.5


# --------------------------------------------------------------------------- undo tiles

@pytest.mark.parametrize(("rect", "tiles"), [
    ((5, 5, 4, 4), {(1, 1), (1, 2), (2, 1), (2, 2)}),  # ends on a tile's first pixel
    ((1, 1, 6, 6), {(0, 0), (0, 1), (1, 0), (1, 1)}),  # ends on a tile's last pixel
    ((4, 8, 4, 4), {(2, 1)}),  # exactly one tile
])
def test_touch_saves_exactly_the_tiles_a_rectangle_overlaps(rect, tiles) -> None:
    """The (row, column) tiles saved are those the rectangle overlaps, each a tile-sized copy."""
    mask = np.arange(144, dtype=np.float32).reshape(12, 12)
    backup = TileBackup(mask, tile=4)
    backup.touch(rect)
    assert set(backup.before) == tiles
    for (ty, tx), before in backup.before.items():
        np.testing.assert_array_equal(before, mask[ty * 4:ty * 4 + 4, tx * 4:tx * 4 + 4])


def test_changes_of_a_narrow_edge_tile() -> None:
    """A tile cut by the mask's right edge (4 × 2) reports its whole before and after."""
    mask = np.zeros((6, 10), np.float32)
    backup = TileBackup(mask, tile=4)
    backup.touch((8, 0, 2, 4))
    mask[3, 9] = 1.0
    [(x, y, before, after)] = backup.changes()
    assert (x, y) == (8, 0)
    assert before.shape == after.shape == (4, 2)
    assert after[3, 1] == 1.0 and not before.any()


def test_tile_changes_cuts_tiles_at_their_own_size() -> None:
    """A difference inside the first tile gives that tile alone, tile-sized."""
    a = np.zeros((8, 8), np.float32)
    b = a.copy()
    b[1, 1] = 1.0
    [(x, y, before, after)] = tile_changes(a, b, tile=4)
    assert (x, y) == (0, 0)
    assert before.shape == after.shape == (4, 4) and after[1, 1] == 1.0


# --------------------------------------------------------------------------- mirror

def test_uv_mirror_reflects_each_dab_across_the_middle() -> None:
    """u → 1 − u: x becomes width − x, y stays, each image from its own dab at full radius."""
    owner, points, scale = UvMirror()(np.array([[10.0, 5.0], [30.0, 7.0]]), (32, 100), 3.0)
    assert owner.tolist() == [0, 1]
    assert points.tolist() == [[90.0, 5.0], [70.0, 7.0]]
    assert scale.tolist() == [1.0, 1.0]


# --------------------------------------------------------------------------- strokes

def test_a_stroke_started_with_to_dabs_there_at_its_pressure() -> None:
    """The first point of a stroke, given with ``to``, is one dab at that point and pressure."""
    mask = np.zeros((16, 16), np.float32)
    stroke = Stroke(mask, HARD)
    assert stroke.to(12.0, 9.0, 0.5) == (9, 6, 6, 6)
    assert stroke.dabs == 1
    assert mask[9, 12] == 0.5 and mask.max() == 0.5


def test_jump_dabs_at_full_pressure_and_counts_every_dab() -> None:
    """Without a pressure a dab is at full pressure; each jump is one more dab."""
    mask = np.zeros((16, 32), np.float32)
    stroke = Stroke(mask, Brush(radius=2.0, hardness=1.0, flow=0.25))
    stroke.jump(4.0, 8.0)
    stroke.jump(20.0, 8.0, 0.5)
    assert stroke.dabs == 2
    assert mask[8, 4] == 0.25 and mask[8, 20] == 0.125


def test_pressure_and_position_are_interpolated_along_a_drag() -> None:
    """Dabs every 5 px along a diagonal drag, pressure going linearly from 0.2 to 1."""
    mask = np.zeros((40, 40), np.float32)
    stroke = Stroke(mask, HARD)
    stroke.jump(10.0, 10.0, 0.2)
    rect = stroke.to(25.0, 30.0, 1.0)  # 25 px: dabs at 5, 10, 15, 20, 25 px
    assert stroke.dabs == 6
    expected = {(10, 10): 0.2, (13, 14): 0.36, (16, 18): 0.52, (19, 22): 0.68,
                (22, 26): 0.84, (25, 30): 1.0}
    for (x, y), value in expected.items():
        assert mask[y, x] == pytest.approx(value, abs=1e-6)
    assert rect == (10, 11, 18, 22)  # all the drag's dabs, not only the last


def test_a_drag_without_pressure_is_at_full_pressure() -> None:
    """``to`` without a pressure ends at full pressure, not more."""
    mask = np.zeros((16, 40), np.float32)
    stroke = Stroke(mask, Brush(radius=2.0, hardness=1.0, flow=0.25, spacing=2.5))
    stroke.jump(10.0, 8.0)
    stroke.to(30.0, 8.0)
    assert [float(mask[8, x]) for x in (10, 15, 20, 25, 30)] == [0.25] * 5


def test_a_drag_along_a_column_lays_dabs_down_it() -> None:
    """A vertical drag is as long as its rows: a dab every 5 px down the column."""
    mask = np.zeros((40, 16), np.float32)
    stroke = Stroke(mask, HARD)
    stroke.jump(8.0, 10.0)
    stroke.to(8.0, 30.0)
    assert stroke.dabs == 5
    assert [float(mask[y, 8]) for y in (10, 15, 20, 25, 30)] == [1.0] * 5


def test_the_next_dab_follows_the_last_one_not_the_last_point() -> None:
    """After a jump the spacing counts from the jump: the first dab of a 5 px move is at its end."""
    mask = np.zeros((16, 40), np.float32)
    stroke = Stroke(mask, HARD)
    stroke.jump(20.0, 8.0)
    stroke.to(25.0, 8.0)
    assert mask[8, 25] == 1.0 and mask[8, 26] == 1.0 and mask[8, 22] == 0.0


def test_short_moves_add_up_to_a_dab() -> None:
    """Moves shorter than the spacing add up: three 2 px moves pass the 5 px spacing."""
    mask = np.zeros((16, 40), np.float32)
    stroke = Stroke(mask, HARD)
    stroke.jump(10.0, 8.0)
    assert stroke.to(12.0, 8.0) is None
    assert stroke.to(14.0, 8.0) is None
    assert stroke.to(16.0, 8.0) is not None
    assert stroke.dabs == 2 and mask[8, 15] == 1.0


def test_the_spacing_is_at_least_half_a_pixel() -> None:
    """A tiny spacing is raised to half a pixel: a 1 px move lays two dabs, at 0.5 and 1 px."""
    mask = np.zeros((8, 16), np.float32)
    stroke = Stroke(mask, Brush(radius=1.0, hardness=1.0, flow=1.0, spacing=0.01))
    stroke.jump(10.5, 4.5)
    stroke.to(11.5, 4.5)
    assert stroke.dabs == 3
    assert mask[4, 11] == 1.0  # the pixel centred on the last dab
    stroke.to(13.5, 4.5)
    assert stroke.dabs == 7


def test_a_stroke_coming_onto_the_mask_paints_once_there() -> None:
    """Dabs off the mask are skipped, not the end of the stroke."""
    mask = np.zeros((16, 16), np.float32)
    stroke = Stroke(mask, HARD)
    stroke.jump(-20.0, 8.0)
    rect = stroke.to(10.0, 8.0)
    assert mask[8, 10] == 1.0 and mask[8, 5] == 1.0 and mask[8, 0] == 1.0
    assert rect == (0, 5, 13, 6)
