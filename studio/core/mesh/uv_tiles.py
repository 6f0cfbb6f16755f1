"""UDIM-tiled UV layouts, packed into the one 0–1 square every map of the studio lives in.

Heads made elsewhere often spread their UVs over several unit tiles — UDIM numbering,
``1001 + ⌊u⌋ + 10·⌊v⌋``: skin on 1001, eyes on 1002, teeth on 1003, each with its own texture
file (``skin.1001.png``, ``skin.1002.png``, …). The studio's masks, paint canvas, bake,
synthesis and shaders all work on one square image, so on import each tile is given a square
*cell* of that image (an atlas) and every UV is moved into its tile's cell; textures are
composed the same way. Skin tiles get full-size cells and the other tiles (eyes, teeth: never
wrinkled) half-size ones, so masks keep their resolution where wrinkles are painted.

The mapping is affine per tile, and each render vertex remembers its tile
(:attr:`UvTiles.vertex_tile`), so the original UDIM coordinates come back exactly for export and
every per-tile image (a mask, a wrinkled map) can be cut back out of its cell.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh

Array = np.ndarray

FIRST_TILE = 1001
SKIN_CELL = 1.0  # a skin tile's cell side, in units of a tile …
OTHER_CELL = 0.5  # … and that of a tile without skin (eyes, teeth), which never wrinkles


def udim(u: Array, v: Array) -> Array:
    """UDIM tile numbers of UV points (u in [0, 10) by the convention's columns)."""
    return (FIRST_TILE + np.floor(u) + 10 * np.floor(v)).astype(np.int64)


def tile_origin(tile: int) -> tuple[int, int]:
    """(u, v) of a tile's lower-left corner."""
    offset = int(tile) - FIRST_TILE
    return offset % 10, offset // 10


@dataclass(frozen=True)
class TileLayout:
    """Where each UDIM tile sits in the atlas: ``cells[i] = (x, y, side)`` in atlas fractions,
    ``x`` from the left and ``y`` from the top of the image (row 0 of a PNG is v = 1)."""

    tiles: tuple[int, ...]
    cells: tuple[tuple[float, float, float], ...]

    @property
    def trivial(self) -> bool:
        """One tile filling the whole square: UVs and images are as they came."""
        return self.tiles == (FIRST_TILE,) and self.cells == ((0.0, 0.0, 1.0),)

    def index(self, tile: int) -> int:
        try:
            return self.tiles.index(int(tile))
        except ValueError:
            raise StudioError(f"the UV layout has no tile {tile} "
                              f"(tiles: {', '.join(map(str, self.tiles))})") from None

    def to_atlas(self, uv: Array, tile_index: Array) -> Array:
        """UDIM coordinates of points (in their tiles) → atlas coordinates."""
        cells = np.asarray(self.cells, np.float64)[tile_index]
        origins = np.array([tile_origin(t) for t in self.tiles], np.float64)[tile_index]
        local = np.asarray(uv, np.float64) - origins
        u = cells[:, 0] + local[:, 0] * cells[:, 2]
        v = 1.0 - cells[:, 1] - (1.0 - local[:, 1]) * cells[:, 2]
        return np.stack([u, v], axis=1)

    def from_atlas(self, uv: Array, tile_index: Array) -> Array:
        """Atlas coordinates → the points' UDIM coordinates (the inverse of ``to_atlas``)."""
        cells = np.asarray(self.cells, np.float64)[tile_index]
        origins = np.array([tile_origin(t) for t in self.tiles], np.float64)[tile_index]
        uv = np.asarray(uv, np.float64)
        lu = (uv[:, 0] - cells[:, 0]) / cells[:, 2]
        lv = 1.0 - (1.0 - cells[:, 1] - uv[:, 1]) / cells[:, 2]
        return np.stack([lu, lv], axis=1) + origins

    def pixel_box(self, tile: int, size: tuple[int, int]) -> tuple[int, int, int, int]:
        """(x0, y0, x1, y1) pixels of a tile's cell in an image of ``size`` = (height, width)."""
        x, y, side = self.cells[self.index(tile)]
        h, w = size
        return (round(x * w), round(y * h), round((x + side) * w), round((y + side) * h))

    def crop(self, image: Array, tile: int) -> Array:
        """The part of an atlas image that holds one tile."""
        x0, y0, x1, y1 = self.pixel_box(tile, image.shape[:2])
        return image[y0:y1, x0:x1]

    def largest_cell(self) -> float:
        return max(side for _, _, side in self.cells)

    def to_dict(self) -> dict:
        return {"tiles": list(self.tiles), "cells": [list(c) for c in self.cells]}

    @classmethod
    def from_dict(cls, data: Mapping) -> TileLayout:
        try:
            tiles = tuple(int(t) for t in data["tiles"])
            cells = tuple((float(x), float(y), float(s)) for x, y, s in data["cells"])
        except (KeyError, TypeError, ValueError):
            raise StudioError("the UV tile layout is damaged") from None
        if not tiles or len(tiles) != len(cells) or len(set(tiles)) != len(tiles):
            raise StudioError("the UV tile layout is damaged")
        if any(min(x, y) < 0 or s <= 0 or max(x, y) + s > 1 + 1e-9 for x, y, s in cells):
            raise StudioError("the UV tile layout has a cell outside the square")
        return cls(tiles, cells)


SINGLE = TileLayout((FIRST_TILE,), ((0.0, 0.0, 1.0),))


def plan_layout(tiles: Iterable[int], skin_tiles: Iterable[int] = ()) -> TileLayout:
    """Square cells for the tiles in one square, skin tiles twice the side of the others.

    The sides are powers of two of each other, so a buddy allocation packs them with no gap
    (largest first, each into the smallest free square that holds it, splitting squares in
    four); the atlas side is the smallest power of two (in tile units) whose area holds all.
    """
    tiles = sorted({int(t) for t in tiles})
    if not tiles:
        raise StudioError("a UV layout needs at least one tile")
    skin = set(skin_tiles) or set(tiles)
    if tiles == [FIRST_TILE]:
        return SINGLE
    sides = {t: SKIN_CELL if t in skin else OTHER_CELL for t in tiles}
    area = sum(s * s for s in sides.values())
    atlas = 1.0
    while atlas * atlas < area - 1e-9:
        atlas *= 2.0
    free: list[tuple[float, float, float]] = [(0.0, 0.0, atlas)]
    placed: dict[int, tuple[float, float, float]] = {}
    for tile in sorted(tiles, key=lambda t: (-sides[t], t)):
        need = sides[tile]
        free.sort(key=lambda c: (c[2], c[1], c[0]))
        k = next(i for i, c in enumerate(free) if c[2] >= need - 1e-9)
        x, y, s = free.pop(k)
        while s > need + 1e-9:  # split into four, keep the top-left, free the rest
            s /= 2.0
            free += [(x + s, y, s), (x, y + s, s), (x + s, y + s, s)]
        placed[tile] = (x / atlas, y / atlas, s / atlas)
    return TileLayout(tuple(tiles), tuple(placed[t] for t in tiles))


@dataclass(eq=False)
class UvTiles:
    """A project's tile layout and the tile of each render vertex (the mesh's UVs are atlas
    coordinates; these give the original UDIM ones back)."""

    layout: TileLayout
    vertex_tile: Array  # (V,) int16: index into layout.tiles

    def __post_init__(self) -> None:
        self.vertex_tile = np.ascontiguousarray(self.vertex_tile, dtype=np.int16)
        if len(self.vertex_tile) and (self.vertex_tile.min() < 0
                                      or self.vertex_tile.max() >= len(self.layout.tiles)):
            raise StudioError("a vertex names a UV tile the layout does not have")

    def udim_uvs(self, mesh: FaceMesh) -> Array:
        """The mesh's UVs in their original tiles."""
        return self.layout.from_atlas(mesh.uvs, self.vertex_tile).astype(np.float32)


def triangle_tiles(uvs: Array, triangles: Array) -> Array:
    """Each triangle's UDIM tile: the one holding its UV centroid (a corner may lie on the
    tile's edge, the centroid never does in a layout that keeps islands inside tiles)."""
    centroid = np.asarray(uvs, np.float64)[triangles].mean(axis=1)
    return udim(centroid[:, 0], centroid[:, 1])


def pack_mesh(mesh: FaceMesh, skin_vertices: Array | None = None
              ) -> tuple[FaceMesh, UvTiles | None]:
    """The mesh with its UVs moved into an atlas, and its tiles; (mesh, None) when every UV is
    already in the first tile. ``skin_vertices`` (per welded vertex) decides which tiles hold
    skin and get full-size cells.

    A render vertex used by triangles of two tiles is split, one copy per tile. UVs outside
    u ∈ [0, 10) or with v < 0 are not UDIM and are refused, naming the file.
    """
    tri_tile = _udim_tiles(mesh)
    if (tri_tile == FIRST_TILE).all():
        return mesh, None
    skin_tri = (np.ones(mesh.n_triangles, bool) if skin_vertices is None
                else np.asarray(skin_vertices, bool)[mesh.welded_triangles].any(axis=1))
    layout = plan_layout(tri_tile, set(tri_tile[skin_tri].tolist()))
    return _into(mesh, tri_tile, layout)


def into_layout(mesh: FaceMesh, layout: TileLayout) -> FaceMesh:
    """Another mesh of the same head (a sculpt to bake from) with its UDIM UVs moved into a
    project's atlas ``layout``, so that its UVs meet the face's; a tile the layout lacks is
    refused, naming the file."""
    tri_tile = _udim_tiles(mesh)
    missing = sorted(set(tri_tile.tolist()) - set(layout.tiles))
    if missing:
        raise StudioError(f"the UVs use tile {', '.join(map(str, missing))}, which the face "
                          f"does not (its tiles: {', '.join(map(str, layout.tiles))})",
                          mesh.source or None)
    return _into(mesh, tri_tile, layout)[0]


def _udim_tiles(mesh: FaceMesh) -> Array:
    """Each triangle's tile; UVs outside the UDIM range are refused, naming the file."""
    centroid = mesh.uvs[mesh.triangles].mean(axis=1)
    if (centroid[:, 0] < 0).any() or (centroid[:, 0] >= 10).any() or (centroid[:, 1] < 0).any():
        raise StudioError("the UVs lie outside the UDIM range (u from 0 to 10, v from 0): "
                          "the texture layout cannot be read", mesh.source or None)
    return triangle_tiles(mesh.uvs, mesh.triangles)


def _into(mesh: FaceMesh, tri_tile: Array, layout: TileLayout) -> tuple[FaceMesh, UvTiles]:
    """The mesh with each triangle's UVs placed in its tile's cell of ``layout``; a render
    vertex on triangles of two tiles split into a copy per tile."""
    corner_tile = np.repeat(tri_tile, 3)
    corner_vertex = mesh.triangles.ravel().astype(np.int64)
    keys, inverse = np.unique(np.stack([corner_vertex, corner_tile], axis=1), axis=0,
                              return_inverse=True)
    vertex, tile = keys[:, 0], keys[:, 1]
    tile_index = np.searchsorted(np.asarray(layout.tiles), tile)
    uvs = layout.to_atlas(mesh.uvs[vertex], tile_index)
    packed = FaceMesh(mesh.rest, inverse.reshape(-1, 3), uvs, mesh.weld[vertex],
                      source=mesh.source)
    return packed, UvTiles(layout, tile_index)


def compose_atlas(images: Mapping[int, Array], layout: TileLayout, fill: Array,
                  size: int) -> Array:
    """One (size, size, C) image with each tile's image resized into its cell; cells without
    an image (and the gaps) take ``fill``, a (C,) colour or an image to resize per cell."""
    first = next(iter(images.values()), None)
    dtype = first.dtype if first is not None else np.asarray(fill).dtype
    channels = first.shape[2] if first is not None else np.asarray(fill).shape[-1]
    out = np.empty((size, size, channels), dtype)
    fill = np.asarray(fill)
    if fill.ndim == 1:
        out[...] = fill.astype(dtype)
    for tile in layout.tiles:
        x0, y0, x1, y1 = layout.pixel_box(tile, (size, size))
        source = images.get(tile)
        if source is None:
            source = fill if fill.ndim == 3 else None
        if source is None:
            continue
        out[y0:y1, x0:x1] = _resize(_match_dtype(source, dtype), y1 - y0, x1 - x0)
    return out


def _match_dtype(image: Array, dtype: np.dtype) -> Array:
    if image.dtype == dtype:
        return image
    if dtype == np.uint16:
        return image.astype(np.uint16) * 257
    return (image >> 8).astype(np.uint8)


ROWS_AT_ONCE = 256  # input rows averaged together by _resize


def _resize(image: Array, height: int, width: int) -> Array:
    """Area-average when shrinking by a whole factor (no aliasing of fine detail such as
    pores), nearest texel otherwise."""
    h, w = image.shape[:2]
    if (h, w) == (height, width):
        return image
    if h % height == 0 and w % width == 0:
        fy, fx = h // height, w // width
        out = np.empty((height, width, *image.shape[2:]), image.dtype)
        step = max(1, ROWS_AT_ONCE // fy)  # a band of output rows at a time: a 4096² map
        for top in range(0, height, step):  # costs a band in float32, not the whole in float64
            band = image[top * fy:(top + step) * fy]
            rows = len(band) // fy
            blocks = band.reshape(rows, fy, width, fx, -1).astype(np.float32).mean(axis=(1, 3))
            out[top:top + rows] = np.rint(blocks).astype(image.dtype).reshape(
                rows, width, *image.shape[2:])
        return out
    rows = np.arange(height) * h // height
    cols = np.arange(width) * w // width
    return image[rows][:, cols]


def atlas_size(layout: TileLayout, tile_size: int, limit: int = 4096) -> int:
    """Side of an atlas that keeps ``tile_size`` texels across a full-size cell, within
    ``limit`` (a power of two when the tile size is one)."""
    return int(min(limit, max(1, round(tile_size / layout.largest_cell()))))
