"""The UV canvas's model without Qt: how masks are tinted, the overlap view's colours, the
wireframe's points and outline, and the hint line (studio/widgets/paint/uv_canvas_model.py)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.widgets.paint.uv_canvas_model import (
    NONE_RGBA,
    OVER_RGBA,
    OVERLAY_ALPHA,
    brush_hint,
    mask_size,
    masks_rgba,
    outline_edges,
    overlap_activations,
    overlap_rgba,
    rgb8,
    uv_points,
)

pytestmark = pytest.mark.core


def test_the_canvas_is_as_wide_as_the_masks_columns():
    assert mask_size((512, 2048)) == (2048, 512)  # rows, columns -> width, height
    assert mask_size(None) == (1024, 1024)


def test_a_16_bit_map_is_shown_at_8_bits_without_its_alpha():
    rgba = np.full((2, 3, 4), 0xABCD, np.uint16)
    out = rgb8(rgba)
    assert out.dtype == np.uint8 and out.shape == (2, 3, 3) and out.flags.c_contiguous
    assert np.all(out == 0xAB)


def test_masks_are_tinted_by_their_colours_and_as_opaque_as_the_strongest():
    masks = np.zeros((2, 1, 3), np.float32)
    masks[0, 0, 0] = 1.0  # red area only
    masks[0, 0, 1], masks[1, 0, 1] = 0.5, 0.5  # both, half each
    colours = np.array([(255, 0, 0), (0, 0, 255)], np.float32)
    out = masks_rgba(masks, colours)
    alpha = round(255 * OVERLAY_ALPHA)
    assert tuple(out[0, 0]) == (round(255 * OVERLAY_ALPHA), 0, 0, alpha)  # premultiplied
    half = 0.5 * OVERLAY_ALPHA
    assert tuple(out[0, 1]) == (round(127.5 * half), 0, round(127.5 * half), round(255 * half))
    assert tuple(out[0, 2]) == (0, 0, 0, 0)  # no area: the map shows through
    assert masks_rgba(np.zeros((0, 4, 5), np.float32), np.zeros((0, 3))).shape == (4, 5, 4)


def test_the_overlap_view_is_red_over_one_and_dark_where_nothing_reaches():
    over = np.array([[True, False, True]])
    none = np.array([[False, True, True]])
    out = overlap_rgba(over, none)
    r, g, b, a = OVER_RGBA
    assert tuple(out[0, 0]) == (r * a // 255, g * a // 255, b * a // 255, a)
    assert tuple(out[0, 1]) == (0, 0, 0, NONE_RGBA[3])
    assert tuple(out[0, 2]) == tuple(out[0, 0])  # red wins


def test_a_neutral_face_checks_overlap_with_every_shown_area_at_one():
    now = np.array([0.0, 0.4, 0.0], np.float32)
    assert overlap_activations(now, [True, True, True]) is now
    neutral = overlap_activations(np.zeros(3, np.float32), [True, False, True])
    assert neutral.tolist() == [1.0, 0.0, 1.0]


def test_uvs_land_on_pixels_with_v_up_and_outside_the_tile_too():
    uvs = np.array([[0.0, 0.0], [1.0, 1.0], [1.5, -0.25]])  # a UDIM face goes past 1
    assert uv_points(uvs, 200, 100).tolist() == [[0.0, 100.0], [200.0, 0.0], [300.0, 125.0]]


def test_only_the_outline_of_what_is_not_skin_is_drawn():
    quad = np.array([[0, 1, 2], [0, 2, 3]])  # the shared diagonal 0-2 is inside
    edges = {tuple(e) for e in outline_edges(quad).tolist()}
    assert edges == {(0, 1), (1, 2), (2, 3), (0, 3)}


def test_the_hint_says_what_a_drag_paints_and_how_to_move():
    assert brush_hint(None, False, 20, None, False).startswith("No area selected")
    text = brush_hint("Brow_L", True, 31.6, "In UV (u → 1 − u)", True)
    assert text.startswith("Eraser on “Brow_L” · radius 32 px · mirror in uv (u → 1 − u) · ")
    assert text.endswith("red: Σ mask·activation > 1, dark: no area")
    assert "mirror" not in brush_hint("Brow_L", False, 8, None, False)
