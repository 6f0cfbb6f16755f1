"""Bake a wrinkled normal map from a high-polygon mesh onto the face.

The high-polygon mesh (a sculpt with the wrinkles, on the same UV layout) is sampled from the
low-polygon face the way the renderer will read the map back:

1. the face is rasterised into UV space: per texel, its triangle and barycentric coordinates,
   hence its position and the renderer's own interpolated normal, tangent and bitangent
   (``DeformCache`` builds the vertex buffer the renderer uploads, in the tangent frame the
   renderer is set to; the fragment shader builds
   ``mat3(normalize(T), normalize(B), normalize(N))`` from the interpolated ones);
2. a ray along ±N from each texel's position meets the high mesh; the nearest front-facing hit
   within ``max_distance`` gives the interpolated high normal there;
3. that normal is written in the texel's tangent frame (the inverse of the shader's TBN, so the
   shader's ``normalize(TBN · n)`` gives the high normal back) and encoded OpenGL-style, RGB =
   n·0.5 + 0.5 with green toward +v (studio.core.wrinkles.textures).

A texel whose ray meets nothing takes the high normal at the same UV (the UV correspondence),
or, outside the high mesh's UV layout, the flat normal. Texels just outside the face's UV charts
are padded from their neighbours so filtering at chart edges does not pull in flat texels.

Rays are cast against a uniform grid of the high triangles in numpy (trimesh's ray API needs
rtree or embree, which the studio does not depend on): each triangle is listed in every cell
its bounding box, grown by half a sampling step, touches, so sampling a ray every step finds
every triangle it crosses. Rays are processed in chunks and in rounds outward from the face,
and a ray leaves as soon as its nearest hit is certain, so most rays cost one or two rounds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.errors import Cancelled, MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache, vertex_normals
from studio.core.mesh.meshio import made_uvs
from studio.core.mesh.tangent_frames import DEFAULT_TANGENT_FRAME
from studio.core.mesh.uv_tiles import UvTiles, into_layout
from studio.core.wrinkles.mask_ops import rasterise_uv

Array = np.ndarray

#: Below this overlap of the two UV layouts (texels both cover / texels either covers), they are
#: taken to be different.
MIN_UV_OVERLAP = 0.75
#: Default maximum ray distance, as a share of the face's bounding-box diagonal: sculpted detail
#: and the difference between a sculpt and its low-polygon cage rarely reach farther.
DISTANCE_SHARE = 0.02
_CHECK_SIZE = 256  # resolution of the UV layout comparison
_MAX_STEPS = 16  # sampling steps along each half-ray at most: bounds a missing ray's cost
_MAX_ENTRIES = 24_000_000  # (cell, triangle) entries of the grid at most
_CHUNK = 8192  # rays per chunk: bounds the memory of the candidate pairs
_MIN_Z = 1e-3  # tangent-space z kept above this: the shader rebuilds z = sqrt(1 - x² - y²) ≥ 0


class BakeCancelled(Cancelled):
    """The user cancelled the bake; nothing was changed."""


@dataclass
class BakeResult:
    image: Array  # (size, size, 3) uint8 or uint16 tangent-space normal map, row 0 = v 1
    normals: Array  # (size, size, 3) float32 unit tangent-space normals before encoding
    covered: Array  # (size, size) bool: texels inside the face's UV layout
    hit: Array  # (size, size) bool: texels whose ray met the high mesh
    from_uv: Array  # (size, size) bool: texels that fell back to the same-UV high normal

    @property
    def hit_fraction(self) -> float:
        """Share of the face's texels that found the high mesh along their ray."""
        return float(self.hit.sum()) / max(int(self.covered.sum()), 1)


Progress = Callable[[float], None]


def sculpt_for(high: FaceMesh, tiles: UvTiles | None) -> FaceMesh:
    """The sculpt as the face is laid out: a face whose UDIM tiles were packed into one atlas
    (``Project.uv_tiles``) gets the sculpt's UDIM UVs packed into the same cells, so the two
    layouts meet; a face on one tile takes the sculpt as it is. A sculpt read without UVs (the
    reader made it some) is refused: baking needs the sculpt on the face's own UVs, and
    made-up ones would only be reported as a layout that differs."""
    if made_uvs(high) is not None:
        raise MeshError("the high-polygon mesh has no texture coordinates (UVs); baking needs "
                        "it exported with the face's UVs", high.source or None)
    return high if tiles is None else into_layout(high, tiles.layout)


def bake_normal_map(low: FaceMesh, high: FaceMesh, size: int, max_distance: float, *,
                    bits: int = 8, padding: int = 4, progress: Progress | None = None,
                    cancelled: Callable[[], bool] | None = None,
                    tangent_frame: str = DEFAULT_TANGENT_FRAME,
                    skin: Array | None = None) -> BakeResult:
    """The wrinkled normal map of ``high`` as seen from ``low`` (both in their rest pose).

    ``max_distance`` is in model units, along the face's normals both ways. ``progress`` gets
    the done fraction 0..1 now and then; ``cancelled`` is polled between chunks and raises
    ``BakeCancelled`` when it returns True. ``tangent_frame`` is the frame the renderer reads
    the map in (studio.core.mesh.tangent_frames): a map baked in another frame shades wrong.
    ``skin``: per triangle of ``low``, the skin's (``Project.skin_triangles``), which own the
    texels where eyes or teeth overlap them in UV. Raises ``MeshError`` when the UV layouts
    differ.
    """
    if bits not in (8, 16):
        raise ValueError(f"bits must be 8 or 16, got {bits}")
    if not np.isfinite(max_distance) or max_distance <= 0:
        raise MeshError(f"the maximum ray distance must be positive, got {max_distance}")
    report = progress or (lambda _: None)

    def check() -> None:
        if cancelled is not None and cancelled():
            raise BakeCancelled()

    check_same_uvs(low, high)
    report(0.02)
    ids = _triangle_ids(low, size, skin)
    rows, cols = np.nonzero(ids >= 0)
    frames = _TexelFrames(low, tangent_frame)
    check()
    report(0.06)

    # The high mesh: welded triangles and the renderer's kind of vertex normals.
    high_tris = high.welded_triangles.astype(np.intp)
    high_pos = high.rest.astype(np.float64)
    high_normals = vertex_normals(high_pos, high_tris)
    grid = _TriangleGrid(high_pos, high_tris, max_distance)
    high_ids: Array | None = None  # the high mesh's UV raster, made for the first miss
    check()
    report(0.12)

    normals = np.zeros((size, size, 3), np.float32)
    normals[..., 2] = 1.0
    hit = np.zeros((size, size), bool)
    from_uv = np.zeros((size, size), bool)
    starts = range(0, len(rows), _CHUNK)
    for k, start in enumerate(starts):
        check()
        r, c = rows[start:start + _CHUNK], cols[start:start + _CHUNK]
        tri = ids[r, c]
        position, normal, tangent, bitangent = frames.at(tri, _barycentric(low, tri, r, c, size))
        found, bary = grid.nearest_hits(position, normal, high_normals, max_distance)
        world = np.zeros((len(r), 3))
        got = found >= 0
        world[got] = _interpolate(high_normals, high_tris[found[got]], bary[got])
        if not got.all():  # the high normal at the same UV, where the high mesh has that UV
            if high_ids is None:
                high_ids = _triangle_ids(high, size)
            same = high_ids[r, c]
            use = ~got & (same >= 0)
            world[use] = _interpolate(high_normals, high_tris[same[use]],
                                      _barycentric(high, same[use], r[use], c[use], size))
            from_uv[r[use], c[use]] = True
            got |= use
        hit[r, c] = found >= 0
        normals[r[got], c[got]] = _to_tangent_space(
            world[got], tangent[got], bitangent[got], normal[got])
        report(0.12 + 0.84 * (k + 1) / len(starts))

    covered = ids >= 0
    normals = _pad(normals, covered, padding)
    report(1.0)
    return BakeResult(image=encode_normals(normals, bits), normals=normals, covered=covered,
                      hit=hit, from_uv=from_uv)


def default_max_distance(mesh: FaceMesh) -> float:
    lo, hi = mesh.bounds()
    return DISTANCE_SHARE * (float(np.linalg.norm(hi - lo)) or 1.0)


def encode_normals(normals: Array, bits: int = 8) -> Array:
    """Unit tangent-space normals to RGB, n·0.5 + 0.5 rounded (flat → (128, 128, 255))."""
    top = 255 if bits == 8 else 65535
    scaled = np.floor((np.asarray(normals, np.float64) * 0.5 + 0.5) * top + 0.5)
    return np.clip(scaled, 0, top).astype(np.uint8 if bits == 8 else np.uint16)


def check_same_uvs(low: FaceMesh, high: FaceMesh) -> None:
    """Raise ``MeshError`` naming the high mesh's file when its UV layout is not the face's."""
    a = texel_coverage(low, _CHECK_SIZE)
    b = texel_coverage(high, _CHECK_SIZE)
    both = int((a & b).sum())
    overlap = both / max(int((a | b).sum()), 1)
    if overlap < MIN_UV_OVERLAP:
        raise MeshError(
            f"its UV layout differs from the face's (only {overlap:.0%} of their UV charts "
            "overlap); baking needs the high-polygon mesh on the same UVs",
            high.source or None)


def texel_coverage(mesh: FaceMesh, size: int) -> Array:
    """(size, size) bool: the texel centres inside the mesh's UV layout."""
    return _triangle_ids(mesh, size) >= 0


def texel_samples(mesh: FaceMesh, size: int) -> tuple[Array, Array, Array, Array]:
    """The texels (row, column) whose centre lies in a triangle of the UV layout, that triangle
    and the centre's barycentric coordinates in it (rows of 3, summing to 1)."""
    ids = _triangle_ids(mesh, size)
    rows, cols = np.nonzero(ids >= 0)
    tri = ids[rows, cols]
    return rows, cols, tri, _barycentric(mesh, tri, rows, cols, size)


def _barycentric(mesh: FaceMesh, tri: Array, rows: Array, cols: Array, size: int) -> Array:
    """Barycentric coordinates of texel centres in their UV triangles (clamped inside)."""
    uv = mesh.uvs.astype(np.float64)[mesh.triangles[tri]]  # (n, 3, 2)
    centre = np.stack([(cols + 0.5) / size, 1.0 - (rows + 0.5) / size], axis=1)
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    d = centre - uv[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    det = np.where(det == 0.0, 1.0, det)
    w1 = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / det
    w2 = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / det
    bary = np.clip(np.stack([1.0 - w1 - w2, w1, w2], axis=1), 0.0, 1.0)
    return bary / bary.sum(axis=1, keepdims=True)


def _triangle_ids(mesh: FaceMesh, size: int, first: Array | None = None) -> Array:
    """(size, size) index of the triangle covering each texel centre, −1 where none does.
    Where triangles overlap in UV, one of ``first`` (a per-triangle bool: the skin's) owns the
    texel: eyes and teeth often share the skin's tile, and the skin is what wrinkles.

    ``rasterise_uv`` interpolates per-vertex values; giving each triangle its own three
    corners, all valued with its index, makes the interpolation return that index.
    """
    ids = np.full((size, size), -1, np.intp)
    groups = [np.arange(mesh.n_triangles)] if first is None else [
        np.flatnonzero(~first), np.flatnonzero(first)]  # the later group wins overlaps
    for chosen in groups:
        if not len(chosen):
            continue
        uvs = mesh.uvs[mesh.triangles[chosen]].reshape(-1, 2)
        corners = np.arange(len(uvs)).reshape(-1, 3)
        index = np.repeat(chosen.astype(np.float64), 3)
        image, covered = rasterise_uv(uvs, corners, index, size)
        ids[covered] = np.rint(image[covered]).astype(np.intp)
    return ids


def _interpolate(values: Array, corners: Array, bary: Array) -> Array:
    """Barycentric blend of per-vertex rows, normalised (for normals)."""
    out = np.einsum("nk,nkj->nj", bary, values[corners])
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-30)


def _unit(v: Array) -> Array:
    return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)


class _TexelFrames:
    """What the renderer interpolates across the face's triangles: the vertex buffer it uploads
    (position, normal, tangent) and the bitangent its vertex shader makes, w·(N×T)."""

    def __init__(self, mesh: FaceMesh, tangent_frame: str) -> None:
        buffer = DeformCache(mesh, tangent_frame).update(mesh.rest).astype(np.float64)
        n, t, w = buffer[:, 3:6], buffer[:, 6:9], buffer[:, 9:10]
        self.triangles = mesh.triangles
        self.attributes = (buffer[:, :3], n, t, w * np.cross(n, t))

    def at(self, tri: Array, bary: Array) -> tuple[Array, Array, Array, Array]:
        """Position and the fragment shader's normalised N, T and B at texels."""
        corners = self.triangles[tri]
        p, n, t, b = (np.einsum("nk,nkj->nj", bary, a[corners]) for a in self.attributes)
        return p, _unit(n), _unit(t), _unit(b)


def _to_tangent_space(world: Array, t: Array, b: Array, n: Array) -> Array:
    """Unit tangent-space normals ``x`` with ``normalize(mat3(t, b, n) · x) = world``, z ≥ 0."""
    # Rows of TBN⁻¹ are the columns' pairwise cross products over the determinant.
    bn, nt, tb = np.cross(b, n), np.cross(n, t), np.cross(t, b)
    det = np.einsum("ij,ij->i", t, bn)
    det = np.where(np.abs(det) < 1e-12, 1e-12, det)
    local = np.stack([np.einsum("ij,ij->i", r, world) for r in (bn, nt, tb)], axis=1)
    local = _unit(local / det[:, None])
    low = local[:, 2] < _MIN_Z
    if low.any():  # the high normal faces away: keep the direction, tip it just above
        xy = _unit(local[low, :2]) * np.sqrt(1.0 - _MIN_Z**2)
        local[low] = np.c_[xy, np.full(len(xy), _MIN_Z)]
    return local


class _TriangleGrid:
    """High-mesh triangles binned into a uniform grid, queried by points along rays."""

    def __init__(self, positions: Array, triangles: Array, max_distance: float) -> None:
        self.corners = triangles
        corners = positions[triangles]  # (F, 3, 3)
        e1 = corners[:, 1] - corners[:, 0]
        # Component rows (3, F): the intersection test gathers and computes on 1-D arrays.
        self.v0 = np.ascontiguousarray(corners[:, 0].T)
        self.e1 = np.ascontiguousarray(e1.T)
        self.e2 = np.ascontiguousarray((corners[:, 2] - corners[:, 0]).T)
        edge = float(np.median(np.linalg.norm(e1, axis=1))) if len(triangles) else 1.0
        # A step of about one edge keeps a cell's list short; at most _MAX_STEPS steps along
        # each half-ray bounds a missing ray's cost. Cells are one step wide.
        step = max(edge, max_distance / _MAX_STEPS, 1e-12)
        lo = corners.min(axis=1)
        hi = corners.max(axis=1)
        while True:
            margin = 0.5 * step * 1.0001
            self.origin = lo.min(axis=0) - margin
            first = np.floor((lo - margin - self.origin) / step).astype(np.int64)
            last = np.floor((hi + margin - self.origin) / step).astype(np.int64)
            span = last - first + 1
            count = span.prod(axis=1)
            if count.sum() <= _MAX_ENTRIES:
                break
            step *= 1.5  # very large triangles: coarser cells
        self.step = step
        self.dims = last.max(axis=0) + 1
        # Every (cell, triangle) entry. A cell's key is linear in its coordinates, so the keys
        # of a triangle's cells are its first cell's key plus fixed offsets, one set per shape
        # of span (a handful of shapes: triangles are about a step wide).
        key_type = np.int32 if int(self.dims.prod()) < 2**31 else np.int64
        base = self._key(first).astype(key_type)
        shapes, shape_of = np.unique(span, axis=0, return_inverse=True)
        key_parts, owner_parts = [], []
        for i, shape in enumerate(shapes):
            mine = np.flatnonzero(shape_of.reshape(-1) == i)
            offsets = self._key(np.indices(shape).reshape(3, -1).T).astype(key_type)
            key_parts.append((base[mine, None] + offsets[None, :]).ravel())
            owner_parts.append(np.repeat(mine.astype(np.int32), len(offsets)))
        keys = np.concatenate(key_parts)
        owner = np.concatenate(owner_parts)
        if key_type is np.int32:  # sorting (key, triangle) packed in one int64 beats argsort
            packed = np.sort((keys.astype(np.int64) << 32) | owner)
            keys, self.triangles = packed >> 32, (packed & 0xFFFFFFFF).astype(np.int32)
        else:
            order = np.argsort(keys)
            keys, self.triangles = keys[order], owner[order]
        self.starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])
        self.keys = keys[self.starts]
        self.counts = np.diff(np.r_[self.starts, len(keys)])

    def _key(self, cell: Array) -> Array:
        return (cell[:, 0] * self.dims[1] + cell[:, 1]) * self.dims[2] + cell[:, 2]

    def candidates(self, points: Array) -> tuple[Array, Array]:
        """(point index, triangle) pairs: the triangles listed in each point's cell."""
        cell = np.floor((points - self.origin) / self.step).astype(np.int64)
        inside = ((cell >= 0) & (cell < self.dims)).all(axis=1)
        which = np.flatnonzero(inside)
        keys = self._key(cell[which])
        at = np.minimum(np.searchsorted(self.keys, keys), len(self.keys) - 1)
        found = self.keys[at] == keys
        which, at = which[found], at[found]
        count = self.counts[at]
        point = np.repeat(which, count)
        offset = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        return point, self.triangles[np.repeat(self.starts[at], count) + offset]

    def nearest_hits(self, origin: Array, direction: Array, normals: Array,
                     max_distance: float) -> tuple[Array, Array]:
        """Per ray (the line origin + t·direction, |t| ≤ max_distance), the triangle of the
        nearest hit whose interpolated normal faces along ``direction`` (−1 for none) and the
        barycentric coordinates of that hit."""
        n = len(origin)
        best_t = np.full(n, np.inf)
        best_tri = np.full(n, -1, np.intp)
        best_bary = np.zeros((n, 3))
        active = np.arange(n)
        rounds = int(np.ceil(max_distance / self.step - 0.5))
        o_rows, d_rows = np.ascontiguousarray(origin.T), np.ascontiguousarray(direction.T)
        for r in range(rounds + 1):
            for s in ((0,) if r == 0 else (r, -r)):
                points = origin[active] + (s * self.step) * direction[active]
                local, tri = self.candidates(points)
                ray = active[local]
                t, bary, ok = self._intersect(o_rows, d_rows, ray, tri)
                ok &= np.abs(t) <= max_distance
                ray, tri, t, bary = ray[ok], tri[ok], np.abs(t[ok]), bary[ok]
                facing = np.einsum("ij,ij->i", _interpolate(normals, self.corners[tri], bary),
                                   direction[ray]) > 0.0
                ray, tri, t, bary = ray[facing], tri[facing], t[facing], bary[facing]
                order = np.lexsort((t, ray))
                ray, first = np.unique(ray[order], return_index=True)
                pick = order[first]
                better = t[pick] < best_t[ray]
                ray, pick = ray[better], pick[better]
                best_t[ray] = t[pick]
                best_tri[ray] = tri[pick]
                best_bary[ray] = bary[pick]
            # Every hit within (r + ½) steps has been seen: rays with one that near are done.
            active = active[best_t[active] > (r + 0.5) * self.step]
            if len(active) == 0:
                break
        return best_tri, best_bary

    def _intersect(self, origin: Array, direction: Array, ray: Array, tri: Array
                   ) -> tuple[Array, Array, Array]:
        """Möller–Trumbore for lines (rays ``ray`` of the (3, n) ``origin`` and ``direction``
        against triangles ``tri``): signed t, barycentric coordinates, and whether it hits."""
        ox, oy, oz = (c[ray] for c in origin)
        dx, dy, dz = (c[ray] for c in direction)
        ax, ay, az = (c[tri] for c in self.e1)
        bx, by, bz = (c[tri] for c in self.e2)
        px, py, pz = dy * bz - dz * by, dz * bx - dx * bz, dx * by - dy * bx
        det = ax * px + ay * py + az * pz
        ok = np.abs(det) > 1e-300
        inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
        sx, sy, sz = ox - self.v0[0][tri], oy - self.v0[1][tri], oz - self.v0[2][tri]
        u = (sx * px + sy * py + sz * pz) * inv
        qx, qy, qz = sy * az - sz * ay, sz * ax - sx * az, sx * ay - sy * ax
        v = (dx * qx + dy * qy + dz * qz) * inv
        t = (bx * qx + by * qy + bz * qz) * inv
        eps = 1e-9
        ok &= (u >= -eps) & (v >= -eps) & (u + v <= 1.0 + eps)
        bary = np.clip(np.stack([1.0 - u - v, u, v], axis=1), 0.0, 1.0)
        return t, bary, ok


def _pad(normals: Array, covered: Array, texels: int) -> Array:
    """Grow the charts by ``texels``: each empty texel next to filled ones takes their mean
    direction, ring by ring, so filtering at a chart's edge meets the chart's own normals."""
    out = normals.copy()
    filled = covered.copy()
    for _ in range(texels):
        padded = np.pad(out * filled[..., None], ((1, 1), (1, 1), (0, 0)))
        weight = np.pad(filled.astype(np.float32), 1)
        total = np.zeros_like(out)
        count = np.zeros(filled.shape, np.float32)
        h, w = filled.shape
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                total += padded[dy:dy + h, dx:dx + w]
                count += weight[dy:dy + h, dx:dx + w]
        grow = ~filled & (count > 0)
        if not grow.any():
            break
        out[grow] = _unit(total[grow])
        filled |= grow
    return out


MIN_HIT_FRACTION = 0.5  # below this share of the face's texels meeting the high mesh: refused


def check_hits(result: BakeResult, low: FaceMesh, distance: float,
               source: str | Path | None = None, minimum: float = MIN_HIT_FRACTION) -> None:
    """Raise MeshError naming the high mesh when too few of the face's texels met it.

    Why: a mesh on the same UVs but elsewhere, or of another face, still "bakes" (every missed
    texel falls back to the normal at the same UV) into a map that means nothing. The threshold
    and the ray distance are stated relative to the face's size, never in model units.
    """
    share = result.hit_fraction
    if share >= minimum:
        return
    lo, hi = low.bounds()
    diagonal = float(np.linalg.norm(hi - lo)) or 1.0
    raise MeshError(
        f"only {share:.0%} of the face's texels found the high-polygon mesh within "
        f"{distance / diagonal:.1%} of the face's size along their normals (at least "
        f"{minimum:.0%} must): it is not the same face, or not in the same place and scale; "
        "fix it in the modelling tool, or give a larger --distance", source)
