"""UDIM tiles packed into the atlas: layouts, coordinates and images worked out by hand."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.files.images import write_png
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import (
    SINGLE,
    TileLayout,
    compose_atlas,
    pack_mesh,
    plan_layout,
    triangle_tiles,
    udim,
)
from studio.core.project.texture_sets import find_tile_set, load_texture


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
