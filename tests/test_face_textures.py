"""Packing the face's normal maps for the shader: neutral and first wrinkled map's x and y in
one RGBA image, the other wrinkled maps as layers, at one size and bit depth."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.textures import FaceTextures, pack_more_maps, pack_normal_maps

pytestmark = pytest.mark.core


def _ramp(rows: int, cols: int, dtype=np.uint8, start: int = 0) -> np.ndarray:
    """An RGB image whose texel (r, c) holds (start + 10r + c, 100 + ..., 200 + ...)."""
    r, c = np.mgrid[0:rows, 0:cols]
    base = start + 10 * r + c
    return np.stack([base, base + 100, base + 200], axis=-1).astype(dtype)


def _textures(*maps: np.ndarray) -> FaceTextures:
    flat = np.full((1, 1, 3), 128, np.uint8)
    return FaceTextures(flat, flat, wrinkle_maps={f"m{i}": m for i, m in enumerate(maps)})


# --------------------------------------------------------------------------- neutral + first

def test_packing_puts_neutral_xy_then_wrinkled_xy() -> None:
    """RGBA = (neutral x, neutral y, wrinkled x, wrinkled y); blue (z) is left out."""
    neutral, wrinkled = _ramp(2, 3), _ramp(2, 3, start=5)
    packed = pack_normal_maps(neutral, wrinkled)
    assert packed.shape == (2, 3, 4) and packed.dtype == np.uint8
    assert packed.flags.c_contiguous
    assert packed[1, 2].tolist() == [12, 112, 17, 117]
    np.testing.assert_array_equal(packed[..., :2], neutral[..., :2])
    np.testing.assert_array_equal(packed[..., 2:], wrinkled[..., :2])


@pytest.mark.parametrize("small_first", [True, False])
def test_the_smaller_map_is_resized_to_the_larger(small_first: bool) -> None:
    """A 2 × 3 map packed with a 4 × 6 one is repeated texel by texel (nearest) to 4 × 6."""
    small, large = _ramp(2, 3), _ramp(4, 6, start=50)
    packed = pack_normal_maps(small, large) if small_first else pack_normal_maps(large, small)
    assert packed.shape == (4, 6, 4)
    small_xy = packed[..., :2] if small_first else packed[..., 2:]
    large_xy = packed[..., 2:] if small_first else packed[..., :2]
    np.testing.assert_array_equal(small_xy[:, :, 0], [[0, 0, 1, 1, 2, 2]] * 2 + [[10, 10, 11, 11,
                                                                                   12, 12]] * 2)
    np.testing.assert_array_equal(large_xy, large[..., :2])


@pytest.mark.parametrize("sixteen_first", [True, False])
def test_an_8_bit_map_packed_with_a_16_bit_one_is_widened_exactly(sixteen_first: bool) -> None:
    """With one 16-bit map, both are packed 16-bit: 8-bit 0, 128, 255 become 0, 32896, 65535."""
    eight = np.array([[[0, 128, 255], [255, 0, 1]]], np.uint8)
    sixteen = np.array([[[1000, 65535, 7], [32768, 0, 3]]], np.uint16)
    packed = (pack_normal_maps(sixteen, eight) if sixteen_first
              else pack_normal_maps(eight, sixteen))
    assert packed.dtype == np.uint16
    widened = [[0, 32896], [65535, 0]]
    kept = [[1000, 65535], [32768, 0]]
    expected = [k + w for k, w in zip(kept, widened, strict=True)] if sixteen_first else \
        [w + k for w, k in zip(widened, kept, strict=True)]
    assert packed[0].tolist() == expected


def test_two_16_bit_maps_stay_as_they_are() -> None:
    """16-bit maps are packed unchanged."""
    a = np.array([[[1, 2, 3]]], np.uint16)
    b = np.array([[[65535, 40000, 5]]], np.uint16)
    packed = pack_normal_maps(a, b)
    assert packed.dtype == np.uint16 and packed[0, 0].tolist() == [1, 2, 65535, 40000]


# --------------------------------------------------------------------------- more maps

def test_a_single_wrinkled_map_gives_one_flat_layer() -> None:
    """With no map after the first, one flat layer (x = y = 128, or 32896 in 16 bits)."""
    textures = _textures(_ramp(2, 3))
    layers = pack_more_maps(textures, np.zeros((2, 3, 4), np.uint8))
    assert layers.shape == (1, 2, 3, 2) and layers.dtype == np.uint8
    assert (layers == 128).all()
    layers16 = pack_more_maps(textures, np.zeros((2, 3, 4), np.uint16))
    assert layers16.dtype == np.uint16 and (layers16 == 32896).all()


def test_the_maps_after_the_first_are_layers_in_order() -> None:
    """Maps 2, 3, … are the layers (x and y only), in the order of the maps."""
    maps = [_ramp(2, 3, start=s) for s in (0, 20, 40)]
    layers = pack_more_maps(_textures(*maps), pack_normal_maps(maps[0], maps[0]))
    assert layers.shape == (2, 2, 3, 2) and layers.flags.c_contiguous
    np.testing.assert_array_equal(layers[0], maps[1][..., :2])
    np.testing.assert_array_equal(layers[1], maps[2][..., :2])
    only_second = pack_more_maps(_textures(*maps[:2]), pack_normal_maps(maps[0], maps[0]))
    np.testing.assert_array_equal(only_second, maps[1][None, ..., :2])


def test_more_maps_take_the_packed_size() -> None:
    """A 2 × 3 map is resized (nearest) to a 4 × 6 packed texture."""
    small = _ramp(2, 3, start=30)
    layers = pack_more_maps(_textures(_ramp(4, 6), small), np.zeros((4, 6, 4), np.uint8))
    assert layers.shape == (1, 4, 6, 2)
    np.testing.assert_array_equal(layers[0, :, :, 0], [[30, 30, 31, 31, 32, 32]] * 2
                                  + [[40, 40, 41, 41, 42, 42]] * 2)


@pytest.mark.parametrize(("map_dtype", "packed_dtype", "values", "expected"), [
    (np.uint8, np.uint8, [0, 128, 255], [0, 128]),
    (np.uint8, np.uint16, [0, 128, 255], [0, 32896]),
    (np.uint8, np.uint16, [255, 1, 9], [65535, 257]),
    (np.uint16, np.uint16, [1000, 65535, 9], [1000, 65535]),
    (np.uint16, np.uint8, [0xABCD, 0x80FF, 9], [0xAB, 0x80]),
])
def test_more_maps_take_the_packed_bit_depth(map_dtype, packed_dtype, values, expected) -> None:
    """8-bit maps are widened (× 257) for a 16-bit texture, 16-bit ones keep their high byte
    for an 8-bit one; a map of the texture's own depth is kept as it is."""
    image = np.array([[values]], map_dtype)
    layers = pack_more_maps(_textures(image, image), np.zeros((1, 1, 4), packed_dtype))
    assert layers.dtype == packed_dtype
    assert layers[0, 0, 0].tolist() == expected
