"""Images in bounded memory (issue #39): the PNG decoder and encoder work a band of rows at a
time and in place, so a texture at the image budget costs about twice its decoded size, not
five or six times; and the bands join exactly (each band's first row refers to the row above
it, from the band before).

The reference is the spec's own filter arithmetic (tests/test_png_filters.py) on random pixels,
with every filter in every row position, at band sizes that split the image anywhere.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files import png_unfilter
from studio.core.files.png import decode_png, encode_png
from tests.test_png_filters import filter_rows, png_file

pytestmark = pytest.mark.core


@pytest.mark.parametrize("band_rows", [1, 2, 3, 7])
@pytest.mark.parametrize("bpp", [1, 3, 4, 6, 8])
def test_pillow_unfiltering_in_bands_joins_exactly(monkeypatch: pytest.MonkeyPatch,
                                                   band_rows: int, bpp: int) -> None:
    rng = np.random.default_rng(bpp * 10 + band_rows)
    h, w = 11, 5
    raw = rng.integers(0, 256, (h, w * bpp), dtype=np.uint8)
    kinds = [4, 3, 4, 1, 3, 2, 4, 0, 3, 4, 4]  # Paeth and Average after every other kind
    filtered = filter_rows(raw, kinds, bpp)
    monkeypatch.setattr(png_unfilter, "_BAND_BYTES", band_rows * w * bpp)
    kinds_array = np.array(kinds, np.uint8)
    np.testing.assert_array_equal(png_unfilter.unfilter_with_pillow(
        kinds_array, filtered, bpp), raw)
    in_place = filtered.copy()  # as the decoder calls it: the filtered bytes become the pixels
    png_unfilter.unfilter_with_pillow(kinds_array, in_place, bpp, in_place)
    np.testing.assert_array_equal(in_place, raw)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("kinds", [[2] * 9, [1] * 9, [0, 2, 2, 1, 2, 2, 0, 2, 2],
                                   [2, 1, 2, 1, 2, 1, 2, 1, 2]])
def test_whole_files_decode_in_place_exactly(dtype: type, kinds: list[int]) -> None:
    """None, Sub and Up undone in the output array itself (Up restarting after each row that
    is not Up), 8- and 16-bit, RGB."""
    rng = np.random.default_rng(len(kinds) + sum(kinds))
    image = rng.integers(0, np.iinfo(dtype).max, (9, 6, 3), dtype=dtype)
    np.testing.assert_array_equal(decode_png(png_file(image, kinds)), image)


@pytest.mark.parametrize("height", [1, 255, 256, 257, 600])
def test_encoding_in_blocks_round_trips(height: int) -> None:
    """Rows filtered a block at a time: the first row of each block refers to the last of the
    block before, whatever the height."""
    rng = np.random.default_rng(height)
    image = rng.integers(0, 65535, (height, 3, 4), dtype=np.uint16)
    np.testing.assert_array_equal(decode_png(encode_png(image)), image)
