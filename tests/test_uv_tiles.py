"""UDIM tiles packed into the atlas: layouts, coordinates and images worked out by hand."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.files.images import write_png
from studio.core.formats.texture_sets import find_tile_set, load_texture
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import (
    SINGLE,
    TileLayout,
    UvTiles,
    atlas_size,
    compose_atlas,
    pack_mesh,
    plan_layout,
    triangle_tiles,
    udim,
)

pytestmark = pytest.mark.core


def test_udim_numbers_follow_the_convention():
    u = np.array([0.5, 1.5, 9.5, 0.5, 2.0])
    v = np.array([0.5, 0.5, 0.5, 1.5, 0.25])
    assert udim(u, v).tolist() == [1001, 1002, 1010, 1011, 1003]


def test_one_skin_tile_and_two_others_share_an_atlas_two_tiles_wide():
    # skin side 1, others 1/2: area 1.5 → a 2 × 2 atlas; skin top-left (half the side), the
    # others a quarter of the side each, next to it in the top row
    layout = plan_layout([1003, 1001, 1002], skin_tiles=[1001])
    assert layout.tiles == (1001, 1002, 1003)
    assert layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.25), (0.75, 0.0, 0.25))
    assert plan_layout([1001]) is SINGLE and SINGLE.trivial
    # four skin tiles fill a 2 × 2 atlas exactly
    four = plan_layout([1001, 1002, 1011, 1012])
    assert sorted(four.cells) == [(0.0, 0.0, 0.5), (0.0, 0.5, 0.5), (0.5, 0.0, 0.5),
                                  (0.5, 0.5, 0.5)]


def test_cells_never_overlap_and_stay_in_the_square():
    rng = np.random.default_rng(1)
    for _ in range(20):
        tiles = sorted(set(rng.integers(1001, 1040, size=rng.integers(1, 12)).tolist()))
        skin = [t for t in tiles if rng.random() < 0.4]
        cells = np.array(plan_layout(tiles, skin).cells)
        assert (cells[:, :2] >= 0).all() and (cells[:, :2] + cells[:, 2:] <= 1 + 1e-9).all()
        for i in range(len(cells)):
            for j in range(i + 1, len(cells)):
                (xa, ya, sa), (xb, yb, sb) = cells[i], cells[j]
                overlap_x = min(xa + sa, xb + sb) - max(xa, xb)
                overlap_y = min(ya + sa, yb + sb) - max(ya, yb)
                assert overlap_x <= 1e-9 or overlap_y <= 1e-9


def test_atlas_coordinates_go_there_and_back():
    layout = plan_layout([1001, 1002, 1003], skin_tiles=[1001])
    uv = np.array([[0.0, 0.0], [1.0, 1.0], [1.25, 0.5], [2.75, 0.25]])
    tile = np.array([0, 0, 1, 2])
    atlas = layout.to_atlas(uv, tile)
    # tile 1001's cell: x 0–0.5, y from the top 0–0.5 → v 0.5–1
    np.testing.assert_allclose(atlas[:2], [[0.0, 0.5], [0.5, 1.0]])
    # tile 1002 (0.5, 0, 0.25): local (0.25, 0.5) → u 0.5 + 0.0625, v 1 − 0.25 + 0.125
    np.testing.assert_allclose(atlas[2], [0.5625, 0.875])
    np.testing.assert_allclose(layout.from_atlas(atlas, tile), uv, atol=1e-12)


def test_a_vertex_used_by_two_tiles_is_split_and_every_uv_lands_in_its_cell():
    # two triangles sharing the vertex (1, 0)–(1, 1) edge: one in tile 1001, one in 1002
    rest = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]],
                    np.float32)
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], np.float32)
    tris = np.array([[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]])
    mesh = FaceMesh(rest, tris, uvs, np.arange(6))
    assert triangle_tiles(mesh.uvs, mesh.triangles).tolist() == [1001, 1001, 1002, 1002]
    packed, tiles = pack_mesh(mesh)
    assert tiles.layout.tiles == (1001, 1002)
    assert packed.n_vertices == 8  # vertices 1 and 2 are in both tiles
    assert packed.uvs.min() >= 0.0 and packed.uvs.max() <= 1.0
    # same geometry, same welded positions, and the UDIM coordinates come back exactly
    np.testing.assert_array_equal(packed.rest[packed.welded_triangles], rest[tris])
    np.testing.assert_allclose(tiles.udim_uvs(packed)[packed.triangles], uvs[tris], atol=1e-6)
    untouched, none = pack_mesh(FaceMesh(rest[:4], tris[:2], uvs[:4], np.arange(4)))
    assert none is None and untouched.n_vertices == 4


def test_uvs_outside_the_udim_range_are_refused_with_the_file():
    rest = np.eye(3, dtype=np.float32)
    mesh = FaceMesh(rest, np.array([[0, 1, 2]]), np.array([[-3, 0], [-2, 0], [-3, 1]]),
                    np.arange(3), source="head.obj")
    with pytest.raises(StudioError, match=r"head\.obj.*UDIM"):
        pack_mesh(mesh)


def test_compose_puts_each_tile_in_its_cell_and_fills_the_rest():
    layout = plan_layout([1001, 1002], skin_tiles=[1001])  # 1001: (0, 0, 0.5), 1002 beside
    red = np.full((4, 4, 3), (200, 0, 0), np.uint8)
    atlas = compose_atlas({1001: red}, layout, np.array([1, 2, 3], np.uint8), 16)
    assert (atlas[:8, :8] == (200, 0, 0)).all()  # tile 1001 resized into its 8 × 8 cell
    assert (atlas[:4, 8:12] == (1, 2, 3)).all()  # 1002 has no image: the fill
    assert (atlas[8:, :] == (1, 2, 3)).all()  # the unused part of the atlas


def test_damaged_layouts_are_refused():
    with pytest.raises(StudioError):
        TileLayout.from_dict({"tiles": [1001], "cells": [[0.7, 0.0, 0.5]]})
    with pytest.raises(StudioError):
        TileLayout.from_dict({"tiles": [1001, 1001], "cells": [[0, 0, 0.5], [0.5, 0, 0.5]]})
    with pytest.raises(StudioError):
        TileLayout.from_dict({"tiles": "x"})


def test_a_udim_texture_set_is_found_from_any_of_its_files(tmp_path):
    for tile, value in ((1001, 10), (1002, 20), (1003, 30)):
        write_png(tmp_path / f"skin.{tile}.png", np.full((8, 8, 3), value, np.uint8))
    write_png(tmp_path / "skin_other.png", np.zeros((2, 2, 3), np.uint8))
    found = find_tile_set(tmp_path / "skin.1002.png")
    assert sorted(found.files) == [1001, 1002, 1003]
    assert sorted(find_tile_set(tmp_path / "skin.<UDIM>.png").files) == [1001, 1002, 1003]
    assert list(find_tile_set(tmp_path / "skin_other.png").files) == [1001]
    layout = plan_layout([1001, 1002, 1003], skin_tiles=[1001])
    atlas = load_texture(tmp_path / "skin.1001.png", layout, np.array([0, 0, 0], np.uint8))
    assert atlas.shape == (16, 16, 3)  # 8 texels across the skin cell, half the side
    assert (layout.crop(atlas, 1001) == 10).all()
    assert (layout.crop(atlas, 1002) == 20).all() and (layout.crop(atlas, 1003) == 30).all()
    with pytest.raises(StudioError, match="UDIM pattern"):
        find_tile_set(tmp_path / "none.<UDIM>.png")


# --- by hand: the layout's record, coordinates, images and packing (each value worked out) ---


THREE = plan_layout([1011, 1002, 1001], skin_tiles=[1001])  # skin 1001 twice the others' side


def test_three_tiles_sit_where_the_buddy_packing_puts_them():
    assert THREE.tiles == (1001, 1002, 1011)
    assert THREE.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.25), (0.75, 0.0, 0.25))
    assert THREE.largest_cell() == 0.5 and not THREE.trivial and SINGLE.trivial
    assert plan_layout([1001]) is SINGLE
    assert plan_layout([1002]).cells == ((0.0, 0.0, 1.0),) and not plan_layout([1002]).trivial
    assert THREE.pixel_box(1002, (16, 16)) == (8, 0, 12, 4)
    assert THREE.pixel_box(1011, (8, 16)) == (12, 0, 16, 2)  # (height, width)
    assert THREE.index(1011) == 2
    with pytest.raises(StudioError, match=r"no tile 1003 \(tiles: 1001, 1002, 1011\)"):
        THREE.index(1003)


def test_atlas_coordinates_by_hand_and_back():
    udim_uv = np.array([[0.5, 0.5], [1.25, 0.5], [0.5, 1.75], [0.0, 1.0]])
    index = np.array([0, 1, 2, 0])
    # 1002's point (0.25, 0.5) in its tile → 0.5 + 0.25·0.25, 1 − (1 − 0.5)·0.25
    expected = [[0.25, 0.75], [0.5625, 0.875], [0.875, 0.9375], [0.0, 1.0]]
    atlas = THREE.to_atlas(udim_uv, index)
    np.testing.assert_allclose(atlas, expected, atol=1e-12)
    np.testing.assert_allclose(THREE.from_atlas(atlas, index), udim_uv, atol=1e-12)


def test_the_layout_record_round_trips_and_every_damage_is_named():
    record = THREE.to_dict()
    assert record == {"tiles": [1001, 1002, 1011],
                      "cells": [[0.0, 0.0, 0.5], [0.5, 0.0, 0.25], [0.75, 0.0, 0.25]]}
    assert TileLayout.from_dict(record) == THREE
    assert TileLayout.from_dict({"tiles": ["1001"], "cells": [["0", "0", "1"]]}) == \
        TileLayout((1001,), ((0.0, 0.0, 1.0),))
    damaged = [{"cells": [[0, 0, 1]]}, {"tiles": [1001]}, {"tiles": [1001], "cells": [[0, 0]]},
               {"tiles": ["x"], "cells": [[0, 0, 1]]}, {"tiles": [1001], "cells": [[0, "y", 1]]},
               {"tiles": [], "cells": []}, {"tiles": [1001, 1002], "cells": [[0, 0, 0.5]]},
               {"tiles": [1001, 1001], "cells": [[0, 0, 0.5], [0.5, 0, 0.5]]}, None]
    for data in damaged:
        with pytest.raises(StudioError, match=r"^the UV tile layout is damaged$"):
            TileLayout.from_dict(data)
    outside = [[-0.1, 0, 0.5], [0, -0.1, 0.5], [0, 0, 0], [0.6, 0, 0.5], [0, 0.6, 0.5]]
    for cell in outside:
        with pytest.raises(StudioError, match=r"^the UV tile layout has a cell outside the sq"):
            TileLayout.from_dict({"tiles": [1001], "cells": [cell]})
    assert TileLayout.from_dict({"tiles": [1001], "cells": [[0.5, 0.5, 0.5]]}).cells == \
        ((0.5, 0.5, 0.5),)  # touching the far edges is inside


def test_vertex_tiles_are_checked_and_give_the_udim_uvs_back():
    tiles = UvTiles(THREE, [0, 1, 2])
    assert tiles.vertex_tile.dtype == np.int16
    mesh = FaceMesh(np.zeros((3, 3), np.float32), np.array([[0, 1, 2]]),
                    THREE.to_atlas(np.array([[0.5, 0.5], [1.25, 0.5], [0.5, 1.75]]),
                                   np.array([0, 1, 2])).astype(np.float32), np.arange(3))
    np.testing.assert_allclose(tiles.udim_uvs(mesh), [[0.5, 0.5], [1.25, 0.5], [0.5, 1.75]],
                               atol=1e-6)
    assert UvTiles(THREE, np.zeros(0)).vertex_tile.shape == (0,)
    for bad in ([0, 3], [-1, 0]):
        with pytest.raises(StudioError, match="names a UV tile the layout does not have"):
            UvTiles(THREE, bad)
    UvTiles(THREE, [2, 2])  # the last tile is fine


def test_images_change_depth_and_size_by_hand():
    grey8 = np.array([[[200]]], np.uint8)
    atlas16 = compose_atlas({1001: grey8}, SINGLE, np.array([0], np.uint16), 1)
    # the first image decides the atlas's depth (a 16-bit fill does not)
    assert atlas16.dtype == np.uint8 and atlas16[0, 0, 0] == 200
    deep = np.array([[[51400]]], np.uint16)  # 200·257
    mixed = compose_atlas({1001: deep, 1002: grey8}, plan_layout([1001, 1002]),
                          np.array([7], np.uint16), 2)
    assert mixed.dtype == np.uint16
    assert mixed[0, 0, 0] == 51400 and mixed[0, 1, 0] == 51400  # 1002's 200 → 200·257
    shallow = compose_atlas({1001: grey8, 1002: deep}, plan_layout([1001, 1002]),
                            np.array([7], np.uint8), 2)
    assert shallow[0, 1, 0] == 200 and shallow[1, 0, 0] == 7  # 51400 >> 8; the fill below
    block = np.arange(16, dtype=np.uint8).reshape(4, 4, 1)
    shrunk = compose_atlas({1001: block}, SINGLE, np.array([0], np.uint8), 2)[..., 0]
    # area average of each 2 × 2 block: (0+1+4+5)/4 = 2.5 → 2 (rint, to even), …
    np.testing.assert_array_equal(shrunk, [[2, 4], [10, 12]])
    picked = compose_atlas({1001: np.arange(9, dtype=np.uint8).reshape(3, 3, 1)}, SINGLE,
                           np.array([0], np.uint8), 2)[..., 0]
    np.testing.assert_array_equal(picked, [[0, 1], [3, 4]])  # 3 → 2: nearest texel (0, 1)
    fill_image = np.full((2, 2, 1), 9, np.uint8)
    filled = compose_atlas({}, plan_layout([1001, 1002]), fill_image, 4)
    assert (filled[:2, :4] == 9).all()  # both cells take the fill image


def test_atlas_size_keeps_the_tile_resolution_within_the_limit():
    assert atlas_size(THREE, 1024) == 2048  # the skin cell is half the atlas
    assert atlas_size(THREE, 4096) == 4096 and atlas_size(THREE, 4096, limit=8192) == 8192
    assert atlas_size(SINGLE, 1000) == 1000 and atlas_size(SINGLE, 0) == 1


def test_packing_splits_a_vertex_shared_by_two_tiles_and_sizes_cells_by_skin():
    rest = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], np.float32)
    # triangle 0 in tile 1001; triangle 1 shares welded vertices 1 and 2 but its UVs lie in
    # 1002 (render vertices 4 and 5 are their copies there)
    mesh = FaceMesh(rest, np.array([[0, 1, 2], [4, 3, 5]]),
                    np.array([[0.2, 0.2], [0.9, 0.2], [0.2, 0.9], [1.8, 0.2],
                              [1.9, 0.2], [1.2, 0.9]], np.float32),
                    np.array([0, 1, 2, 3, 1, 2]), source="head.obj")
    assert triangle_tiles(mesh.uvs, mesh.triangles).tolist() == [1001, 1002]
    packed, tiles = pack_mesh(mesh, skin_vertices=np.array([True, False, False, False]))
    assert tiles.layout.tiles == (1001, 1002)
    assert tiles.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.25))  # skin tile twice as big
    assert packed.n_vertices == 6 and sorted(tiles.vertex_tile.tolist()) == [0, 0, 0, 1, 1, 1]
    np.testing.assert_array_equal(packed.rest, rest)
    corners = tiles.udim_uvs(packed)[packed.triangles]
    np.testing.assert_allclose(corners, mesh.uvs[mesh.triangles], atol=1e-6)
    np.testing.assert_array_equal(packed.weld[packed.triangles], mesh.weld[mesh.triangles])
    # the atlas UVs of tile 1001's corner (0.2, 0.2): 0 + 0.2·0.5, 1 − (1 − 0.2)·0.5
    np.testing.assert_allclose(packed.uvs[packed.triangles[0, 0]], [0.1, 0.6], atol=1e-6)
    _, all_skin = pack_mesh(mesh)
    assert all_skin.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.5))
    one_tile = FaceMesh(rest[:3], np.array([[0, 1, 2]]), mesh.uvs[:3], np.arange(3))
    assert pack_mesh(one_tile) == (one_tile, None)
    for uv in ([[10.2, 0.2], [10.5, 0.2], [10.2, 0.5]], [[-0.5, 0.2], [-0.2, 0.2], [-0.5, 0.5]],
               [[1.2, -0.8], [1.5, -0.8], [1.2, -0.5]]):
        outside = FaceMesh(rest[:3], np.array([[0, 1, 2]]), np.array(uv, np.float32),
                           np.arange(3), source="head.obj")
        with pytest.raises(StudioError, match="outside the UDIM range") as info:
            pack_mesh(outside)
        assert "head.obj" in str(info.value)
