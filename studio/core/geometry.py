"""Per-frame geometry: face and vertex normals, Lengyel tangents (SPEC §3, thesis [4.1]).

The thesis recomputes normals, tangents and bitangents on the CPU every frame, so this module has
two faces:

* small standalone functions (``face_normals``, ``vertex_normals``, ``vertex_tangents``,
  ``bitangents``) that state the maths plainly and are what the tests check against hand-worked
  values;
* ``DeformCache``, built once per mesh, which does the same work for a whole frame in a few
  milliseconds by precomputing every index structure and reusing every buffer.

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

import numpy as np

from studio.core.mesh import FaceMesh

Array = np.ndarray

#: Fallback normal for vertices that touch no triangle of non-zero area.
FALLBACK_NORMAL = (0.0, 0.0, 1.0)

# A UV triangle counts as degenerate when |det| <= _UV_SINE * |e1|·|e2|, i.e. when its UV edges
# are parallel to within ~1e-7 rad: 1/det would otherwise explode (or be inf for det == 0).
_UV_SINE = 1e-7
# A tangent is unusable when, after removing its normal component, less than this fraction of its
# length is left (it was parallel to the normal): its direction would be rounding noise.
_TANGENT_KEEP = 1e-4
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

    Area weighting is what the thesis code does (SPEC §3). A vertex that touches no triangle of
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
    ok = (np.abs(det) > _UV_SINE * scale) & (det != 0.0)
    r = np.zeros_like(det)
    np.divide(1.0, det, out=r, where=ok)
    return r * t2, -r * t1, -r * s2, r * s1


def _perpendicular(normals: Array) -> Array:
    """Some unit vector perpendicular to each (unit) normal, for vertices without a tangent."""
    n = np.asarray(normals, dtype=np.float64)
    # Cross with the coordinate axis least aligned with n: never parallel, so never zero.
    axis = np.zeros_like(n)
    axis[np.arange(len(n)), np.argmin(np.abs(n), axis=1)] = 1.0
    return _normalise_rows(np.cross(n, axis), (1.0, 0.0, 0.0))


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
    usable = (o_len2 > _TANGENT_KEEP**2 * t_len2) & (o_len2 > _TINY32)
    out = np.empty((n_vertices, 4), dtype=np.float64)
    out[:, :3] = _normalise_rows(ortho, (1.0, 0.0, 0.0))
    out[:, 3] = np.where(np.einsum("ij,ij->i", np.cross(n, t_sum), b_sum) < 0.0, -1.0, 1.0)
    if not usable.all():
        out[~usable, :3] = _perpendicular(n[~usable])
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

        # Per capacity k, a table[row, j] = j-th item of the owner in that row (pad where it has
        # fewer), built only for that group so one vertex of huge valence costs nothing extra.
        sort = np.argsort(owner, kind="stable")
        owner_sorted = owner[sort]
        item_sorted = item[sort]
        first = np.zeros(n_owners + 1, dtype=np.intp)
        np.cumsum(count, out=first[1:])
        rank = np.arange(len(owner)) - first[owner_sorted]
        cap_sorted = cap[owner_sorted]

        self.chunks: list[tuple[int, int, int, int]] = []  # (row lo, row hi, capacity, offset)
        pieces: list[Array] = []
        offset = 0
        for k in np.unique(cap_by_row).tolist():
            if k == 0:
                continue  # owners without items: their rows stay zero
            lo, hi = np.searchsorted(cap_by_row, [k, k + 1]).tolist()
            mine = cap_sorted == k
            table = np.full((hi - lo, k), pad, dtype=np.intp)
            table[row_of[owner_sorted[mine]] - lo, rank[mine]] = item_sorted[mine]
            step = max(1, (_CHUNK if chunk is None else chunk) // k)
            for start in range(lo, hi, step):
                stop = min(hi, start + step)
                block = table[start - lo : stop - lo].T  # (k, n): item j of every owner
                pieces.append(block.ravel())
                self.chunks.append((start, stop, k, offset))
                offset += block.size
        self.index = np.concatenate(pieces) if pieces else np.zeros(0, dtype=np.intp)
        self.scratch_rows = max((k * (hi - lo) for lo, hi, k, _ in self.chunks), default=0)

    def reduce(self, jobs: list[tuple[Array, Array, Array]]) -> None:
        """For each ``(source, scratch, out)``: ``out[row] = Σ source[item]`` over the row's items.

        ``source`` has one zero row past the items (the padding item); ``scratch`` holds at least
        ``scratch_rows`` rows; rows of ``out`` whose owner has no items are left untouched.
        """
        views = [(_row_view(src), _row_view(scr), scr, out) for src, scr, out in jobs]
        index = self.index
        for lo, hi, k, offset in self.chunks:
            m = k * (hi - lo)
            ix = index[offset : offset + m]
            for src_v, scr_v, scr, out in views:
                np.take(src_v, ix, axis=0, out=scr_v[:m], mode=_NO_CHECK)
                block = scr[:m].reshape((k, hi - lo, *scr.shape[1:]))
                np.add.reduce(block, axis=0, out=out[lo:hi])


class DeformCache:
    """Per-frame normals and tangents for one mesh, with all index work done once.

    ``update(positions_welded)`` returns the interleaved vertex buffer the renderer uploads:
    ``(V, 10) float32`` per render vertex ``[x, y, z, nx, ny, nz, tx, ty, tz, w]``. Normals are
    summed over the welded triangles (area-weighted) so split seam vertices share one normal;
    tangents are summed over render vertices (they depend on the UVs) and orthogonalised against
    that welded normal. The returned array is reused by the next call; copy it to keep it.

    How it stays fast: per-triangle maths runs on contiguous float32 component arrays; each
    render vertex's sum over its triangles is a gather of 32-byte rows plus dense additions
    (``_GroupPlan``); every temporary is preallocated; if the plan had to reorder vertices, the
    per-vertex stage runs in its order and one gather of 40-byte rows puts the buffer back in
    render order.
    """

    def __init__(self, mesh: FaceMesh) -> None:
        self.mesh = mesh
        tri = mesh.triangles.astype(np.intp)
        n_f = len(tri)
        n_v = mesh.n_vertices
        n_w = mesh.n_welded
        self.n_vertices = n_v
        self.n_welded = n_w
        f32 = np.float32
        weld = mesh.weld.astype(np.intp)

        # Welded corners of every triangle, component-major for three 1-D gathers per frame.
        self._wtri = np.ascontiguousarray(weld[tri].T)  # (3, F)
        self._pos_t = np.empty((3, n_w), f32)
        self._corner = np.empty((3, 3, n_f), f32)  # [component, corner, face]
        self._e1 = np.empty((3, n_f), f32)
        self._e2 = np.empty((3, n_f), f32)
        self._tmp_f = np.empty((3, n_f), f32)
        self._tmp_f1 = np.empty(n_f, f32)
        self._coef = np.stack(_uv_coefficients(mesh.uvs, tri)).astype(f32)  # (4, F): a, b, c, d

        # Per face [cross xyz, T xyz, Bx, By] (32-byte rows) and Bz; the extra last row is the
        # plan's always-zero padding item.
        self._face8 = np.zeros((n_f + 1, 8), f32)
        self._face_z = np.zeros(n_f + 1, f32)

        # Sum faces into render vertices.
        self._plan = plan = _GroupPlan(tri.ravel(), np.repeat(np.arange(n_f), 3), n_v, pad=n_f)
        order = plan.order  # plan row -> render vertex
        self._scratch8 = np.empty((plan.scratch_rows, 8), f32)
        self._scratch_z = np.empty(plan.scratch_rows, f32)
        self._sums8 = np.zeros((n_v + 1, 8), f32)  # plan order; last row zero (padding item)
        self._sums_z = np.zeros(n_v, f32)

        # Welded normal sums: a render vertex's own sum unless a seam split its position; only
        # the split ones (usually a few percent) are re-summed over all their copies.
        identity_weld = n_v == n_w and np.array_equal(weld, np.arange(n_v))
        weld_of_row = weld[order]
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

        # Per-vertex stage, in plan order, on contiguous component arrays.
        self._pos_index = None if (plan.identity and identity_weld) else weld_of_row
        self._n = np.empty((3, n_v), f32)
        self._t = np.empty((3, n_v), f32)
        self._b = np.empty((3, n_v), f32)
        self._v1 = np.empty(n_v, f32)
        self._v2 = np.empty(n_v, f32)
        self._v3 = np.empty(n_v, f32)
        self._mask = np.empty(n_v, dtype=bool)
        self._out = np.empty((n_v, 10), f32)  # render order (returned)
        if plan.identity:
            self._row = self._out
        else:
            self._row = np.empty((n_v, 10), f32)  # plan order
            self._row_void = self._row.view(np.dtype((np.void, 40))).reshape(n_v)
            self._out_void = self._out.view(np.dtype((np.void, 40))).reshape(n_v)
            self._row_of_vertex = np.empty(n_v, dtype=np.intp)
            self._row_of_vertex[order] = np.arange(n_v)

    @property
    def buffer(self) -> Array:
        """The ``(V, 10)`` array ``update`` fills (valid after the first call)."""
        return self._out

    def update(self, positions_welded: Array) -> Array:
        """Recompute the interleaved ``(V, 10)`` float32 buffer for one frame's welded positions."""
        p = np.asarray(positions_welded)
        if p.shape != (self.n_welded, 3):
            raise ValueError(f"expected positions of shape ({self.n_welded}, 3), got {p.shape}")
        pos_t = self._pos_t
        pos_t[...] = p.T

        # Per-triangle edges, cross product (Eq. 4.1) and Lengyel T and B (Eq. 4.8).
        corner = self._corner
        for comp in range(3):
            np.take(pos_t[comp], self._wtri, out=corner[comp], mode=_NO_CHECK)
        e1, e2, tmp, tmp1 = self._e1, self._e2, self._tmp_f, self._tmp_f1
        np.subtract(corner[:, 1], corner[:, 0], out=e1)
        np.subtract(corner[:, 2], corner[:, 0], out=e2)
        face = self._face8[:-1]
        for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
            np.multiply(e1[j], e2[k], out=tmp1)
            np.multiply(e1[k], e2[j], out=tmp[0])
            np.subtract(tmp1, tmp[0], out=face[:, i])
        a, b, c, d = self._coef
        np.multiply(e1, a, out=tmp)
        for comp in range(3):
            np.multiply(e2[comp], b, out=tmp1)
            np.add(tmp[comp], tmp1, out=face[:, 3 + comp])
        np.multiply(e1, c, out=tmp)
        for comp in range(3):
            np.multiply(e2[comp], d, out=tmp1)
            np.add(tmp[comp], tmp1, out=face[:, 6 + comp] if comp < 2 else self._face_z[:-1])

        # Sum per render vertex (plan order), then per welded vertex for the normals.
        sums8 = self._sums8
        self._plan.reduce(
            [
                (self._face8, self._scratch8, sums8),
                (self._face_z, self._scratch_z, self._sums_z),
            ]
        )
        n, t, bt = self._n, self._t, self._b
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
        v1, v2, v3, mask = self._v1, self._v2, self._v3, self._mask
        # Normalise the normals; zero sums fall back to (0, 0, 1).
        _dot(n, n, v1, v2)
        np.less_equal(v1, _TINY32, out=mask)
        np.maximum(v1, _TINY32, out=v1)
        np.sqrt(v1, out=v1)
        np.divide(1.0, v1, out=v1)
        n *= v1
        if mask.any():
            n[:, mask] = np.array(FALLBACK_NORMAL, np.float32)[:, None]

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
        np.multiply(v3, np.float32(_TANGENT_KEEP**2), out=v3)
        np.maximum(v3, _TINY32, out=v3)
        np.less_equal(v1, v3, out=mask)
        np.maximum(v1, _TINY32, out=v1)
        np.sqrt(v1, out=v1)
        np.divide(1.0, v1, out=v1)
        t *= v1
        if mask.any():
            t[:, mask] = _perpendicular(n[:, mask].T).T
            row[mask, 9] = 1.0

        # Interleave; if the plan reordered vertices, one 40-byte-row gather restores the order.
        for comp in range(3):
            if self._pos_index is None:
                row[:, comp] = pos_t[comp]
            else:
                np.take(pos_t[comp], self._pos_index, out=v1, mode=_NO_CHECK)
                row[:, comp] = v1
            row[:, 3 + comp] = n[comp]
            row[:, 6 + comp] = t[comp]
        if row is not self._out:
            np.take(self._row_void, self._row_of_vertex, out=self._out_void, mode=_NO_CHECK)
        return self._out


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
