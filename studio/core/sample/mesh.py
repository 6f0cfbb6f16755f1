"""Geometry of the bundled sample face: a whole head built from one analytic (u, v) surface.

Why analytic: the head is a stack of horizontal cross-sections (rings) swept from the top of the
skull (v = 1) to the bottom of the neck (v = 0), azimuth ``u`` wrapping once around with the UV
seam at the back. The same map gives vertex positions at any resolution *and* the position of
every texel, so painted maps, masks, wrinkles and key poses agree with the geometry by
construction. Facial features and pose motions are smooth Gaussian fields over *face
coordinates*: the (x, y) of the undisplaced head, which the whole sample uses to place things.

Vertex density and texel density are warped separately toward the face, so the face gets most
vertices and most of the UV square while the back of the head stays coarse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

Array = np.ndarray

# Azimuth warps θ = π·(a·w + (1 − a)·w^k), w = 2p − 1: a < 1 spends more of p on the front.
A_MESH, K_MESH = 0.5, 3  # vertices: 4× denser in azimuth at the front than at the back
A_UV, K_UV = 0.45, 7  # texels: nearly even over the whole face, which fills half of u
MIN_RING = 5  # fewest vertices on the rings next to the poles
MIN_VERTICES = 64

# Face landmarks in face coordinates (x: toward the character's left, y: up). Eyes sit at
# (±EYE_X, EYE_Y); "right" is the character's own right, the −X side.
EYE_X, EYE_Y = 0.27, 0.09
EYE_HALF_WIDTH = 0.112  # the outer eye corner (canthus) is at x = ±(EYE_X + EYE_HALF_WIDTH)
CORNER_X, CORNER_Y = 0.45, 0.075  # crow's feet centre, just outside the outer eye corner
BROW_Y = 0.245
HAIRLINE_Y = 0.70
EAR_THETA, EAR_Y = 1.74, 0.0  # ears: azimuth (radians from the front) and height
MOUTH_Y = -0.425
MOUTH_X = 0.2  # mouth corners


def smoothstep(e0: float, e1: float, x: Array) -> Array:
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def blob(x: Array, y: Array, cx: float, cy: float, sx: float, sy: float) -> Array:
    """Anisotropic Gaussian bump, 1 at (cx, cy)."""
    return np.exp(-0.5 * (((x - cx) / sx) ** 2 + ((y - cy) / sy) ** 2))


# --- profile: the rings' cross-section parameters from the top pole down to the bottom pole ---

def _knots() -> Array:
    """(y, half-width X, front depth Zf, back depth Zb, centre z0) down the head."""
    rows = []
    for deg in range(0, 91, 10):  # skull: a quarter ellipse down to brow level
        s, c = math.sin(math.radians(deg)), math.cos(math.radians(deg))
        rows.append((0.10 + 0.88 * c ** 1.15, 0.72 * s ** 0.75, 0.80 * s ** 0.75, 0.92 * s ** 0.85,
                     -0.12))
    rows += [
        (-0.08, 0.715, 0.80, 0.90, -0.12),  # cheekbones
        (-0.30, 0.68, 0.79, 0.77, -0.13),  # nose base / back of the skull
        (-0.50, 0.60, 0.78, 0.56, -0.14),  # mouth / nape
        (-0.66, 0.50, 0.78, 0.44, -0.15),  # jaw
        (-0.79, 0.35, 0.73, 0.40, -0.15),  # chin
        (-0.86, 0.33, 0.55, 0.38, -0.15),  # under the chin
        (-0.92, 0.325, 0.40, 0.37, -0.15),  # throat
        (-1.10, 0.33, 0.37, 0.37, -0.15),  # neck
        (-1.15, 0.27, 0.30, 0.30, -0.15),
        (-1.17, 0.0, 0.0, 0.0, -0.15),  # bottom pole
    ]
    return np.array(rows, dtype=np.float64)


def _chaikin(points: Array, iterations: int) -> Array:
    """Corner cutting: a smooth curve that never overshoots its knots; ends stay put."""
    for _ in range(iterations):
        a, b = points[:-1], points[1:]
        mid = np.empty((2 * len(a), points.shape[1]))
        mid[0::2] = 0.75 * a + 0.25 * b
        mid[1::2] = 0.25 * a + 0.75 * b
        points = np.vstack([points[:1], mid[1:-1], points[-1:]])
    return points


@dataclass(frozen=True)
class Profile:
    """Dense samples of the ring parameters with the mesh and UV arc-length fractions."""

    values: Array  # (S, 5): y, X, Zf, Zb, z0
    s_mesh: Array  # (S,) in [0, 1]: where rings go
    s_uv: Array  # (S,) in [0, 1]: 1 − v
    mesh_weight: Array  # (S,) rings per unit length, relative
    mesh_length: float  # weighted length: ring spacing = dq · mesh_length / mesh_weight

    def at_mesh(self, q: Array) -> Array:
        return self._interp(q, self.s_mesh)

    def at_v(self, v: Array) -> Array:
        return self._interp(1.0 - np.asarray(v, dtype=np.float64), self.s_uv)

    def v_of_mesh(self, q: Array) -> Array:
        return 1.0 - np.interp(q, self.s_mesh, self.s_uv)

    def v_of_y(self, y: Array) -> Array:
        """UV v of the ring at height y (y falls monotonically down the profile)."""
        ys = self.values[:, 0]
        return 1.0 - np.interp(-np.asarray(y, dtype=np.float64), -ys, self.s_uv)

    def _interp(self, frac: Array, s: Array) -> Array:
        frac = np.asarray(frac, dtype=np.float64)
        return np.stack([np.interp(frac, s, self.values[:, k]) for k in range(5)], axis=-1)


@lru_cache(maxsize=1)
def profile() -> Profile:
    values = _chaikin(_knots(), 5)
    y, half_width, front, back = values[:, 0], values[:, 1], values[:, 2], values[:, 3]
    ds = np.sqrt(np.diff(y) ** 2 + np.diff(front) ** 2
                 + 0.5 * (np.diff(half_width) ** 2 + np.diff(back) ** 2))
    face = smoothstep(-1.0, -0.8, y) * smoothstep(0.95, 0.7, y)
    mesh_weight = 1.0 + 0.9 * face
    uv_weight = 1.0 + 5.0 * face

    def cumulative(weight: Array) -> Array:
        return np.concatenate([[0.0], np.cumsum(ds * 0.5 * (weight[1:] + weight[:-1]))])

    s_mesh, s_uv = cumulative(mesh_weight), cumulative(uv_weight)
    return Profile(values, s_mesh / s_mesh[-1], s_uv / s_uv[-1], mesh_weight, float(s_mesh[-1]))


# --- azimuth: theta = 0 looks toward +Z, the seam (u = 0 = 1) is at the back --------------------

def theta_of(p: Array, a: float, k: int) -> Array:
    """Azimuth for a parameter p in [0, 1] (p = 0.5 faces +Z); k is odd, so the warp is too."""
    w = 2.0 * np.asarray(p, dtype=np.float64) - 1.0
    return math.pi * (a * w + (1.0 - a) * w ** k)


@lru_cache(maxsize=1)
def _uv_theta_table() -> tuple[Array, Array]:
    u = np.linspace(0.0, 1.0, 8193)
    return theta_of(u, A_UV, K_UV), u


def u_of_theta(theta: Array) -> Array:
    thetas, u = _uv_theta_table()
    return np.interp(theta, thetas, u)


def base_point(rings: Array, theta: Array) -> Array:
    """Undisplaced head point for ring parameters (…, 5) and azimuth (…)."""
    y, half_width, front, back, z0 = np.moveaxis(rings, -1, 0)
    c, s = np.cos(theta), np.sin(theta)
    depth = 0.5 * (front + back) + 0.5 * (front - back) * c
    # the jaw narrows toward the chin at the front only, so the back of the neck stays round
    taper = 1.0 - 0.30 * smoothstep(-0.25, -0.8, y) * np.clip(c, 0.0, 1.0) ** 2
    return np.stack(np.broadcast_arrays(half_width * s * taper, y, z0 + depth * c), axis=-1)


def front_weight(cos_theta: Array) -> Array:
    """1 on the face, 0 from the ears back: keeps face features off the back of the head."""
    return smoothstep(0.15, 0.55, cos_theta)


def features(base: Array, theta: Array) -> Array:
    """Displacement (…, 3) that sculpts brow, eyes, nose, lips, chin, cheeks and ears."""
    x, y = base[..., 0], base[..., 1]
    ax = np.abs(x)
    dz = (
        0.045 * blob(ax, y, 0.20, BROW_Y, 0.17, 0.05)  # brow ridge
        + 0.025 * blob(x, y, 0.0, 0.22, 0.09, 0.07)  # glabella
        - 0.095 * blob(ax, y, EYE_X, EYE_Y + 0.01, 0.12, 0.085)  # eye sockets
        + 0.065 * blob(ax, y, EYE_X, EYE_Y, 0.085, 0.045)  # eyeballs under the lids
        + 0.012 * blob(ax, y, EYE_X, EYE_Y + 0.06, 0.085, 0.018)  # upper-lid fold
        + 0.055 * blob(ax, y, 0.36, -0.06, 0.12, 0.09)  # cheekbones
        + 0.03 * blob(ax, y, 0.24, -0.28, 0.12, 0.10)  # cheeks
        + 0.045 * blob(x, y, 0.0, -0.385, 0.13, 0.03)  # upper lip
        + 0.05 * blob(x, y, 0.0, -0.465, 0.11, 0.035)  # lower lip
        - 0.02 * blob(x, y, 0.0, MOUTH_Y, 0.11, 0.012)  # lips' parting
        - 0.02 * blob(x, y, 0.0, -0.56, 0.12, 0.03)  # groove above the chin
        + 0.065 * blob(x, y, 0.0, -0.70, 0.11, 0.08)  # chin
        + 0.035 * blob(x, y, 0.0, -0.42, 0.2, 0.12)  # the mouth's forward bulge
        + 0.015 * blob(ax, y, 0.24, MOUTH_Y - 0.05, 0.06, 0.12)  # nasolabial fullness
    )
    # nose: a ridge whose height and width follow y, a rounded tip and two wings
    nose_h = np.interp(-y, -np.array([0.22, 0.12, 0.0, -0.12, -0.19, -0.245, -0.29]),
                       [0.0, 0.03, 0.07, 0.14, 0.18, 0.10, 0.0])
    nose_w = np.interp(-y, -np.array([0.22, 0.0, -0.19, -0.29]), [0.055, 0.045, 0.06, 0.07])
    dz = dz + nose_h * np.exp(-0.5 * (x / nose_w) ** 2)
    dz = dz + 0.05 * blob(x, y, 0.0, -0.175, 0.05, 0.045) + 0.06 * blob(ax, y, 0.085, -0.215,
                                                                           0.04, 0.035)
    out = np.zeros(base.shape, dtype=np.float64)
    out[..., 2] = dz * front_weight(np.cos(theta))
    # ears: outward bumps on the sides
    ear_r2 = ((np.abs(theta) - EAR_THETA) / 0.1) ** 2 + ((y - EAR_Y) / 0.16) ** 2
    ear = 0.12 * np.exp(-0.5 * ear_r2 ** 2)  # flat-topped, so it reads as a flap
    out[..., 0] = np.sign(x) * ear
    return out


# --- the mesh -------------------------------------------------------------------------------------

@dataclass
class SampleGeometry:
    rest: Array  # (W, 3) float32 welded positions
    triangles: Array  # (F, 3) int32 over render vertices
    uvs: Array  # (V, 2) float32
    weld: Array  # (V,) int32
    face_xy: Array  # (W, 2) face coordinates of each welded vertex
    front: Array  # (W,) front weight of each welded vertex


def _ring_counts(n_vertices: int) -> tuple[Array, Array]:
    """Mesh fractions of the rings (poles included) and vertex counts of the inner rings.

    Counts make quads on the face roughly square (front spacing ``X·dθ/dp / n`` equal to the
    ring spacing), then are adjusted to sum to exactly ``n_vertices − 2`` (largest remainder).
    """
    prof = profile()
    front_rate = 2.0 * math.pi * A_MESH  # dθ/dp at the front
    dense = np.linspace(0.0, 1.0, 4097)
    rate = np.interp(dense, prof.s_mesh, prof.values[:, 1] * prof.mesh_weight)  # X · weight
    gaps = round(math.sqrt((n_vertices - 2) * prof.mesh_length / (front_rate * rate.mean())))
    gaps = max(4, min(gaps, (n_vertices - 2) // MIN_RING + 1))
    q = np.linspace(0.0, 1.0, gaps + 1)
    raw = np.maximum(np.interp(q[1:-1], dense, rate), 1e-6)
    target = n_vertices - 2
    scaled = raw * (target / raw.sum())
    counts = np.maximum(np.floor(scaled).astype(np.int64), MIN_RING)
    # hand out (or take back) the difference where rounding lost (or gained) most
    while (diff := target - int(counts.sum())) != 0:
        if diff > 0:
            order = np.argsort(counts - scaled, kind="stable")[:diff]
            counts[order] += 1
        else:
            spare = np.flatnonzero(counts > MIN_RING)
            order = spare[np.argsort(scaled[spare] - counts[spare], kind="stable")][:-diff]
            counts[order] -= 1
    return q, counts


def _strip(a0: int, ua: Array, b0: int, ub: Array) -> Array:
    """Triangles between two open rings of render vertices, merged by segment midpoints.

    Ring A (above) has render vertices a0 … a0+len(ua)−1 at ascending u, ring B (below) likewise.
    Triangles are counter-clockwise seen from outside (u grows toward +x on the face).
    """
    na, nb = len(ua) - 1, len(ub) - 1
    keys = np.concatenate([0.5 * (ua[1:] + ua[:-1]), 0.5 * (ub[1:] + ub[:-1])])
    order = np.argsort(keys, kind="stable")
    is_a = order < na
    i = np.cumsum(is_a) - is_a  # A segments before this step
    j = np.cumsum(~is_a) - ~is_a  # B segments before this step
    tri = np.empty((na + nb, 3), dtype=np.int64)
    tri[:, 0] = a0 + i
    tri[:, 1] = b0 + j
    tri[:, 2] = np.where(is_a, a0 + i + 1, b0 + j + 1)
    # an A step is (A_i, B_j, A_i+1); a B step is (A_i, B_j, B_j+1)
    return tri


def build_geometry(n_vertices: int) -> SampleGeometry:
    """The neutral head with exactly ``n_vertices`` welded vertices."""
    if n_vertices < MIN_VERTICES:
        raise ValueError(f"the sample face needs at least {MIN_VERTICES} vertices")
    prof = profile()
    q, counts = _ring_counts(n_vertices)
    rings = prof.at_mesh(q)
    v_ring = prof.v_of_mesh(q)
    n_rings = len(counts)

    # welded vertices: top pole, rings, bottom pole
    ring_of = np.repeat(np.arange(n_rings), counts)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    k = np.arange(len(ring_of)) - starts[ring_of]
    p = k / counts[ring_of]
    theta = theta_of(p, A_MESH, K_MESH)
    ring_params = np.vstack([rings[:1], rings[1 + ring_of], rings[-1:]])
    theta_all = np.concatenate([[0.0], theta, [0.0]])
    base = base_point(ring_params, theta_all)
    rest = base + features(base, theta_all)

    # render vertices: each ring is open at the seam (its first vertex repeated at u = 1)
    welded_of_ring = 1 + starts  # welded index of each ring's first vertex
    r_len = counts + 1
    r_start = np.concatenate([[0], np.cumsum(r_len)[:-1]])
    ring_r = np.repeat(np.arange(n_rings), r_len)
    kr = np.arange(len(ring_r)) - r_start[ring_r]
    u_r = u_of_theta(theta_of(kr / counts[ring_r], A_MESH, K_MESH))
    weld_r = welded_of_ring[ring_r] + kr % counts[ring_r]
    uv_r = np.stack([u_r, v_ring[1 + ring_r]], axis=1)
    n_ring_render = len(ring_r)

    tris = [
        _strip(r_start[i], u_r[r_start[i]:r_start[i] + r_len[i]], r_start[i + 1],
               u_r[r_start[i + 1]:r_start[i + 1] + r_len[i + 1]])
        for i in range(n_rings - 1)
    ]
    # poles: one render vertex per fan triangle, at the middle of its ring segment
    top_u = 0.5 * (u_r[1:r_len[0]] + u_r[:r_len[0] - 1])
    last = r_start[-1]
    bot_u = 0.5 * (u_r[last + 1:last + r_len[-1]] + u_r[last:last + r_len[-1] - 1])
    top0 = n_ring_render
    bot0 = top0 + len(top_u)
    kt = np.arange(len(top_u))
    tris.append(np.stack([top0 + kt, kt, kt + 1], axis=1))
    kb = np.arange(len(bot_u))
    tris.append(np.stack([last + kb, bot0 + kb, last + kb + 1], axis=1))
    uvs = np.vstack([uv_r, np.stack([top_u, np.full_like(top_u, v_ring[0])], axis=1),
                     np.stack([bot_u, np.full_like(bot_u, v_ring[-1])], axis=1)])
    weld = np.concatenate([weld_r, np.zeros(len(top_u), np.int64),
                           np.full(len(bot_u), len(rest) - 1)])
    return SampleGeometry(
        rest=rest.astype(np.float32),
        triangles=np.vstack(tris).astype(np.int32),
        uvs=uvs.astype(np.float32),
        weld=weld.astype(np.int32),
        face_xy=base[:, :2].copy(),
        front=front_weight(np.cos(theta_all)),
    )


def uv_to_face(uv: Array) -> Array:
    """Face coordinates (…, 2) of UV points: the undisplaced head's (x, y) there."""
    uv = np.asarray(uv, dtype=np.float64)
    return base_point(profile().at_v(uv[..., 1]), theta_of(uv[..., 0], A_UV, K_UV))[..., :2]


def face_to_uv(xy: Array) -> Array:
    """UV of face points (…, 2) on the front of the head: the inverse of ``uv_to_face`` there.

    Newton's method with a finite-difference Jacobian, from a guess that ignores the jaw taper.
    """
    xy = np.asarray(xy, dtype=np.float64)
    prof = profile()
    v = prof.v_of_y(xy[..., 1])
    half_width = prof.at_v(v)[..., 1]
    theta = np.arcsin(np.clip(xy[..., 0] / half_width, -0.99, 0.99))
    uv = np.stack([u_of_theta(theta), v], axis=-1)
    du_, dv_ = np.array([1e-6, 0.0]), np.array([0.0, 1e-6])
    for _ in range(12):
        f = uv_to_face(uv) - xy
        ju = (uv_to_face(uv + du_) - uv_to_face(uv - du_)) / 2e-6
        jv = (uv_to_face(uv + dv_) - uv_to_face(uv - dv_)) / 2e-6
        det = ju[..., 0] * jv[..., 1] - jv[..., 0] * ju[..., 1]
        du = (f[..., 0] * jv[..., 1] - jv[..., 0] * f[..., 1]) / det
        dv = (ju[..., 0] * f[..., 1] - f[..., 0] * ju[..., 1]) / det
        uv = uv - np.stack([du, dv], axis=-1)
    return uv


def vertex_normals(positions: Array, triangles: Array) -> Array:
    """Area-weighted vertex normals over welded triangles (for sliding pose motions)."""
    p0, p1, p2 = (positions[triangles[:, k]] for k in range(3))
    fn = np.cross(p1 - p0, p2 - p0)
    n = np.zeros_like(positions, dtype=np.float64)
    for k in range(3):
        for axis in range(3):
            n[:, axis] += np.bincount(triangles[:, k], fn[:, axis], minlength=len(positions))
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.maximum(length, 1e-12)
