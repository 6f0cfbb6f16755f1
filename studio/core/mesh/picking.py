"""Exact picking on the CPU: a ray against every triangle at once (Möller–Trumbore, vectorised).

Used by vertex selection and by painting on the face: the hit gives the triangle, the point and
its barycentric coordinates, from which any per-corner value (a UV, a vertex) follows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray


@dataclass
class Hit:
    triangle: int  # index into the triangles that were tested
    point: Array  # (3,) world position
    barycentric: Array  # (3,) weights of the triangle's corners
    distance: float  # along the ray

    def interpolate(self, corner_values: Array) -> Array:
        """A per-corner value (3, …) at the hit point."""
        return np.tensordot(self.barycentric, corner_values, axes=1)


def ray_triangles(origin: Array, direction: Array, positions: Array, triangles: Array,
                  cull_back_faces: bool = False) -> Hit | None:
    """Nearest triangle the ray enters, or None. Degenerate triangles are never hit."""
    o = np.asarray(origin, np.float64)
    d = np.asarray(direction, np.float64)
    p0 = positions[triangles[:, 0]].astype(np.float64)
    e1 = positions[triangles[:, 1]] - p0
    e2 = positions[triangles[:, 2]] - p0
    h = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    eps = 1e-12 * max(float(np.abs(e1).max(initial=0.0)) ** 2, 1e-30)
    ok = det > eps if cull_back_faces else np.abs(det) > eps
    inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
    s = o - p0
    u = np.einsum("ij,ij->i", s, h) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    ok &= (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > 0.0)
    if not ok.any():
        return None
    t_hit = np.where(ok, t, np.inf)
    i = int(np.argmin(t_hit))
    bary = np.array([1.0 - u[i] - v[i], u[i], v[i]])
    return Hit(i, o + t[i] * d, bary, float(t[i]))


def nearest_corner(hit: Hit) -> int:
    """Which corner (0, 1, 2) of the hit triangle is closest to the hit point."""
    return int(np.argmax(hit.barycentric))
