"""The UDIM atlas worked out by hand: one skin tile and five eye/teeth tiles.

A head made elsewhere puts its skin in tile 1001 and its eyes, teeth and tongue in 1002–1006;
the studio packs them into one square texture, the skin at full size and the others at half
(their texels never wrinkle). By hand: the cells' total area is 1 + 5 · ¼ = 2.25 tile², so the
atlas is 2 tiles wide; 1001 takes the top-left quarter, the half-size tiles fill the
top-right quarter row by row, then the bottom-left. Every coordinate below follows from that.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.mesh.uv_tiles import _resize, compose_atlas, plan_layout

pytestmark = pytest.mark.core

TILES = [1001, 1002, 1003, 1004, 1005, 1006]
CELLS = {  # (x, y, side) as fractions of the atlas, y from the top
    1001: (0.0, 0.0, 0.5),
    1002: (0.5, 0.0, 0.25),
    1003: (0.75, 0.0, 0.25),
    1004: (0.5, 0.25, 0.25),
    1005: (0.75, 0.25, 0.25),
    1006: (0.0, 0.5, 0.25),
}


@pytest.fixture(scope="module")
def layout():
    return plan_layout(reversed(TILES), skin_tiles={1001})


def test_cells_by_hand(layout) -> None:
    assert layout.tiles == tuple(TILES)
    assert dict(zip(layout.tiles, layout.cells, strict=True)) == CELLS
    assert layout.largest_cell() == 0.5


def test_a_point_goes_into_its_tiles_cell_and_back(layout) -> None:
    """Tile 1004 (origin u = 3, v = 0), local point (0.2, 0.6): atlas u = 0.5 + 0.2 · 0.25,
    v = 1 − 0.25 − (1 − 0.6) · 0.25 (the cell's top is 0.25 below the atlas' top)."""
    udim = np.array([[3.2, 0.6], [0.5, 0.5]])
    index = np.array([3, 0])
    atlas = layout.to_atlas(udim, index)
    assert np.allclose(atlas, [[0.55, 0.65], [0.25, 0.75]])
    assert np.allclose(layout.from_atlas(atlas, index), udim)


def test_a_cells_pixels_in_a_wide_image(layout) -> None:
    assert layout.pixel_box(1004, (100, 200)) == (100, 25, 150, 50)
    assert layout.pixel_box(1006, (100, 200)) == (0, 50, 50, 75)


def test_a_layout_needs_a_tile() -> None:
    with pytest.raises(StudioError) as caught:
        plan_layout([])
    assert str(caught.value) == "a UV layout needs at least one tile"


def test_tiles_without_an_image_take_the_fill_and_the_rest_still_land(layout) -> None:
    """16-bit skin, an 8-bit eye two tiles later, nothing for 1002: the eye is widened to 16
    bits (× 257) and lands in its cell although the tile before it had no image."""
    skin = np.full((8, 8, 3), 40000, np.uint16)
    eye = np.full((4, 4, 3), 200, np.uint8)
    atlas = compose_atlas({1001: skin, 1004: eye}, layout, np.array([1, 2, 3], np.uint16), 16)
    assert atlas.dtype == np.uint16 and atlas.shape == (16, 16, 3)
    assert (atlas[0:8, 0:8] == 40000).all()
    assert (atlas[4:8, 8:12] == 200 * 257).all()
    assert (atlas[0:4, 8:12] == [1, 2, 3]).all()  # 1002: no image
    assert (atlas[12:16, 12:16] == [1, 2, 3]).all()  # a gap


def test_a_size_that_only_one_side_divides_is_resized_by_nearest_texel() -> None:
    image = np.arange(12, dtype=np.uint8).reshape(4, 3, 1)
    assert _resize(image, 2, 2)[..., 0].tolist() == [[0, 1], [6, 7]]
    # both sides divide: averaged blocks, rounded
    assert _resize(image[:, :2], 2, 1)[..., 0].tolist() == [[2], [8]]
