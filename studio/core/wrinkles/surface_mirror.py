"""Where a brush dab lands on the face's surface: points in UV charts, across UV seams, and
mirrored through the mesh (numpy only).

Why through the mesh: mirroring a mask in UV (u → 1 − u) is only right when the UV layout is
itself symmetric. Reflecting the dab's 3-D point across the face's symmetry plane and finding
the surface there works for any layout: a UV point becomes a 3-D point through the UV triangle
under it (barycentric coordinates), is reflected (x = 0 by default, as
studio.core.mesh.selection.mirror_map), lands on the closest triangle of the neutral mesh, and that
triangle's UVs give the mirrored UV. The neutral mesh is used even while the face is posed, so an
asymmetric expression does not shift the mirror image.

Both lookups (a UV point → its UV triangle; a 3-D point → the closest surface triangle) go
through ``TriangleGrid``: triangles binned once per mesh in a uniform grid, queried for many
points at once without loops over triangles.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh

Array = np.ndarray
SCALE_LIMITS = (0.2, 5.0)  # a mirrored dab is at most this much smaller / larger in UV
EXTRAPOLATE = -1.5  # lowest barycentric weight at which a neighbouring triangle's UVs still hold


# --- points and triangles ------------------------------------------------------------------------

def _dot(a: Array, b: Array) -> Array:
    return np.einsum("ij,ij->i", a, b)


def plane_barycentric(points: Array, a: Array, b: Array, c: Array) -> tuple[Array, Array]:
    """Barycentric coordinates (M, 3) of points projected on their triangles' planes — negative
    outside the triangle — and which triangles were not degenerate. Any dimension (2-D UVs or
    3-D positions); one triangle per point."""
    e1, e2, d = b - a, c - a, points - a
    d11, d12, d22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    r1, r2 = _dot(d, e1), _dot(d, e2)
    det = d11 * d22 - d12 * d12
    ok = det > 1e-12 * np.maximum(d11 * d22, 1e-300)
    inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
    v = (d22 * r1 - d12 * r2) * inv
    w = (d11 * r2 - d12 * r1) * inv
    bary = np.stack([1.0 - v - w, v, w], axis=1)
    bary[~ok] = (1.0, 0.0, 0.0)
    return bary, ok


def closest_on_triangles(points: Array, a: Array, b: Array, c: Array
                         ) -> tuple[Array, Array, Array]:
    """For each point and its triangle: the closest point's barycentric coordinates (clamped to
    the triangle), the plane's unclamped ones (to extrapolate just past an edge), and the
    distance. Vectorised over the pairs; any dimension."""
    plane, ok = plane_barycentric(points, a, b, c)
    inside = ok & (plane >= 0.0).all(axis=1)
    bary = np.where(inside[:, None], plane, 0.0)
    best = np.where(inside, 0.0, np.inf)
    for k, (s0, s1) in enumerate(((a, b), (b, c), (c, a))):  # the three edges, each vectorised
        seg = s1 - s0
        length = _dot(seg, seg)
        t = np.clip(np.divide(_dot(points - s0, seg), length, out=np.zeros_like(length),
                              where=length > 0.0), 0.0, 1.0)
        gap = points - s0 - t[:, None] * seg
        d2 = _dot(gap, gap)
        better = d2 < best
        best = np.where(better, d2, best)
        edge = np.zeros_like(bary)
        edge[:, k], edge[:, (k + 1) % 3] = 1.0 - t, t
        bary = np.where(better[:, None], edge, bary)
    closest = bary[:, 0:1] * a + bary[:, 1:2] * b + bary[:, 2:3] * c
    dist = np.linalg.norm(points - closest, axis=1)
    return bary, np.where(ok[:, None], plane, bary), dist


def _box_items(lo: Array, hi: Array) -> tuple[Array, Array]:
    """Every integer cell in each box [lo, hi] (inclusive), as (box index, cell) pairs."""
    size = hi - lo + 1
    counts = np.prod(size, axis=1)
    owner = np.repeat(np.arange(len(lo)), counts)
    local = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    cells = np.empty((len(owner), lo.shape[1]), np.int64)
    for axis in range(lo.shape[1]):  # 2 or 3 axes
        s = size[owner, axis]
        cells[:, axis] = lo[owner, axis] + local % s
        local = local // s
    return owner, cells


class TriangleGrid:
    """Triangles (2-D or 3-D corners) binned by their bounding boxes in a uniform grid, for the
    closest triangle to many points at once."""

    def __init__(self, corners: Array) -> None:
        c = np.asarray(corners, np.float64)  # (F, 3, D)
        self.corners = c
        tmin, tmax = c.min(axis=1), c.max(axis=1)
        self.lo = tmin.min(axis=0)
        hi = tmax.max(axis=0)
        self.diag = float(np.linalg.norm(hi - self.lo)) or 1.0
        extent = (tmax - tmin).max(axis=1)
        # about one triangle across a cell; never so fine that the grid explodes
        self.cell = max(float(np.median(extent)), self.diag / 1024.0, 1e-12)
        self.dims = np.floor((hi - self.lo) / self.cell).astype(np.int64) + 1
        owner, cells = _box_items(self._cells(tmin), self._cells(tmax))
        keys = self._keys(cells)
        order = np.argsort(keys, kind="stable")
        self.keys, self.tris = keys[order], owner[order]

    def _cells(self, points: Array) -> Array:
        c = np.floor((points - self.lo) / self.cell).astype(np.int64)
        return np.clip(c, 0, self.dims - 1)

    def _keys(self, cells: Array) -> Array:
        key = cells[:, 0].copy()
        for axis in range(1, cells.shape[1]):
            key = key * self.dims[axis] + cells[:, axis]
        return key

    def near(self, points: Array, radius: float) -> tuple[Array, Array]:
        """(point index, triangle) pairs whose bounding cells come within ``radius`` of the
        points: every triangle closer than ``radius`` is among them."""
        owner, cells = _box_items(self._cells(points - radius), self._cells(points + radius))
        keys = self._keys(cells)
        start = np.searchsorted(self.keys, keys, "left")
        count = np.searchsorted(self.keys, keys, "right") - start
        pair_owner = np.repeat(owner, count)
        pos = (np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
               + np.repeat(start, count))
        tri = self.tris[pos]
        pair = np.unique(pair_owner * len(self.corners) + tri)  # a triangle in several cells
        return pair // len(self.corners), pair % len(self.corners)

    def closest(self, points: Array, max_distance: float | None = None
                ) -> tuple[Array, Array, Array, Array]:
        """For each point: the closest triangle (−1 when none lies within ``max_distance``), the
        clamped and the unclamped barycentric coordinates there, and the distance."""
        pts = np.asarray(points, np.float64).reshape(-1, self.corners.shape[2])
        n = len(pts)
        tri = np.full(n, -1, np.int64)
        bary = np.zeros((n, 3))
        plane = np.zeros((n, 3))
        dist = np.full(n, np.inf)
        todo = np.arange(n)
        radius = self.cell
        while len(todo):
            reach = radius if max_distance is None else min(radius, max_distance)
            qi, t = self.near(pts[todo], reach)
            b, p, d = closest_on_triangles(pts[todo][qi], *self.corners[t].transpose(1, 0, 2))
            hit = np.flatnonzero(d <= reach)
            order = hit[np.lexsort((d[hit], qi[hit]))]
            first = order[np.r_[True, qi[order][1:] != qi[order][:-1]]] if len(order) else order
            q = todo[qi[first]]
            tri[q], bary[q], plane[q], dist[q] = t[first], b[first], p[first], d[first]
            todo = np.setdiff1d(todo, q, assume_unique=True)
            if max_distance is not None and reach >= max_distance:
                break
            radius *= 2.0
        return tri, bary, plane, dist


# --- UV seams ------------------------------------------------------------------------------------

class SeamMap:
    """For each welded vertex on a UV seam, one triangle per other chart that uses it: how one
    surface point is found again in the neighbouring charts."""

    def __init__(self, mesh: FaceMesh) -> None:
        self.mesh = mesh
        weld = mesh.weld
        counts = np.bincount(weld, minlength=mesh.n_welded)
        self.seam_welded = counts > 1
        tri = mesh.triangles
        on_seam = self.seam_welded[weld[tri]]
        self.touches_seam = on_seam.any(axis=1)
        # welded vertex -> list of (render vertex, a triangle using it); once per mesh
        self.corners: dict[int, list[tuple[int, int]]] = {}
        for f, k in zip(*np.nonzero(on_seam), strict=True):
            r = int(tri[f, k])
            entries = self.corners.setdefault(int(weld[r]), [])
            if all(r != e[0] for e in entries):
                entries.append((r, int(f)))

    def other_charts(self, triangle: int) -> list[int]:
        """Triangles in other charts that share a seam vertex with ``triangle``."""
        tri = self.mesh.triangles[triangle]
        own = set(int(r) for r in tri)
        found = []
        for r in tri:
            w = int(self.mesh.weld[r])
            if self.seam_welded[w]:
                found += [f for rr, f in self.corners.get(w, []) if rr not in own]
        return found

    def locations(self, triangle: int, point: Array, positions: Array, reach: float
                  ) -> list[tuple[int, Array]]:
        """(triangle, UV) of a surface point on ``triangle`` as each other chart at a seam
        sees it (barycentric coordinates extrapolated on that chart's triangle at the shared
        vertex); ``positions`` per render vertex. Only where a dab of radius ``reach`` (UV)
        there would touch that chart, and once per chart (UVs within ``reach / 2`` of one
        already found are the same place)."""
        others = self.other_charts(triangle)
        if not others:
            return []
        tris = self.mesh.triangles[others]
        corners = np.asarray(positions, np.float64)[tris]
        pts = np.broadcast_to(np.asarray(point, np.float64), (len(others), 3))
        bary, _ = plane_barycentric(pts, corners[:, 0], corners[:, 1], corners[:, 2])
        uv_corners = self.mesh.uvs[tris].astype(np.float64)
        uvs = np.einsum("ik,ikj->ij", bary, uv_corners)
        _, _, gap = closest_on_triangles(uvs, uv_corners[:, 0], uv_corners[:, 1],
                                         uv_corners[:, 2])
        found: list[tuple[int, Array]] = []
        for f, b, uv, d in zip(others, bary, uvs, gap, strict=True):  # a handful at most
            if b.min() < EXTRAPOLATE or d > reach:  # too far to extrapolate, or to reach
                continue
            if any(np.hypot(*(uv - u)) < 0.5 * reach for _, u in found):
                continue
            found.append((f, uv))
        return found


# --- the mirror through the mesh -----------------------------------------------------------------

def reflect(points: Array, axis: int = 0, plane: float = 0.0) -> Array:
    """Points reflected across the plane ``axis = plane``."""
    out = np.array(points, np.float64, copy=True)
    out[..., axis] = 2.0 * plane - out[..., axis]
    return out


def _triangle_areas(corners: Array) -> Array:
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    if corners.shape[2] == 2:
        return 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)


class SurfaceMirror:
    """Mirror images of brush dabs through the neutral mesh, for any UV layout. Built once per
    mesh; a call maps a batch of dab centres (mask pixels) to their mirror images."""

    def __init__(self, mesh: FaceMesh, axis: int = 0, plane: float = 0.0,
                 skin: Array | None = None) -> None:
        """``skin``: per triangle, the skin's (``Project.skin_triangles``): only they are found
        under a UV point or as a mirror image, so an eye that shares the skin's UV tile never
        takes a dab's place. Triangle indices are the whole mesh's either way."""
        self.mesh = mesh
        self.axis, self.plane = axis, plane
        self.skin = skin
        self.uv_corners = mesh.uvs[mesh.triangles].astype(np.float64)  # (F, 3, 2)
        self.rest_vertices = mesh.rest[mesh.weld].astype(np.float64)  # per render vertex
        self.rest_corners = self.rest_vertices[mesh.triangles]  # (F, 3, 3)
        self.searched = np.arange(mesh.n_triangles) if skin is None else np.flatnonzero(skin)
        self.uv_grid = TriangleGrid(self.uv_corners[self.searched])
        self.surface = TriangleGrid(self.rest_corners[self.searched])
        self.seams = SeamMap(mesh)
        area_3d = _triangle_areas(self.rest_corners)
        area_uv = _triangle_areas(self.uv_corners)
        # UV length per model unit on each triangle: how big one dab is on the surface
        self.uv_per_unit = np.sqrt(np.divide(area_uv, area_3d, out=np.zeros_like(area_uv),
                                             where=area_3d > 0.0))

    def locate_uv(self, uvs: Array, reach: float) -> tuple[Array, Array]:
        """The UV triangle under each UV point (or the nearest within ``reach``; −1 for none)
        and the point's barycentric coordinates on it (extrapolated when just outside)."""
        tri, _, plane, _ = self.uv_grid.closest(uvs, max_distance=reach)
        return self._whole(tri), plane

    def rest_points(self, triangles: Array, bary: Array) -> Array:
        return np.einsum("ik,ikj->ij", bary, self.rest_corners[triangles])

    def uv_points(self, triangles: Array, bary: Array) -> Array:
        return np.einsum("ik,ikj->ij", bary, self.uv_corners[triangles])

    def mirror_surface(self, points: Array) -> tuple[Array, Array]:
        """Neutral surface points → the triangle and barycentric coordinates of their mirror
        images (the closest surface point to the reflection)."""
        tri, _, plane, _ = self.surface.closest(reflect(points, self.axis, self.plane))
        return self._whole(tri), plane

    def _whole(self, found: Array) -> Array:
        """Indices among the searched triangles → the whole mesh's (−1 stays)."""
        return np.where(found >= 0, self.searched[np.maximum(found, 0)], -1)

    def scale(self, source: Array, target: Array) -> Array:
        """How much larger in UV a dab must be on ``target`` triangles to cover the surface a
        dab covers on ``source`` ones."""
        s = np.divide(self.uv_per_unit[target], self.uv_per_unit[source],
                      out=np.ones(len(target)), where=self.uv_per_unit[source] > 0.0)
        return np.clip(s, *SCALE_LIMITS)

    def mirror_uv(self, uvs: Array, reach: float) -> tuple[Array, Array, Array]:
        """UV points → (index of the source point, mirrored UV, radius scale) per mirror image.
        A point off every chart by more than ``reach`` has none; a mirror image next to a UV
        seam has one per chart there, so the mirrored dab is continuous across the seam too."""
        uvs = np.asarray(uvs, np.float64).reshape(-1, 2)
        tri, bary = self.locate_uv(uvs, reach)
        src = np.flatnonzero(tri >= 0)
        if not len(src):
            return src, np.zeros((0, 2)), np.zeros(0)
        points = self.rest_points(tri[src], bary[src])
        tri2, bary2 = self.mirror_surface(points)
        main = self.uv_points(tri2, bary2)
        owners, out, scales = [src], [main], [self.scale(tri[src], tri2)]
        for i in np.flatnonzero(self.seams.touches_seam[tri2]):  # only dabs beside a seam
            on_surface = bary2[i] @ self.rest_corners[tri2[i]]
            extra = [(f, uv) for f, uv in self.seams.locations(
                int(tri2[i]), on_surface, self.rest_vertices, reach)
                if np.hypot(*(uv - main[i])) >= 0.5 * reach]  # not the main image again
            if extra:
                faces, places = zip(*extra, strict=True)
                owners.append(np.full(len(extra), src[i]))
                out.append(np.array(places))
                scales.append(self.scale(np.full(len(extra), tri[src[i]]), np.array(faces)))
        return np.concatenate(owners), np.concatenate(out), np.concatenate(scales)

    def __call__(self, points: Array, shape: tuple[int, int], radius: float
                 ) -> tuple[Array, Array, Array]:
        """The brush's mirror (studio.core.wrinkles.brush.Mirror): dab centres in mask pixels →
        (index of the source dab, mirrored centre in pixels, radius scale)."""
        h, w = shape
        pts = np.asarray(points, np.float64).reshape(-1, 2)
        uvs = np.c_[pts[:, 0] / w, 1.0 - pts[:, 1] / h]
        owner, mirrored, scale = self.mirror_uv(uvs, radius / max(w, h))
        return owner, np.c_[mirrored[:, 0] * w, (1.0 - mirrored[:, 1]) * h], scale


# --- the brush's footprint on the surface ---------------------------------------------------------

def footprint_ring(centre_uv: Sequence[float], radius_uv: tuple[float, float], uv_corners: Array,
                   corners: Array, segments: int = 48) -> Array | None:
    """The brush circle (radius in u and in v) around a UV point, carried onto the surface by
    one triangle's UV → position map (its plane): where a dab there lands, as (segments, 3)
    points; None when the triangle has no area in UV."""
    angle = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    ring = np.asarray(centre_uv, np.float64) + np.c_[radius_uv[0] * np.cos(angle),
                                                       radius_uv[1] * np.sin(angle)]
    uv = np.broadcast_to(np.asarray(uv_corners, np.float64), (segments, 3, 2))
    bary, ok = plane_barycentric(ring, uv[:, 0], uv[:, 1], uv[:, 2])
    if not ok.all():
        return None
    return bary @ np.asarray(corners, np.float64)


# --- a whole mask, mirrored ----------------------------------------------------------------------

def mirror_mask(mask: Array, mirror: SurfaceMirror) -> Array:
    """The mask painted on the other side of the face: each texel takes the value at its mirror
    image through the mesh (the mirror is its own inverse), so the result has no holes whatever
    the UV layout. Only texels whose mirror image can fall in the painted region are looked up:
    the painted texels' own images bound them."""
    h, w = mask.shape
    out = np.zeros_like(mask)
    rows, cols = np.nonzero(mask > 0.0)
    if not len(rows):
        return out
    reach = 2.0 / max(h, w)

    def mirrored(r: Array, c: Array) -> tuple[Array, Array]:
        """Texel centres → (which have an image, image texel rows and columns, as floats)."""
        uvs = np.c_[(c + 0.5) / w, 1.0 - (r + 0.5) / h]
        tri, bary = mirror.locate_uv(uvs, reach)
        ok = np.flatnonzero(tri >= 0)
        tri2, bary2 = mirror.mirror_surface(mirror.rest_points(tri[ok], bary[ok]))
        uv = mirror.uv_points(tri2, bary2)
        return ok, np.c_[(1.0 - uv[:, 1]) * h - 0.5, uv[:, 0] * w - 0.5]

    step = max(1, len(rows) // 20000)  # the painted region's images give the target's bounds
    _, images = mirrored(rows[::step].astype(np.float64), cols[::step].astype(np.float64))
    if not len(images):
        return out
    pad = 3 + 2 * step
    r0, c0 = np.maximum(np.floor(images.min(axis=0)).astype(int) - pad, 0)
    r1, c1 = np.minimum(np.ceil(images.max(axis=0)).astype(int) + pad + 1, (h, w))
    rr, cc = np.mgrid[r0:r1, c0:c1]
    rr, cc = rr.ravel(), cc.ravel()
    ok, source = mirrored(rr.astype(np.float64), cc.astype(np.float64))
    sr = np.clip(np.rint(source[:, 0]).astype(int), 0, h - 1)
    sc = np.clip(np.rint(source[:, 1]).astype(int), 0, w - 1)
    out[rr[ok], cc[ok]] = mask[sr, sc]
    return out
