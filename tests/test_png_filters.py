"""The PNG Average and Paeth row filters undone exactly, alone and mixed with the other three,
for every pixel size from 8-bit grey to 16-bit RGBA, both by the row decoder that decoding uses for
them (``png_unfilter.unfilter_with_pillow``) and through whole hand-built PNG files."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from studio.core.files.png import SIGNATURE, decode_png, read_png
from studio.core.files.png_unfilter import unfilter_with_pillow

pytestmark = pytest.mark.core

NONE, SUB, UP, AVERAGE, PAETH = range(5)
COLOUR_TYPE = {1: 0, 2: 4, 3: 2, 4: 6}  # channels -> PNG colour type


def paeth(a: int, b: int, c: int) -> int:
    """The Paeth predictor exactly as the PNG specification writes it."""
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    if pb <= pc:
        return b
    return c


def filter_rows(raw: np.ndarray, kinds: list[int], bpp: int) -> np.ndarray:
    """(h, stride) pixel bytes -> (h, stride) filtered bytes, byte by byte after the spec."""
    h, stride = raw.shape
    out = np.zeros((h, stride), np.uint8)
    for y in range(h):
        for i in range(stride):
            a = int(raw[y, i - bpp]) if i >= bpp else 0
            b = int(raw[y - 1, i]) if y > 0 else 0
            c = int(raw[y - 1, i - bpp]) if y > 0 and i >= bpp else 0
            pred = (0, a, b, (a + b) // 2, paeth(a, b, c))[kinds[y]]
            out[y, i] = (int(raw[y, i]) - pred) % 256
    return out


def png_file(image: np.ndarray, kinds: list[int]) -> bytes:
    """A PNG of an (H, W, C) uint8/uint16 image, row y filtered with ``kinds[y]``."""
    h, w, channels = image.shape
    depth = 16 if image.dtype == np.uint16 else 8
    raw = np.ascontiguousarray(image.astype(">u2") if depth == 16 else image)
    rows = raw.view(np.uint8).reshape(h, -1)
    filtered = filter_rows(rows, kinds, channels * depth // 8)
    body = np.hstack([np.array(kinds, np.uint8)[:, None], filtered]).tobytes()

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", w, h, depth, COLOUR_TYPE[channels], 0, 0, 0)
    return b"".join((SIGNATURE, chunk(b"IHDR", header), chunk(b"IDAT", zlib.compress(body)),
                     chunk(b"IEND", b"")))


def unfilter(filtered: np.ndarray, kinds: list[int], bpp: int) -> np.ndarray:
    """The row decoder's pixel bytes, checked to be (h, stride) uint8."""
    out = unfilter_with_pillow(np.array(kinds, np.uint8), filtered, bpp)
    assert out.dtype == np.uint8
    assert out.shape == filtered.shape
    return out


def test_average_then_paeth_on_a_2x2_grey_image_by_hand() -> None:
    """Average adds half the left+above sum, Paeth the nearest of left/above/corner."""
    # row 0, Average: 10 - 0 = 10; 20 - (10 + 0) // 2 = 15
    # row 1, Paeth: x0: a=0 b=10 c=0, p=10 -> b: 30 - 10 = 20;
    #               x1: a=30 b=20 c=10, p=40, pa=10 pb=20 pc=30 -> a: 25 - 30 = -5 = 251
    filtered = np.array([[10, 15], [20, 251]], np.uint8)
    assert np.array_equal(filter_rows(np.array([[10, 20], [30, 25]], np.uint8),
                                      [AVERAGE, PAETH], 1), filtered)
    assert np.array_equal(unfilter(filtered, [AVERAGE, PAETH], 1), [[10, 20], [30, 25]])


def test_average_sums_above_255_without_overflow() -> None:
    """(left + above) // 2 of two large bytes is taken on the true sum, not modulo 256."""
    # row 0, None: 200 250; row 1, Average: x0 pred (0 + 200) // 2 = 100 -> 240,
    # x1 pred (240 + 250) // 2 = 245 -> 251 - 245 = 6
    filtered = np.array([[200, 250], [140, 6]], np.uint8)
    assert np.array_equal(unfilter(filtered, [NONE, AVERAGE], 1), [[200, 250], [240, 251]])


@pytest.mark.parametrize(("above", "below", "filtered_below"), [
    ((30, 40), (10, 15), (236, 5)),  # left 10, above 40, corner 30: p 20, 10/20/10 -> left
    ((48, 40), (50, 45), (2, 5)),  # left 50, above 40, corner 48: p 42, 8/2/6 -> above
    ((11, 12), (10, 20), (255, 9)),  # left 10, above 12, corner 11: p 11, 1/1/0 -> corner
])
def test_paeth_predicts_from_the_nearest_of_left_above_and_corner(
        above: tuple[int, int], below: tuple[int, int], filtered_below: tuple[int, int]) -> None:
    """The second pixel of a Paeth row takes each of the three predictions in turn (the first
    always the byte above: left and corner are zero)."""
    filtered = np.array([above, filtered_below], np.uint8)
    assert np.array_equal(filter_rows(np.array([above, below], np.uint8), [NONE, PAETH], 1),
                          filtered)
    assert np.array_equal(unfilter(filtered, [NONE, PAETH], 1), [above, below])


def test_paeth_ties_follow_the_specification_order() -> None:
    """Equal distances prefer left over above over the corner (a 4-level image is full of ties,
    so any other order decodes different bytes)."""
    rng = np.random.default_rng(3)
    raw = rng.integers(0, 4, (9, 12), dtype=np.uint8)
    filtered = filter_rows(raw, [PAETH] * 9, 1)
    assert np.array_equal(unfilter(filtered, [PAETH] * 9, 1), raw)
    steps = rng.choice(np.array([0, 1, 2, 254, 255], np.uint8), (9, 12))
    filtered = filter_rows(steps, [PAETH] * 9, 1)
    assert np.array_equal(unfilter(filtered, [PAETH] * 9, 1), steps)


@pytest.mark.parametrize("bpp", [1, 2, 3, 4, 6, 8])
@pytest.mark.parametrize(("h", "w"), [(1, 1), (1, 5), (5, 1), (3, 7), (7, 3), (6, 6)])
def test_every_filter_mix_decodes_back_to_the_pixels(bpp: int, h: int, w: int) -> None:
    """Random bytes, rows filtered None/Sub/Up/Average/Paeth in turn (and all Average, all
    Paeth), come back exactly for pixels of 1 to 8 bytes and images wide, tall or square."""
    rng = np.random.default_rng(bpp * 100 + h * 10 + w)
    raw = rng.integers(0, 256, (h, w * bpp), dtype=np.uint8)
    for kinds in ([(y + bpp) % 5 for y in range(h)], [(4 - y) % 5 for y in range(h)],
                  [AVERAGE] * h, [PAETH] * h):
        filtered = filter_rows(raw, kinds, bpp)
        assert np.array_equal(unfilter(filtered, kinds, bpp), raw), kinds


def test_rows_filtered_none_sub_and_up_between_diagonal_ones() -> None:
    """Each row is undone with its own filter, whatever its neighbours use."""
    raw = np.array([[9, 200, 31, 7], [250, 3, 3, 128], [1, 2, 255, 0], [77, 77, 0, 255],
                    [10, 20, 30, 40]], np.uint8)
    for kinds in ([NONE, SUB, UP, AVERAGE, PAETH], [PAETH, NONE, AVERAGE, SUB, UP],
                  [UP, PAETH, SUB, NONE, AVERAGE], [SUB, AVERAGE, PAETH, UP, NONE]):
        filtered = filter_rows(raw, kinds, 2)
        assert np.array_equal(unfilter(filtered, kinds, 2), raw), kinds


@pytest.mark.parametrize(("channels", "dtype"), [(1, np.uint8), (2, np.uint8), (3, np.uint8),
                                                 (4, np.uint8), (1, np.uint16), (3, np.uint16),
                                                 (4, np.uint16)])
def test_png_files_filtered_with_average_and_paeth_decode_exactly(channels: int,
                                                                  dtype: type) -> None:
    """Grey, grey+alpha, RGB and RGBA PNGs at 8 and 16 bits, rows Average and Paeth (alone and
    mixed with the others), read back pixel for pixel."""
    rng = np.random.default_rng(channels * 7 + np.dtype(dtype).itemsize)
    image = rng.integers(0, np.iinfo(dtype).max + 1, (5, 4, channels), dtype=dtype)
    want = image[:, :, 0] if channels == 1 else image
    for kinds in ([AVERAGE] * 5, [PAETH] * 5, [PAETH, AVERAGE, NONE, SUB, UP]):
        data = png_file(image, kinds)
        decoded = decode_png(data)
        assert decoded.dtype == dtype
        assert np.array_equal(decoded, want)
        assert np.array_equal(read_png(data), want)
