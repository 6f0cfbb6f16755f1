"""The tangent frame a tangent-space normal map is read in: the thesis's, or MikkTSpace's.

A normal map only means something together with the tangent frame it was baked in. Two frames
are offered:

* ``thesis`` — Lengyel's per-triangle ``T``/``B`` (Eq. 4.8) summed unnormalised per render
  vertex, so each triangle counts by its position area over its UV area; Gram–Schmidt against
  the vertex normal; handedness ``w = sign((N×T)·B)`` from the sums (``studio.core.mesh.geometry``).
* ``mikktspace`` — the convention of today's bakers (Blender, Substance, xNormal, Marmoset) and
  engines (Unreal, Unity, Godot, the glTF specification's default): per triangle the *unit*
  direction of ``T``, summed per render vertex weighted by the triangle's angle at that corner,
  Gram–Schmidt against the normal, and ``w`` the side of the UV layout the vertex lies on
  (``+1`` where the UV triangle is counter-clockwise like the mesh, ``−1`` on a mirrored
  island). A map baked by those tools shows without seams or wrong lighting only in this frame.

MikkTSpace proper outputs a tangent per triangle *corner* and splits a vertex whose corners lie
on both sides of a UV mirror line; the studio keeps one tangent per render vertex, so such a
vertex takes the side most of its corner angle lies on and sums only those corners ("faces with
the same UV side"). It also projects every corner's tangent onto the tangent plane before
weighting, and measures the angle between projected edges; here the 3-D angle weights the raw
unit tangent and the sum is projected once. On smooth faces the two differ by well under a
degree; where the UVs are mirrored or sheared (where the thesis's frame differs most) they agree.

Everything is vectorised over corners; nothing here loops over vertices in Python.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

Array = np.ndarray
TangentFrame = Literal["mikktspace", "thesis"]

#: The frames, the default first: imported faces are read in the bakers' convention.
TANGENT_FRAMES: tuple[str, ...] = ("mikktspace", "thesis")
DEFAULT_TANGENT_FRAME = "mikktspace"

#: A UV triangle counts as degenerate when |det| <= UV_SINE·|e1|·|e2|, i.e. when its UV edges are
#: parallel to within ~1e-7 rad: 1/det would otherwise explode (or be inf for det == 0).
UV_SINE = 1e-7
#: A tangent is unusable when, after removing its normal component, less than this fraction of
#: its length is left (it was parallel to the normal): its direction would be rounding noise.
TANGENT_KEEP = 1e-4
_TINY = float(np.finfo(np.float32).tiny)


def uv_directions(uvs: Array, triangles: Array) -> tuple[Array, Array, Array]:
    """Per triangle, ``a, b`` with ``T ∝ a·Q1 + b·Q2`` pointing along +u, and the UV side.

    ``a = t2·s``, ``b = −t1·s`` with ``s = sign(s1·t2 − s2·t1)``: Lengyel's ``T`` (Eq. 4.8)
    without the ``1/det`` magnitude, which the unit direction drops. The side is ``+1`` for a
    counter-clockwise UV triangle, ``−1`` for a mirrored one and ``0`` for a UV triangle of
    (numerically) zero area, which contributes nothing.
    """
    uv = np.asarray(uvs, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.intp)
    d1 = uv[t[:, 1]] - uv[t[:, 0]]
    d2 = uv[t[:, 2]] - uv[t[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    scale = np.sqrt(np.einsum("ij,ij->i", d1, d1) * np.einsum("ij,ij->i", d2, d2))
    side = np.where(np.abs(det) > UV_SINE * scale, np.sign(det), 0.0)
    return side * d2[:, 1], -side * d1[:, 1], side


def corner_angles(corners: Array) -> Array:
    """``(F, 3)`` interior angle of each triangle at each corner, from ``(F, 3, 3)`` corner
    positions."""
    c = np.moveaxis(np.asarray(corners), 2, 0)  # (3 components, F, 3 corners)
    return _edge_angles(c[:, :, 1] - c[:, :, 0], c[:, :, 2] - c[:, :, 0],
                        c[:, :, 2] - c[:, :, 1])


def _edge_angles(e01: Array, e02: Array, e12: Array) -> Array:
    """``(F, 3)`` corner angles from component-major ``(3, F)`` edges (corner 0 → 1, 0 → 2,
    1 → 2); ``atan2(|e×f|, e·f)`` stays accurate for slivers where ``acos`` does not."""
    cross = np.sqrt((e01[1] * e02[2] - e01[2] * e02[1]) ** 2
                    + (e01[2] * e02[0] - e01[0] * e02[2]) ** 2
                    + (e01[0] * e02[1] - e01[1] * e02[0]) ** 2)
    dots = np.stack([(e01 * e02).sum(axis=0), -(e01 * e12).sum(axis=0),
                     (e02 * e12).sum(axis=0)], axis=1)
    return np.arctan2(cross[:, None], dots)


def _rows_at(rows: Array, index: Array) -> Array:
    """``rows[:, index]`` for component rows (3, n), a ``take`` per row: numpy's 2-D fancy
    index gathers several times slower, and this runs on every posed frame."""
    out = np.empty((len(rows), len(index)), rows.dtype)
    for k in range(len(rows)):
        np.take(rows[k], index, out=out[k])
    return out


def _posed_angles(e01: Array, e02: Array, e12: Array) -> Array:
    """``_edge_angles`` for every posed frame, a third cheaper: the angles at corners 0 and 1
    by ``atan2``, the third as π minus them (a triangle's angles sum to π). That holds for
    triangles without area too: points in a line have one angle of π, and where two corners
    meet, ``atan2(0, −0.0)`` is π at the second of them, as three ``atan2`` s give."""
    def dot(a: Array, b: Array) -> Array:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    cx = e01[1] * e02[2] - e01[2] * e02[1]
    cy = e01[2] * e02[0] - e01[0] * e02[2]
    cz = e01[0] * e02[1] - e01[1] * e02[0]
    cross = np.sqrt(cx * cx + cy * cy + cz * cz)
    out = np.empty((len(cross), 3), cross.dtype)
    np.arctan2(cross, dot(e01, e02), out=out[:, 0])
    np.arctan2(cross, -dot(e01, e12), out=out[:, 1])
    np.maximum(np.pi - out[:, 0] - out[:, 1], 0.0, out=out[:, 2])
    return out


def perpendicular(normals: Array) -> Array:
    """Some unit vector perpendicular to each unit normal, for vertices without a tangent."""
    n = np.asarray(normals, dtype=np.float64)
    axis = np.zeros_like(n)
    axis[np.arange(len(n)), np.argmin(np.abs(n), axis=1)] = 1.0  # never parallel to n
    out = np.cross(n, axis)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), _TINY)


class MikkTSpaceFrame:
    """MikkTSpace-style tangents of one mesh, with everything that depends only on its UVs and
    topology (the triangles' UV directions and sides, each vertex's side) worked out once, so a
    posed frame costs a few vectorised passes over the corners.

    ``triangles`` index render vertices, ``weld`` maps them to welded positions, and
    ``rest_welded`` (the neutral pose) decides each vertex's side once: a vertex's handedness
    must not flip while the face animates.
    """

    def __init__(self, triangles: Array, uvs: Array, weld: Array, rest_welded: Array) -> None:
        self.triangles = np.asarray(triangles, dtype=np.intp)
        self.n_vertices = len(weld)
        self.welded_triangles = np.asarray(weld, dtype=np.intp)[self.triangles]
        a, b, side = uv_directions(uvs, self.triangles)
        self._a, self._b = a[:, None], b[:, None]
        corner_vertex = self.triangles.ravel()
        rest = np.asarray(rest_welded, dtype=np.float64)
        angles = corner_angles(rest[self.welded_triangles]).ravel()
        corner_side = np.repeat(side, 3)
        votes = np.bincount(corner_vertex, weights=angles * corner_side,
                            minlength=self.n_vertices)
        #: +1 or −1 per render vertex: the UV side most of its corner angle lies on
        self.side = np.where(votes < 0.0, -1.0, 1.0)
        self._keep = (corner_side == self.side[corner_vertex]).reshape(-1, 3).astype(np.float32)
        # the corners sorted by their vertex once, so that a frame that moves part of the
        # face finds the corners of just its vertices (``subset``)
        order = np.argsort(corner_vertex, kind="stable")
        by_vertex = corner_vertex[order]
        self._corner_order = order
        everyone = np.arange(self.n_vertices)
        self._vertex_first = np.searchsorted(by_vertex, everyone, side="left")
        self._vertex_count = np.searchsorted(by_vertex, everyone, side="right") - \
            self._vertex_first
        self._corner_vertex = corner_vertex
        self._wtri_t = np.ascontiguousarray(self.welded_triangles.T)  # (3, F)
        self._a_row = self._a[:, 0].astype(np.float32)  # (F,): broadcast over x, y, z rows
        self._b_row = self._b[:, 0].astype(np.float32)

    def tangents(self, positions_welded: Array, normals: Array) -> Array:
        """``(V, 4)`` float64 tangents ``(x, y, z, w)`` for one pose and its unit vertex
        normals (per render vertex). A vertex without a usable tangent (every corner's UV
        triangle degenerate, or the sum parallel to the normal) gets some unit vector
        perpendicular to its normal and ``w = +1``, never NaN."""
        direction, weight = self._face_terms(positions_welded, self._wtri_t, self._a_row,
                                             self._b_row, self._keep)
        summed = np.empty((self.n_vertices, 3))
        for j in range(3):  # a bincount per axis: no gather of every corner
            summed[:, j] = np.bincount(self._corner_vertex, weights=(direction[j][:, None]
                                                                     * weight).ravel(),
                                       minlength=self.n_vertices)
        return orthonormal_frame(summed, normals, self.side)

    @staticmethod
    def _face_terms(positions_welded: Array, wtri_t: Array, a: Array, b: Array,
                    keep: Array) -> tuple[Array, Array]:
        """Per triangle its unit +u direction ``(3, F)`` and its kept corners' angles
        ``(F, 3)``, in float32 (the vertex buffer's precision) and component-major, so each
        step is a flat pass over the triangles: this runs on every posed frame."""
        pos_t = np.ascontiguousarray(np.asarray(positions_welded, dtype=np.float32).T)
        c0, c1, c2 = (_rows_at(pos_t, wtri_t[k]) for k in range(3))
        e1, e2, e3 = c1 - c0, c2 - c0, c2 - c1
        direction = a * e1 + b * e2
        length = np.sqrt(direction[0] * direction[0] + direction[1] * direction[1]
                         + direction[2] * direction[2])
        direction = np.divide(direction, length, out=np.zeros_like(direction),
                              where=length > _TINY)
        return direction, _posed_angles(e1, e2, e3) * keep

    def subset(self, vertices: Array) -> MikkSubset:
        """The index work for recomputing only ``vertices`` (render vertices, e.g. those a
        pose moves), done once and reused by every frame that moves the same part."""
        vertices = np.sort(np.asarray(vertices, dtype=np.intp))
        counts = self._vertex_count[vertices]
        ends = np.cumsum(counts)
        firsts = self._vertex_first[vertices]
        at = np.repeat(firsts - (ends - counts), counts) + np.arange(int(ends[-1]) if len(ends)
                                                                      else 0)
        corners = self._corner_order[at]  # face * 3 + corner, grouped by vertex
        faces, local = np.unique(corners // 3, return_inverse=True)
        has = counts > 0
        local = local.reshape(-1)
        return MikkSubset(vertices, np.flatnonzero(has), faces, local,
                          3 * local + corners % 3, (ends - counts)[has],
                          np.ascontiguousarray(self._wtri_t[:, faces]), self._a_row[faces],
                          self._b_row[faces], self._keep[faces], self.side[vertices])

    def tangents_of(self, subset: MikkSubset, positions_welded: Array, normals: Array) -> Array:
        """``(len(subset.vertices), 4)`` tangents of the subset's vertices only (``normals``
        theirs, in the same order): the values ``tangents`` gives them, orthogonalised in
        float32 (the vertex buffer's precision) where ``tangents`` uses float64."""
        direction, weight = self._face_terms(positions_welded, subset.wtri_t, subset.a,
                                             subset.b, subset.keep)
        per_corner = _rows_at(direction, subset.local_face)
        per_corner *= np.take(weight.ravel(), subset.flat_corner)
        summed = np.zeros((len(subset.vertices), 3), np.float32)
        if len(subset.starts):
            summed[subset.with_corners] = np.add.reduceat(per_corner, subset.starts, axis=1).T
        return orthonormal_frame(summed, normals, subset.side)


@dataclass(frozen=True)
class MikkSubset:
    """Index arrays for the tangents of some render vertices (see ``MikkTSpaceFrame.subset``)."""

    vertices: Array  # the render vertices, ascending
    with_corners: Array  # which of them have corners (index into ``vertices``)
    faces: Array  # the triangles their corners belong to
    local_face: Array  # per corner (grouped by vertex): index into ``faces``
    flat_corner: Array  # per corner: 3 × its local face + which corner of it (0, 1, 2)
    starts: Array  # where each vertex with corners starts in the corner arrays
    # what the frame reads of its faces and vertices, gathered once: (3, F') welded corners,
    # UV factors, kept corners, each vertex's side
    wtri_t: Array
    a: Array
    b: Array
    keep: Array
    side: Array


def orthonormal_frame(summed: Array, normals: Array, handedness: Array) -> Array:
    """Gram–Schmidt ``T' = normalize(T − (N·T)N)`` with handedness ``w``; a tangent that is
    missing or parallel to the normal falls back to a perpendicular with ``w = +1``.

    On component rows (x, y, z each one contiguous array): it runs every posed frame, and
    numpy's sums along a short last axis cost several times these flat passes. In float32 when
    ``summed`` is (a frame's part, bound for the float32 vertex buffer), else in float64."""
    dtype = np.float32 if np.asarray(summed).dtype == np.float32 else np.float64
    n = np.array(np.asarray(normals).T, dtype=dtype)  # (3, V)
    t = np.array(np.asarray(summed).T, dtype=dtype)
    length = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    n /= np.maximum(length, _TINY)
    along = n[0] * t[0] + n[1] * t[1] + n[2] * t[2]
    t_length = np.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    t -= along * n
    o_len = np.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    usable = (o_len > TANGENT_KEEP * t_length) & (o_len > _TINY)
    t /= np.where(usable, o_len, 1.0)
    out = np.empty((n.shape[1], 4), dtype)
    out[:, :3] = t.T
    out[:, 3] = handedness
    if not usable.all():
        out[~usable, :3] = perpendicular(n[:, ~usable].T)
        out[~usable, 3] = 1.0
    return out


def mikktspace_tangents(positions_render: Array, uvs: Array, triangles: Array,
                        normals_render: Array) -> Array:
    """MikkTSpace-style ``(V, 4)`` tangents of a mesh given over render vertices (each its own
    position); the standalone form of ``MikkTSpaceFrame`` that the tests check by hand."""
    positions = np.asarray(positions_render, dtype=np.float64)
    frame = MikkTSpaceFrame(triangles, uvs, np.arange(len(positions)), positions)
    return frame.tangents(positions, normals_render)
