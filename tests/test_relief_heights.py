"""Wrinkle heights from normal maps (numpy): relief depth, slopes of encoded normals, the
Frankot–Chellappa integration with its border mirror, and the joint scaling of wrinkle maps."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.normalmap import height_to_normal
from studio.core.wrinkles.relief import (
    integrate_slopes,
    normal_slopes,
    relief_image,
    suggested_relief_depth,
    wrinkle_heights,
)
from studio.core.wrinkles.textures import flat_normal_map

pytestmark = pytest.mark.core


# --------------------------------------------------------------------------- relief depth

def test_relief_depth_follows_the_largest_extent_of_the_bounds() -> None:
    """The depth is 0.014 × the largest extent (hi − lo), to two significant digits."""
    assert suggested_relief_depth([-1.0, -2.0, 0.0], [1.0, 1.0, 0.5]) == 0.042  # extent 3
    assert suggested_relief_depth(np.array([0, 0, 0]), np.array([0.5, 0.2, 0.1])) == 0.007


def test_relief_depth_of_empty_bounds_is_the_default() -> None:
    """Bounds of no extent (a single point) give the sample's default depth, 0.03."""
    assert suggested_relief_depth([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]) == 0.03


# --------------------------------------------------------------------------- slopes

def test_slopes_of_an_8_bit_normal() -> None:
    """128 is 0 and 255 is 1 in 8-bit maps: (191, 65, 255) slopes (−63/127, −63/127)."""
    image = np.array([[[191, 65, 255], [128, 128, 255]]], np.uint8)
    p, q = normal_slopes(image)
    assert p.dtype == np.float32 and q.dtype == np.float32
    np.testing.assert_allclose(p, [[-63 / 127, 0.0]], rtol=1e-6)
    np.testing.assert_allclose(q, [[-63 / 127, 0.0]], rtol=1e-6)


def test_slopes_of_normals_tilted_past_87_degrees_are_clamped() -> None:
    """A normal with nz below 0.05 has its slopes taken as if nz were 0.05 (so at most 20)."""
    image = np.array([[[255, 128, 132], [1, 128, 128]]], np.uint8)  # nz = 4/127, then 0
    p, q = normal_slopes(image)
    np.testing.assert_allclose(p, [[-20.0, 20.0]], rtol=1e-6)
    np.testing.assert_allclose(q, [[0.0, 0.0]], atol=1e-7)
    wide = np.array([[[65535, 32768, 33000]]], np.uint16)
    np.testing.assert_allclose(normal_slopes(wide)[0], [[-20.0]], rtol=1e-6)


def test_slopes_of_a_16_bit_normal() -> None:
    """32768 is 0 and 65535 is 1 in 16-bit maps; the alpha channel is ignored."""
    image = np.array([[[49151, 16385, 65535, 7], [32768, 32768, 65535, 0]]], np.uint16)
    p, q = normal_slopes(image)
    np.testing.assert_allclose(p, [[-16383 / 32767, 0.0]], rtol=1e-6)
    np.testing.assert_allclose(q, [[-16383 / 32767, 0.0]], rtol=1e-6)


def test_slopes_of_a_float_normal_map_in_0_1() -> None:
    """Float maps encode n as (n + 1) / 2: (0.75, 0.25, 1.0) is n = (0.5, −0.5, 1)."""
    image = np.array([[[0.75, 0.25, 1.0], [0.5, 0.5, 1.0], [0.75, 0.5, 0.75]]], np.float64)
    p, q = normal_slopes(image)
    assert p.dtype == np.float32 and q.dtype == np.float32
    np.testing.assert_allclose(p, [[-0.5, 0.0, -1.0]], rtol=1e-6)
    np.testing.assert_allclose(q, [[-0.5, 0.0, 0.0]], atol=1e-7)


# --------------------------------------------------------------------------- integration

def _mirrored(p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The slopes of the height's even reflection to twice the size (by hand)."""
    px = np.concatenate([p, -p[:, ::-1]], axis=1)
    qx = np.concatenate([q, q[:, ::-1]], axis=1)
    return np.concatenate([px, px[::-1]], axis=0), np.concatenate([qx, -qx[::-1]], axis=0)


LINES = {  # one border line of a 6 × 7 field (corners left out)
    "top": np.s_[0, 2:5], "bottom": np.s_[-1, 2:5],
    "left": np.s_[2:4, 0], "right": np.s_[2:4, -1],
}


@pytest.mark.parametrize("line", list(LINES))
@pytest.mark.parametrize("which", ["p", "q"])
def test_slopes_on_any_border_line_are_solved_as_the_mirrored_field(line: str, which: str) -> None:
    """Slopes reaching any one border line are integrated as the field's even reflection: the
    height is the same as that of the doubled field's, cut back to size."""
    p, q = np.zeros((6, 7)), np.zeros((6, 7))
    (p if which == "p" else q)[LINES[line]] = [1.0, -2.0, 0.5][: 3 if line in ("top", "bottom")
                                                               else 2]
    height = integrate_slopes(p, q)
    doubled = integrate_slopes(*_mirrored(p, q))
    assert np.abs(height).max() > 0.05
    np.testing.assert_allclose(height, doubled[:6, :7], atol=1e-5)


def test_a_ramp_cut_by_the_border_is_recovered() -> None:
    """A constant slope across the whole image (h = x) comes back as the ramp, mean 0."""
    p, q = np.ones((8, 10)), np.zeros((8, 10))
    height = integrate_slopes(p, q)
    assert height.dtype == np.float32 and height.shape == (8, 10)
    ramp = np.arange(10) - 4.5
    assert np.corrcoef(height[4], ramp)[0, 1] > 0.99
    assert np.ptp(height, axis=0).max() < 1e-5  # the same in every row
    assert height[:, 6:].min() > 0 > height[:, :4].max()
    q_ramp = integrate_slopes(q.T, p.T)  # h = y (rows downward)
    np.testing.assert_allclose(q_ramp, height.T, atol=1e-5)


def test_interior_slopes_are_integrated_at_their_own_odd_size() -> None:
    """Slopes that stay inside the image (an odd 12 × 11 field) are integrated at their own
    size: a raised block comes back, mean 0, float32."""
    inner = np.zeros((12, 11))
    inner[3:9, 3:8] = 1.0  # only the interior of a field changes
    bump_p, bump_q = np.gradient(inner, axis=1), np.gradient(inner, axis=0)
    bump = integrate_slopes(bump_p, bump_q)
    assert bump.dtype == np.float32 and bump.shape == (12, 11)
    assert bump.mean() == pytest.approx(0.0, abs=1e-6)
    assert np.corrcoef(bump.ravel(), inner.ravel())[0, 1] > 0.95
    assert bump[5:7, 5].min() > bump[0].max()


def test_a_sinusoid_reaching_the_border_is_recovered() -> None:
    """Exact slopes of a whole-period sinusoid that reach the border (on an odd 9 × 7 field)
    integrate back to it, up to the mirror's small error."""
    rows, cols = 9, 7
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float64)
    wy, wx = 2 * np.pi / rows, 2 * np.pi / cols
    h = np.sin(wx * x) * np.sin(wy * y)
    p = wx * np.cos(wx * x) * np.sin(wy * y)
    q = wy * np.sin(wx * x) * np.cos(wy * y)
    assert p[:, 0].any()  # reaches the border: mirrored
    height = integrate_slopes(p, q)
    assert np.corrcoef(height.ravel(), h.ravel())[0, 1] > 0.97


def test_float32_slopes_are_integrated_in_double_precision() -> None:
    """The slopes' type does not change the height: float32 slopes give the float64 result."""
    rng = np.random.default_rng(3)
    p, q = rng.standard_normal((2, 10, 12)).astype(np.float32)
    np.testing.assert_array_equal(integrate_slopes(p, q),
                                  integrate_slopes(p.astype(np.float64), q.astype(np.float64)))


# --------------------------------------------------------------------------- wrinkle heights

def _valley_maps(rows: int, cols: int, column: int, depth: float = 1.0,
                 bits: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """A flat neutral map and one with a valley running down ``column``."""
    x = np.arange(cols)[None, :]
    valley = -depth * np.exp(-0.5 * ((x - column) / 1.0) ** 2) * np.ones((rows, 1))
    return height_to_normal(0 * valley, bits=bits), height_to_normal(valley, 2.0, bits=bits)


def test_wrinkle_heights_of_non_square_maps_of_other_sizes() -> None:
    """Maps of other sizes are resized to the largest rows and columns; heights are float32."""
    neutral, wrinkled = _valley_maps(8, 20, 10)
    small_neutral = neutral[::2, ::2]  # 4 × 10: the same flat map at half size
    heights = wrinkle_heights(small_neutral, [wrinkled])
    assert heights.shape == (1, 8, 20) and heights.dtype == np.float32
    np.testing.assert_array_equal(heights, wrinkle_heights(neutral, [wrinkled]))
    assert heights[0].min() == -1.0 and heights[0, :, 10].max() < -0.9


def test_a_map_like_the_neutral_one_before_a_wrinkled_one() -> None:
    """A map with no wrinkle gives zeros and does not stop the maps after it."""
    neutral, wrinkled = _valley_maps(8, 16, 8)
    heights = wrinkle_heights(neutral, [neutral, wrinkled])
    assert not heights[0].any()
    assert heights[1].min() == -1.0


def test_no_wrinkled_maps_give_no_heights() -> None:
    """With no wrinkled maps the heights are an empty (0, H, W) stack."""
    heights = wrinkle_heights(flat_normal_map(4), [])
    assert heights.shape == (0, 4, 4)


def test_a_shallow_wrinkle_alone_is_scaled_up_to_1() -> None:
    """Even a faint wrinkle's deepest point becomes −1 when it is the only one."""
    neutral, faint = _valley_maps(8, 16, 8, depth=0.05)
    heights = wrinkle_heights(neutral, [faint])
    assert heights.min() == -1.0


def test_skin_beside_a_wide_wrinkle_is_level_0() -> None:
    """The level of the texels whose slopes did not change is 0, even where most texels
    changed (here a wide, shallow trough with a flat floor)."""
    cols = 24
    x = np.arange(cols, dtype=np.float64)
    trough = -np.clip(np.minimum(x - 2, 21 - x) / 2.0, 0.0, 1.0)  # flat skin at 0..2, 21..23
    wrinkled = height_to_normal(np.tile(trough, (6, 1)), 1.0, bits=16)
    neutral = height_to_normal(np.zeros((6, cols)), bits=16)
    heights = wrinkle_heights(neutral, [wrinkled])[0]
    p, _ = normal_slopes(wrinkled)
    unchanged = p[0] == 0
    assert unchanged[[0, 1, 23]].all() and unchanged[10:14].all()
    assert np.median(heights[:, unchanged]) == pytest.approx(0.0, abs=1e-6)
    assert heights.min() == -1.0 or heights.max() == 1.0


def test_where_every_texel_changed_the_median_is_level_0() -> None:
    """A wrinkled map whose slopes differ everywhere is levelled by its own median."""
    y, x = np.mgrid[0:6, 0:8].astype(np.float64)
    wave = np.sin(2 * np.pi * x / 8 + 0.3) + 0.3 * np.cos(2 * np.pi * y / 6 + 0.2)
    wrinkled = height_to_normal(wave, 1.0, bits=16)
    neutral = np.empty_like(wrinkled)
    neutral[...] = (40000, 25000, 60000)  # a tilted plane: no slope agrees anywhere
    p0, q0 = normal_slopes(neutral)
    p, q = normal_slopes(wrinkled)
    assert ((p != p0) | (q != q0)).all()
    heights = wrinkle_heights(neutral, [wrinkled])[0]
    assert np.isfinite(heights).all()
    assert np.median(heights) == pytest.approx(0.0, abs=1e-6)
    assert np.abs(heights).max() == 1.0


def test_large_maps_are_averaged_over_blocks_whatever_their_shape() -> None:
    """A map over ``max_size`` gives heights at a whole fraction of its size, rounding up
    (the last blocks repeat the edge texels): 10 × 15 at most 8 → 5 × 8."""
    neutral, wrinkled = _valley_maps(10, 15, 7)
    heights = wrinkle_heights(neutral, [wrinkled], max_size=8)
    assert heights.shape == (1, 5, 8)
    assert heights[0, :, 3].max() < -0.9
    assert np.abs(heights[0, :, 7]).max() < 0.1  # the last (edge-repeated) column: skin
    np.testing.assert_allclose(heights[0], heights[0, :1].repeat(5, 0), atol=1e-5)
    tall = wrinkle_heights(*(np.swapaxes(m, 0, 1) for m in (neutral,)),
                           [np.swapaxes(wrinkled, 0, 1)], max_size=8)
    assert tall.shape == (1, 8, 5)


def test_blocks_past_the_edge_repeat_the_edge_texels() -> None:
    """A map of odd width reduced by blocks of 2 counts its last column twice: the same heights
    as the map with that column repeated, here where a valley runs along the edge."""
    neutral, wrinkled = _valley_maps(4, 5, 4)
    padded = [np.pad(m, ((0, 0), (0, 1), (0, 0)), mode="edge") for m in (neutral, wrinkled)]
    heights = wrinkle_heights(neutral, [wrinkled], max_size=4)
    assert heights.shape == (1, 2, 3)
    np.testing.assert_array_equal(heights, wrinkle_heights(padded[0], [padded[1]], max_size=4))


def test_halving_maps_averages_the_slopes_over_2x2_blocks() -> None:
    """With max_size half the map's size the heights come at half size."""
    neutral, wrinkled = _valley_maps(8, 16, 8)
    heights = wrinkle_heights(neutral, [wrinkled], max_size=8)
    assert heights.shape == (1, 4, 8)
    assert heights[0, :, 4].max() < -0.9


# --------------------------------------------------------------------------- relief image

def test_relief_image_holds_each_maps_height_in_its_channel() -> None:
    """Channel m is map m's height (float16); unused channels are 0; four maps fit."""
    neutral, deep = _valley_maps(6, 16, 8)
    _, shallow = _valley_maps(6, 16, 8, depth=0.5)
    heights = wrinkle_heights(neutral, [deep, shallow, neutral, deep])
    image = relief_image(neutral, [deep, shallow, neutral, deep])
    assert image.shape == (6, 16, 4) and image.dtype == np.float16
    np.testing.assert_array_equal(image, np.moveaxis(heights, 0, -1).astype(np.float16))
    assert image[0, 8, 0] == image[0, 8, 3] == -1.0
    assert image[0, 8, 1] == pytest.approx(-0.5, abs=0.05) and not image[..., 2].any()


def test_relief_image_refuses_more_than_four_maps() -> None:
    """A fifth wrinkled map does not fit the four channels: refused, naming the limit."""
    flat = flat_normal_map(2)
    with pytest.raises(ValueError, match=r"^at most 4 wrinkled maps fit one relief image$"):
        relief_image(flat, [flat] * 5)
