"""Per-frame geometry: face and vertex normals, Lengyel tangents.

The thesis recomputes normals, tangents and bitangents on the CPU every frame, so this module has
two faces:

* small standalone functions (``face_normals``, ``vertex_normals``, ``vertex_tangents``,
  ``bitangents``) that state the maths plainly and are what the tests check against hand-worked
  values;
* ``DeformCache``, built once per mesh, which does the same work for a whole frame in a few
  milliseconds by precomputing every index structure and reusing every buffer, and for a frame
  that moved part of the face (a key pose being animated) only over that part.

Conventions shared by both:

* Vertex normals are the normalised sum of the *unnormalised* face cross products
  ``(P1-P0)×(P2-P0)``, i.e. weighted by triangle area — what the thesis code does (Eq. 4.2 with
  area weighting). Large triangles dominate, and slivers barely count, which is the robust choice
  for badly shaped faces.
* Normals are computed over welded positions so a UV seam never creases the shading.
* Nothing here ever returns NaN or infinity: zero-area triangles contribute nothing, zero-area UV
  triangles contribute no tangent, and a vertex left without a usable direction gets a finite
  fallback (normal ``(0, 0, 1)``; tangent any unit vector perpendicular to the normal, ``w = +1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.tangent_frames import (
    TANGENT_FRAMES,
    TANGENT_KEEP,
    UV_SINE,
    MikkSubset,
    MikkTSpaceFrame,
    perpendicular,
)

Array = np.ndarray

#: Fallback normal for vertices that touch no triangle of non-zero area.
FALLBACK_NORMAL = (0.0, 0.0, 1.0)

_TINY32 = float(np.finfo(np.float32).tiny)

# Vertices are grouped by how many corners they own; groups smaller than this are padded into the
# next larger group so a frame does not pay Python overhead for a handful of odd-valence vertices.
_MIN_GROUP = 512
# Padding every vertex to the largest valence is accepted (no reordering) below this waste.
_PAD_WASTE = 0.125
# Items gathered per gather-and-add step: keeps the gathered rows in cache.
_CHUNK = 32768
# Every index the cache gathers with was built in range at construction; np.take's default
# mode="raise" would also copy its output through a temporary buffer, doubling the cost.
_NO_CHECK = "clip"
# 32-byte rows as single items: ``np.put`` scatters them several times faster than row indexing.
_VOID32 = np.dtype((np.void, 32))


# --------------------------------------------------------------------------------------------
# Standalone functions
# --------------------------------------------------------------------------------------------


def _cross_products(positions: Array, triangles: Array) -> tuple[Array, Array, Array]:
    """Edges ``Q1 = P1-P0``, ``Q2 = P2-P0`` and their cross product, per triangle."""
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.intp)
    p0 = p[t[:, 0]]
    q1 = p[t[:, 1]] - p0
    q2 = p[t[:, 2]] - p0
    return q1, q2, np.cross(q1, q2)


def _normalise_rows(v: Array, fallback: Array | tuple[float, float, float] | None) -> Array:
    """Unit rows; rows of (near) zero length become ``fallback`` (or stay zero if None)."""
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    ok = length > _TINY32
    out = np.zeros_like(v)
    np.divide(v, length[:, None], out=out, where=ok[:, None])
    if fallback is not None and not ok.all():
        out[~ok] = np.broadcast_to(np.asarray(fallback, dtype=v.dtype), out[~ok].shape)
    return out


def _scatter_rows(index: Array, values: Array, n: int) -> Array:
    """Sum ``values`` rows into ``n`` bins by ``index`` (bincount per column, no np.add.at)."""
    index = np.asarray(index, dtype=np.intp).ravel()
    out = np.empty((n, values.shape[1]), dtype=np.float64)
    for j in range(values.shape[1]):
        out[:, j] = np.bincount(index, weights=values[:, j], minlength=n)[:n]
    return out


def face_normals(positions: Array, triangles: Array) -> Array:
    """Unit normal of each counter-clockwise triangle (Eq. 4.1); zero for zero-area triangles."""
    _, _, cross = _cross_products(positions, triangles)
    return _normalise_rows(cross, None)


def vertex_normals(positions: Array, triangles: Array) -> Array:
    """Area-weighted vertex normals: the normalised sum of the faces' unnormalised cross products.

    Area weighting is what the thesis code does. A vertex that touches no triangle of
    non-zero area gets ``FALLBACK_NORMAL`` rather than NaN.
    """
    positions = np.asarray(positions)
    triangles = np.asarray(triangles, dtype=np.intp)
    _, _, cross = _cross_products(positions, triangles)
    per_corner = np.repeat(cross, 3, axis=0)  # corner order = triangles.ravel()
    summed = _scatter_rows(triangles.ravel(), per_corner, len(positions))
    return _normalise_rows(summed, FALLBACK_NORMAL)


def _uv_coefficients(uvs: Array, triangles: Array) -> tuple[Array, Array, Array, Array]:
    """Per triangle, the factors of Eq. 4.8 written as ``T = a·Q1 + b·Q2``, ``B = c·Q1 + d·Q2``.

    ``a = r·t2, b = -r·t1, c = -r·s2, d = r·s1`` with ``r = 1/(s1·t2 - s2·t1)``. They depend only
    on the UVs, so ``DeformCache`` computes them once. Triangles whose UV area is (numerically)
    zero get all four factors 0: they contribute no tangent instead of NaN or infinity.
    """
    uv = np.asarray(uvs, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.intp)
    uv0 = uv[t[:, 0]]
    d1 = uv[t[:, 1]] - uv0
    d2 = uv[t[:, 2]] - uv0
    s1, t1 = d1[:, 0], d1[:, 1]
    s2, t2 = d2[:, 0], d2[:, 1]
    det = s1 * t2 - s2 * t1
    scale = np.sqrt((s1 * s1 + t1 * t1) * (s2 * s2 + t2 * t2))
    ok = (np.abs(det) > UV_SINE * scale) & (det != 0.0)
    r = np.zeros_like(det)
    np.divide(1.0, det, out=r, where=ok)
    return r * t2, -r * t1, -r * s2, r * s1


def vertex_tangents(
    positions_render: Array, uvs: Array, triangles: Array, normals_render: Array
) -> Array:
    """Per-vertex tangent ``(x, y, z, w)`` by Lengyel's method (Eq. 4.8–4.10).

    Per triangle ``T = r(t2·Q1 − t1·Q2)`` and ``B = r(s1·Q2 − s2·Q1)``, summed per vertex (so the
    sum is weighted like the normals: by position area over UV area); then Gram–Schmidt
    ``T' = normalize(T − (N·T)N)`` and handedness ``w = sign((N×T)·B)`` (+1 when zero). The
    bitangent ``B' = w·(N×T')`` is left to the vertex shader (see ``bitangents``). The normals are
    expected unit length (they are renormalised here to be safe); a vertex whose tangent is
    missing or parallel to its normal gets some unit vector perpendicular to the normal, w = +1.
    """
    triangles = np.asarray(triangles, dtype=np.intp)
    n_vertices = len(positions_render)
    q1, q2, _ = _cross_products(positions_render, triangles)
    a, b, c, d = _uv_coefficients(uvs, triangles)
    tan = a[:, None] * q1 + b[:, None] * q2
    bit = c[:, None] * q1 + d[:, None] * q2
    per_corner = np.repeat(np.hstack([tan, bit]), 3, axis=0)
    summed = _scatter_rows(triangles.ravel(), per_corner, n_vertices)
    t_sum, b_sum = summed[:, :3], summed[:, 3:]
    n = _normalise_rows(np.asarray(normals_render, dtype=np.float64), FALLBACK_NORMAL)

    ortho = t_sum - np.einsum("ij,ij->i", n, t_sum)[:, None] * n
    t_len2 = np.einsum("ij,ij->i", t_sum, t_sum)
    o_len2 = np.einsum("ij,ij->i", ortho, ortho)
    usable = (o_len2 > TANGENT_KEEP**2 * t_len2) & (o_len2 > _TINY32)
    out = np.empty((n_vertices, 4), dtype=np.float64)
    out[:, :3] = _normalise_rows(ortho, (1.0, 0.0, 0.0))
    out[:, 3] = np.where(np.einsum("ij,ij->i", np.cross(n, t_sum), b_sum) < 0.0, -1.0, 1.0)
    if not usable.all():
        out[~usable, :3] = perpendicular(n[~usable])
        out[~usable, 3] = 1.0
    return out


def bitangents(normals: Array, tangents4: Array) -> Array:
    """The bitangent the vertex shader reconstructs: ``B' = w·(N×T')`` (Eq. 4.10)."""
    n = np.asarray(normals, dtype=np.float64)
    t4 = np.asarray(tangents4, dtype=np.float64)
    return t4[:, 3:4] * np.cross(n, t4[:, :3])


# --------------------------------------------------------------------------------------------
# DeformCache
# --------------------------------------------------------------------------------------------


def _row_view(a: Array) -> Array:
    """View 2-D rows of 8, 16 or 32 bytes as whole numbers so ``np.take`` copies them in one go.

    ``np.take`` has fast paths for items of those sizes; 12- or 36-byte rows go through a generic
    per-row copy that is several times slower.
    """
    row_bytes = a.shape[1] * a.itemsize if a.ndim == 2 else a.itemsize
    if a.ndim == 2 and row_bytes in (8, 16, 32):
        unit = np.float64 if row_bytes == 8 else np.complex128
        return a.view(unit)
    return a


class _GroupPlan:
    """How to sum items into their owners with gathers and dense additions, not scatter-adds.

    Each owner's items are read through a table padded with ``pad`` (an item that is always zero).
    A chunk of ``n`` consecutive owner rows of capacity ``k`` reads a ``(k, n)`` block of the
    table, so its sum is ``k - 1`` contiguous additions — far faster than ``np.add.at`` and than
    ``np.add.reduceat`` over runs of ~6. ``order[row]`` is the owner whose sum lands in ``row``.
    When padding every owner to the largest count wastes little (regular meshes), ``order`` is the
    identity and no permutation is needed; otherwise owners are grouped by count.
    Owners with no items get rows that are always zero.
    """

    def __init__(
        self, owner: Array, item: Array, n_owners: int, pad: int, chunk: int | None = None
    ) -> None:
        owner = np.asarray(owner, dtype=np.intp)
        item = np.asarray(item, dtype=np.intp)
        count = np.bincount(owner, minlength=n_owners)
        largest = int(count.max())
        if n_owners * largest - len(owner) <= _PAD_WASTE * len(owner):
            cap = np.full(n_owners, largest, dtype=np.intp)
            self.order = np.arange(n_owners, dtype=np.intp)
            self.identity = True
        else:
            values, how_many = np.unique(count, return_counts=True)
            capacity_of = np.zeros(largest + 1, dtype=np.intp)
            pending: list[int] = []
            for i, (value, n) in enumerate(zip(values.tolist(), how_many.tolist(), strict=True)):
                pending.append(value)
                if n >= _MIN_GROUP or i == len(values) - 1:
                    capacity_of[pending] = value
                    pending = []
            cap = capacity_of[count]
            self.order = np.lexsort((np.arange(n_owners), cap)).astype(np.intp)
            self.identity = False
        row_of = np.empty(n_owners, dtype=np.intp)
        row_of[self.order] = np.arange(n_owners)
        cap_by_row = cap[self.order]

        # Per capacity k, a table[j, row] = j-th item of the owner in that row (pad where it has
        # fewer), built only for that group so one vertex of huge valence costs nothing extra.
        sort = np.argsort(owner, kind="stable")
        owner_sorted = owner[sort]
        item_sorted = item[sort]
        first = np.zeros(n_owners + 1, dtype=np.intp)
        np.cumsum(count, out=first[1:])
        rank = np.arange(len(owner)) - first[owner_sorted]
        cap_sorted = cap[owner_sorted]

        # (first row, row past the last, capacity k, items: (k * n) item j of every row)
        self.chunks: list[tuple[int, int, int, Array]] = []
        self._groups: list[tuple[int, int, Array]] = []  # (row lo, row hi, table.T: (k, hi - lo))
        self._chunk = _CHUNK if chunk is None else chunk
        for k in np.unique(cap_by_row).tolist():
            if k == 0:
                continue  # owners without items: their rows stay zero
            lo, hi = np.searchsorted(cap_by_row, [k, k + 1]).tolist()
            mine = cap_sorted == k
            table = np.full((k, hi - lo), pad, dtype=np.intp)  # item j of the owner in each row
            table[rank[mine], row_of[owner_sorted[mine]] - lo] = item_sorted[mine]
            self._groups.append((lo, hi, table))
            for start in range(lo, hi, self._step(k)):
                stop = min(hi, start + self._step(k))
                self.chunks.append((start, stop, k, table[:, start - lo : stop - lo].ravel()))
        self.scratch_rows = max((len(items) for *_, items in self.chunks), default=0)

    def _step(self, k: int) -> int:
        """Rows per chunk at capacity k: keeps the gathered rows in cache."""
        return max(1, self._chunk // k)

    def subset(self, rows: Array) -> list[tuple[int, int, int, Array]]:
        """Chunks like ``chunks`` for some rows only (ascending): the i-th row summed is
        ``rows[i]``. Gathering the tables costs about what a sum does, so keep and reuse them."""
        chunks = []
        for lo, hi, table in self._groups:
            k = len(table)
            a, b = np.searchsorted(rows, (lo, hi)).tolist()
            for start in range(a, b, self._step(k)):
                stop = min(b, start + self._step(k))
                items = np.take(table, rows[start:stop] - lo, axis=1, mode=_NO_CHECK)
                chunks.append((start, stop, k, items.ravel()))
        return chunks

    def reduce(self, jobs: list[tuple[Array, Array, Array]],
               chunks: list[tuple[int, int, int, Array]] | None = None) -> None:
        """For each ``(source, scratch, out)``: ``out[row] = Σ source[item]`` over the row's items
        (over ``chunks`` from ``subset``: ``out[i]`` for the i-th row of the subset).

        ``source`` has one zero row past the items (the padding item); ``scratch`` holds at least
        ``scratch_rows`` rows; rows of ``out`` whose owner has no items are left untouched.
        """
        views = [(_row_view(src), _row_view(scr), scr, out) for src, scr, out in jobs]
        for start, stop, k, items in self.chunks if chunks is None else chunks:
            m = len(items)
            for src_v, scr_v, scr, out in views:
                np.take(src_v, items, axis=0, out=scr_v[:m], mode=_NO_CHECK)
                block = scr[:m].reshape((k, stop - start, *scr.shape[1:]))
                np.add.reduce(block, axis=0, out=out[start:stop])


def _shaped(buffer: Array, *shape: int) -> Array:
    """The first ``prod(shape)`` items of a flat buffer as a contiguous array of that shape, so
    one preallocated buffer serves every size of a frame's work."""
    return buffer[: math.prod(shape)].reshape(shape)


@dataclass(eq=False)
class _Region:
    """The part of a mesh some moved positions reach, with every index its recomputation
    gathers: built for a new set of moved positions, reused for every frame whose moved
    positions it covers (an animated pose moves the same vertices frame after frame). ``rows``
    None: recompute everything."""

    changed: Array  # (W,) bool: the moved positions it was built for
    rows: Array | None  # plan rows (ascending) of every render vertex to recompute
    size: int = 0  # how many positions ``changed`` holds
    faces: Array = field(default_factory=lambda: np.zeros(0, np.intp))  # triangles to redo
    wtri: Array = field(default_factory=lambda: np.zeros((3, 0), np.intp))  # their corners
    coef: Array = field(default_factory=lambda: np.zeros((4, 0), np.float32))  # their a, b, c, d
    chunks: list = field(default_factory=list)  # _GroupPlan.subset(rows)
    welded: Array = field(default_factory=lambda: np.zeros(0, np.intp))  # position of each row
    vertices: Array = field(default_factory=lambda: np.zeros(0, np.intp))  # vertex of each row
    mikk: MikkSubset | None = None  # the MikkTSpace frame's index work for ``vertices``
    split: Array = field(default_factory=lambda: np.zeros(0, np.intp))  # which rows: seam copies
    split_source: Array = field(default_factory=lambda: np.zeros(0, np.intp))  # their welded sums
    span: tuple[int, int] = (0, 0)  # first render vertex recomputed, and one past the last

    NOTHING: ClassVar[_Region]


_Region.NOTHING = _Region(np.zeros(0, bool), np.zeros(0, np.intp))


# A frame recomputes only the render vertices its moved positions reach while they are fewer than
# this fraction of the mesh; past it, everything (a subset costs more per vertex: it is gathered
# and scattered; about even at 80 %).
_PARTIAL = 0.75
# Regions kept for reuse (an animation cycling through this many poses builds each once); the
# fraction of a frame's moved positions a region may miss and still be grown to cover them; and
# the least fraction of a region a frame must move for the region to serve it.
_REGIONS = 6
_FLICKER = 0.2
_SLACK = 0.5


class DeformCache:
    """Per-frame normals and tangents for one mesh, with all index work done once.

    ``update(positions_welded)`` returns the interleaved vertex buffer the renderer uploads:
    ``(V, 10) float32`` per render vertex ``[x, y, z, nx, ny, nz, tx, ty, tz, w]``. Normals are
    summed over the welded triangles (area-weighted) so split seam vertices share one normal;
    tangents are summed over render vertices (they depend on the UVs) and orthogonalised against
    that welded normal. ``frame`` picks the tangent frame (studio.core.mesh.tangent_frames):
    ``thesis`` (Lengyel, above) or ``mikktspace`` (angle-weighted unit tangents per UV side,
    the bakers' convention). The returned array is reused by later calls, which also read it back:
    copy it to keep it, never write to it.

    How it stays fast: per-triangle maths runs on contiguous float32 component arrays, with the
    UV factors of the tangents (constant per mesh) computed once; each render vertex's sum over
    its triangles is a gather of 32-byte rows plus dense additions (``_GroupPlan``); every
    temporary is preallocated. And a frame redoes only what its moved positions reach: key poses
    move part of a face, so the triangles with a moved corner and the render vertices of their
    welded corners are recomputed, the rest of the buffer is kept from the previous frame
    (``last_recomputed`` says how many vertices a frame redid). In the MikkTSpace-style frame
    Lengyel's T and B are not computed at all: only the normals, then that frame's tangents.
    """

    def __init__(self, mesh: FaceMesh, frame: str = "thesis") -> None:
        self.mesh = mesh
        self._mikk: MikkTSpaceFrame | None = None
        self.frame = "thesis"
        tri = mesh.triangles.astype(np.intp)
        n_f = len(tri)
        n_v = mesh.n_vertices
        n_w = mesh.n_welded
        self.n_vertices = n_v
        self.n_welded = n_w
        self.last_recomputed = 0  # render vertices the last update recomputed
        self.last_span = (0, 0)  # the range of render vertices it changed: upload just these
        f32 = np.float32
        weld = mesh.weld.astype(np.intp)

        # Welded corners of every triangle, component-major for three 1-D gathers per frame.
        self._wtri = np.ascontiguousarray(weld[tri].T)  # (3, F)
        self._pos_t = np.empty((3, n_w), f32)  # this frame's positions, component-major
        self._prev_t = np.empty((3, n_w), f32)  # the previous frame's (the buffers swap)
        self._valid = False  # whether the buffers hold a whole frame to build on
        self._coef = np.stack(_uv_coefficients(mesh.uvs, tri)).astype(f32)  # (4, F): a, b, c, d
        # Per-face work, flat so a frame that redoes some faces uses a prefix of each buffer.
        self._corner = np.empty(9 * n_f, f32)  # [component, corner, face]
        self._e1 = np.empty(3 * n_f, f32)
        self._e2 = np.empty(3 * n_f, f32)
        self._tmp_f = np.empty(3 * n_f, f32)
        self._tmp_f1 = np.empty(n_f, f32)

        # Per face [cross xyz, T xyz, Bx, By] (32-byte rows) and Bz; the extra last row is the
        # plan's always-zero padding item.
        self._face8 = np.zeros((n_f + 1, 8), f32)
        self._face_z = np.zeros(n_f + 1, f32)
        self._face8_void = self._face8.view(_VOID32).reshape(n_f + 1)

        # Sum faces into render vertices.
        self._plan = plan = _GroupPlan(tri.ravel(), np.repeat(np.arange(n_f), 3), n_v, pad=n_f)
        order = plan.order  # plan row -> render vertex
        self._scratch8 = np.empty((plan.scratch_rows, 8), f32)
        self._scratch_z = np.empty(plan.scratch_rows, f32)
        self._sums8 = np.zeros((n_v + 1, 8), f32)  # plan order; last row zero (padding item)
        self._sums8_void = self._sums8.view(_VOID32).reshape(n_v + 1)
        self._sums_z = np.zeros(n_v, f32)

        # Welded normal sums: a render vertex's own sum unless a seam split its position; only
        # the split ones (usually a few percent) are re-summed over all their copies.
        identity_weld = n_v == n_w and np.array_equal(weld, np.arange(n_v))
        self._weld_of_row = weld_of_row = weld[order]
        copies = np.bincount(weld_of_row, minlength=n_w)
        seam_rows = np.flatnonzero(copies[weld_of_row] > 1)
        self._seams = len(seam_rows) > 0
        if self._seams:
            seam_welds, compact = np.unique(weld_of_row[seam_rows], return_inverse=True)
            self._wplan = _GroupPlan(compact, seam_rows, len(seam_welds), pad=n_v)
            self._wscratch = np.empty((self._wplan.scratch_rows, 8), f32)
            self._wsums = np.zeros((len(seam_welds), 8), f32)
            wrow = np.empty(len(seam_welds), dtype=np.intp)
            wrow[self._wplan.order] = np.arange(len(seam_welds))
            self._seam_rows = seam_rows
            self._seam_source = wrow[compact.reshape(-1)]  # seam row -> its welded sum's row
            self._expanded = np.empty((len(seam_rows), 8), f32)
            self._wsum_of_row = np.full(n_v, -1, dtype=np.intp)  # the same for any row, or -1
            self._wsum_of_row[seam_rows] = self._seam_source

        # Per-vertex stage, in plan order, on contiguous component arrays.
        self._pos_index = None if (plan.identity and identity_weld) else weld_of_row
        self._n = np.empty(3 * n_v, f32)
        self._t = np.empty(3 * n_v, f32)
        self._b = np.empty(3 * n_v, f32)
        self._v1 = np.empty(n_v, f32)
        self._v2 = np.empty(n_v, f32)
        self._v3 = np.empty(n_v, f32)
        self._mask = np.empty(n_v, dtype=bool)
        self._out = np.empty((n_v, 10), f32)  # render order (returned)
        self._out_void = self._out.view(np.dtype((np.void, 40))).reshape(n_v)
        self._row = self._out if plan.identity else np.empty((n_v, 10), f32)  # plan order
        self._row_void = self._row.view(np.dtype((np.void, 40))).reshape(n_v)
        self._row_of_vertex = np.empty(n_v, dtype=np.intp)
        self._row_of_vertex[order] = np.arange(n_v)

        # What a frame that moved only some positions needs.
        self._moved = np.empty((3, n_w), dtype=bool)
        self._changed = np.empty(n_w, dtype=bool)
        self._face_hit = np.empty((3, n_f), dtype=bool)
        self._face_mask = np.empty(n_f, dtype=bool)
        self._touched = np.empty(n_w, dtype=bool)
        self._row_mask = np.empty(n_v, dtype=bool)
        # a moved position no triangle uses is left to the whole-frame path
        self._faceless = np.bincount(self._wtri.ravel(), minlength=n_w) == 0
        self._faceless_any = bool(self._faceless.any())
        self._outside = np.empty(n_w, dtype=bool)
        self._regions: list[_Region] = []  # most recently used first
        self._sub_face8 = np.zeros((n_f, 8), f32)  # T, B stay 0 in the MikkTSpace frame
        self._sub_face_z = np.zeros(n_f, f32)
        self._sub_sums8 = np.empty((n_v, 8), f32)
        self._sub_sums_z = np.empty(n_v, f32)
        self._sub_row = np.empty((n_v, 10), f32)

        self.set_frame(frame)

    def set_frame(self, frame: str) -> None:
        """Which tangent frame columns 6–9 hold (studio.core.mesh.tangent_frames): ``thesis`` is
        Lengyel's, computed with the normals; ``mikktspace`` replaces it after them (its UV
        work is done once, on first use). Changing it makes the next ``update`` whole."""
        if frame not in TANGENT_FRAMES:
            raise ValueError(f"unknown tangent frame '{frame}' (choose from "
                             f"{', '.join(TANGENT_FRAMES)})")
        if frame == "mikktspace" and self._mikk is None:
            mesh = self.mesh
            self._mikk = MikkTSpaceFrame(mesh.triangles, mesh.uvs, mesh.weld, mesh.rest)
        if frame != self.frame:
            self._valid = False
        self.frame = frame

    @property
    def buffer(self) -> Array:
        """The ``(V, 10)`` array ``update`` fills (valid after the first call)."""
        return self._out

    def update(self, positions_welded: Array) -> Array:
        """The interleaved ``(V, 10)`` float32 buffer for one frame's welded positions."""
        p = np.asarray(positions_welded)
        if p.shape != (self.n_welded, 3):
            raise ValueError(f"expected positions of shape ({self.n_welded}, 3), got {p.shape}")
        self._pos_t, self._prev_t = self._prev_t, self._pos_t
        self._pos_t[...] = p.T
        region = self._moved_region() if self._valid else None
        if region is None or region.rows is None:
            self._update_all()
            self._valid = True
            self.last_recomputed, self.last_span = self.n_vertices, (0, self.n_vertices)
        else:
            if len(region.rows):
                self._update_some(region)
            self.last_recomputed, self.last_span = len(region.rows), region.span
        if self._mikk is not None and self.frame == "mikktspace" and self.last_recomputed:
            out = self._out
            if region is None or region.rows is None:
                out[:, 6:10] = self._mikk.tangents(self._pos_t.T, out[:, 3:6])
            else:  # the vertices whose triangles moved; every other tangent keeps its inputs
                if region.mikk is None:
                    region.mikk = self._mikk.subset(region.vertices)
                rows = region.mikk.vertices
                out[rows, 6:10] = self._mikk.tangents_of(region.mikk, self._pos_t.T,
                                                         out[rows, 3:6])
        return self._out

    # --- a whole frame ----------------------------------------------------------------------

    def _update_all(self) -> None:
        pos_t = self._pos_t
        n_f = len(self._face_z) - 1
        corner = _shaped(self._corner, 3, 3, n_f)
        for comp in range(3):
            np.take(pos_t[comp], self._wtri, out=corner[comp], mode=_NO_CHECK)
        self._face_terms(corner, self._coef, self._face8[:-1], self._face_z[:-1])

        # Sum per render vertex (plan order), then per welded vertex for the normals.
        sums8 = self._sums8
        self._plan.reduce(
            [
                (self._face8, self._scratch8, sums8),
                (self._face_z, self._scratch_z, self._sums_z),
            ]
        )
        n_v = self.n_vertices
        n, t, bt = (_shaped(x, 3, n_v) for x in (self._n, self._t, self._b))
        n[...] = sums8[:-1, :3].T
        if self._seams:
            self._wplan.reduce([(sums8, self._wscratch, self._wsums)])
            expanded = _row_view(self._expanded)
            np.take(_row_view(self._wsums), self._seam_source, axis=0, out=expanded, mode=_NO_CHECK)
            n[:, self._seam_rows] = self._expanded[:, :3].T
        t[...] = sums8[:-1, 3:6].T
        bt[:2] = sums8[:-1, 6:8].T
        bt[2] = self._sums_z

        row = self._row
        self._vertex_terms(n, t, bt, row)
        v1 = self._v1
        for comp in range(3):
            if self._pos_index is None:
                row[:, comp] = pos_t[comp]
            else:
                np.take(pos_t[comp], self._pos_index, out=v1, mode=_NO_CHECK)
                row[:, comp] = v1
        # If the plan reordered vertices, one 40-byte-row gather restores the render order.
        if row is not self._out:
            np.take(self._row_void, self._row_of_vertex, out=self._out_void, mode=_NO_CHECK)

    # --- part of a frame --------------------------------------------------------------------

    def _moved_region(self) -> _Region | None:
        """What the positions that moved since the last frame reach (None: recompute all).

        A region is reused for any frame whose moved positions it covers without being much
        larger. The set a pose moves flickers a little from frame to frame (tiny offsets round
        away at some weights), so a region that nearly covers a frame grows to cover it rather
        than being rebuilt for it.
        """
        moved, changed, outside = self._moved, self._changed, self._outside
        np.not_equal(self._pos_t, self._prev_t, out=moved)
        np.logical_or(moved[0], moved[1], out=changed)
        changed |= moved[2]
        count = np.count_nonzero(changed)
        if count == 0:
            return _Region.NOTHING
        if count > _PARTIAL * self.n_welded:
            return None
        regions = self._regions
        for i, region in enumerate(regions):
            if count < _SLACK * region.size:
                continue
            np.greater(changed, region.changed, out=outside)  # moved but not covered
            if not outside.any():
                regions.insert(0, regions.pop(i))
                return region
        if self._faceless_any and (changed & self._faceless).any():
            return None
        cover = changed.copy()
        if regions:
            np.greater(changed, regions[0].changed, out=outside)
            missed = np.count_nonzero(outside)
            if missed <= _FLICKER * count and count >= _SLACK * (regions[0].size + missed):
                cover |= regions.pop(0).changed
        regions.insert(0, self._build_region(cover))
        del regions[_REGIONS:]
        return regions[0]

    def _build_region(self, changed: Array) -> _Region:
        """The triangles with a corner in ``changed`` and the render vertices they reach."""
        size = int(np.count_nonzero(changed))
        everything = _Region(changed, None, size)
        if size > _PARTIAL * self.n_welded:
            return everything
        hit, face_mask = self._face_hit, self._face_mask
        np.take(changed, self._wtri, out=hit, mode=_NO_CHECK)
        np.logical_or(hit[0], hit[1], out=face_mask)
        face_mask |= hit[2]
        faces = np.flatnonzero(face_mask)
        if len(faces) > _PARTIAL * len(face_mask):
            return everything
        # every copy of every corner of those triangles: their sums, or their welded normals,
        # take in a changed triangle
        wtri = np.take(self._wtri, faces, axis=1, mode=_NO_CHECK)
        touched = self._touched
        np.copyto(touched, changed)
        touched[wtri.ravel()] = True
        np.take(touched, self._weld_of_row, out=self._row_mask, mode=_NO_CHECK)
        rows = np.flatnonzero(self._row_mask)
        if len(rows) > _PARTIAL * self.n_vertices:
            return everything
        vertices = self._plan.order[rows]
        region = _Region(changed, rows, size, faces, wtri,
                         np.take(self._coef, faces, axis=1, mode=_NO_CHECK),
                         self._plan.subset(rows), self._weld_of_row[rows], vertices)
        if len(vertices):
            region.span = (int(vertices.min()), int(vertices.max()) + 1)
        if self._seams:
            source = self._wsum_of_row[rows]
            region.split = np.flatnonzero(source >= 0)
            region.split_source = source[region.split]
        return region

    def _update_some(self, region: _Region) -> None:
        """Recompute the region's triangles and render vertices; keep the rest of the buffer."""
        pos_t = self._pos_t
        n_f, m = len(region.faces), len(region.rows)
        corner = _shaped(self._corner, 3, 3, n_f)
        for comp in range(3):
            np.take(pos_t[comp], region.wtri, out=corner[comp], mode=_NO_CHECK)
        face8, face_z = self._sub_face8[:n_f], self._sub_face_z[:n_f]
        self._face_terms(corner, region.coef, face8, face_z)
        np.put(self._face8_void, region.faces, face8.view(_VOID32).reshape(n_f))
        self._face_z[region.faces] = face_z

        sums8, sums_z = self._sub_sums8[:m], self._sub_sums_z[:m]
        sums8[...] = 0.0  # rows of vertices without triangles are not written
        sums_z[...] = 0.0
        self._plan.reduce(
            [(self._face8, self._scratch8, sums8), (self._face_z, self._scratch_z, sums_z)],
            region.chunks,
        )
        n, t, bt = (_shaped(x, 3, m) for x in (self._n, self._t, self._b))
        n[...] = sums8[:, :3].T
        if len(region.split):  # welded sums read every copy's sum: keep those current
            split = region.split
            np.put(self._sums8_void, region.rows[split], sums8.view(_VOID32).reshape(m)[split])
            self._wplan.reduce([(self._sums8, self._wscratch, self._wsums)])
            n[:, split] = self._wsums[region.split_source, :3].T
        t[...] = sums8[:, 3:6].T
        bt[:2] = sums8[:, 6:8].T
        bt[2] = sums_z

        row = self._sub_row[:m]
        self._vertex_terms(n, t, bt, row)
        v1 = self._v1[:m]
        for comp in range(3):
            np.take(pos_t[comp], region.welded, out=v1, mode=_NO_CHECK)
            row[:, comp] = v1
        np.put(self._out_void, region.vertices, row.view(self._out_void.dtype).reshape(m))

    # --- the maths, for a whole frame or part of one ----------------------------------------

    def _face_terms(self, corner: Array, coef: Array, face8: Array, face_z: Array) -> None:
        """Per triangle: edges, cross product (Eq. 4.1) and Lengyel's T and B (Eq. 4.8), from
        ``corner[component, corner, face]`` into ``face8`` rows and ``face_z`` (B's z)."""
        n_f = corner.shape[2]
        e1, e2, tmp = (_shaped(x, 3, n_f) for x in (self._e1, self._e2, self._tmp_f))
        tmp1 = self._tmp_f1[:n_f]
        np.subtract(corner[:, 1], corner[:, 0], out=e1)
        np.subtract(corner[:, 2], corner[:, 0], out=e2)
        for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
            np.multiply(e1[j], e2[k], out=tmp1)
            np.multiply(e1[k], e2[j], out=tmp[0])
            np.subtract(tmp1, tmp[0], out=face8[:, i])
        if self.frame != "thesis":
            return  # the MikkTSpace-style frame replaces T and B: the normals are all it needs
        a, b, c, d = coef
        np.multiply(e1, a, out=tmp)
        for comp in range(3):
            np.multiply(e2[comp], b, out=tmp1)
            np.add(tmp[comp], tmp1, out=face8[:, 3 + comp])
        np.multiply(e1, c, out=tmp)
        for comp in range(3):
            np.multiply(e2[comp], d, out=tmp1)
            np.add(tmp[comp], tmp1, out=face8[:, 6 + comp] if comp < 2 else face_z)

    def _vertex_terms(self, n: Array, t: Array, bt: Array, row: Array) -> None:
        """From summed ``(3, m)`` N, T, B (changed in place): unit normal, orthonormal tangent
        and handedness into columns 3–9 of ``row``."""
        m = n.shape[1]
        v1, v2, v3, mask = self._v1[:m], self._v2[:m], self._v3[:m], self._mask[:m]
        # Normalise the normals; zero sums fall back to (0, 0, 1).
        _dot(n, n, v1, v2)
        np.less_equal(v1, _TINY32, out=mask)
        np.maximum(v1, _TINY32, out=v1)
        np.sqrt(v1, out=v1)
        np.divide(1.0, v1, out=v1)
        n *= v1
        if mask.any():
            n[:, mask] = np.array(FALLBACK_NORMAL, np.float32)[:, None]
        if self.frame != "thesis":  # columns 6–9 are the MikkTSpace-style frame's, filled next
            for comp in range(3):
                row[:, 3 + comp] = n[comp]
            return

        # Handedness from the sums: (N×T)·B < 0 → -1, else +1 (N×T' = N×T, so before G–S).
        _cross_dot(n, t, bt, v1, v2, v3)
        np.less(v1, 0.0, out=mask)
        np.multiply(mask, np.float32(-2.0), out=row[:, 9])
        row[:, 9] += np.float32(1.0)

        # Gram–Schmidt (Eq. 4.10): T' = normalize(T - (N·T)N); fall back when nothing is left.
        _dot(t, t, v3, v2)  # |T|² before
        _dot(n, t, v1, v2)
        for comp in range(3):
            np.multiply(n[comp], v1, out=v2)
            t[comp] -= v2
        _dot(t, t, v1, v2)  # |T'|²
        np.multiply(v3, np.float32(TANGENT_KEEP**2), out=v3)
        np.maximum(v3, _TINY32, out=v3)
        np.less_equal(v1, v3, out=mask)
        np.maximum(v1, _TINY32, out=v1)
        np.sqrt(v1, out=v1)
        np.divide(1.0, v1, out=v1)
        t *= v1
        if mask.any():
            t[:, mask] = perpendicular(n[:, mask].T).T
            row[mask, 9] = 1.0
        for comp in range(3):
            row[:, 3 + comp] = n[comp]
            row[:, 6 + comp] = t[comp]


def _dot(x: Array, y: Array, out: Array, tmp: Array) -> Array:
    """Row-wise dot product of two ``(3, n)`` component arrays, without allocating."""
    np.multiply(x[0], y[0], out=out)
    np.multiply(x[1], y[1], out=tmp)
    out += tmp
    np.multiply(x[2], y[2], out=tmp)
    out += tmp
    return out


def _cross_dot(n: Array, t: Array, b: Array, out: Array, tmp: Array, tmp2: Array) -> Array:
    """``(n × t) · b`` for ``(3, n)`` component arrays, without allocating."""
    out[...] = 0.0
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        np.multiply(n[j], t[k], out=tmp)
        np.multiply(n[k], t[j], out=tmp2)
        tmp -= tmp2
        tmp *= b[i]
        out += tmp
    return out
