"""Painted maps of the bundled sample face: diffuse, neutral and wrinkled normals, T1 masks.

Everything is drawn as smooth analytic functions of each texel's *face coordinates* (see
``sample_mesh``), so the maps line up with the geometry at any resolution and need no
anti-aliasing pass: a wrinkle is a Gaussian valley a few texels wide, an eyebrow a soft-edged
band. Work is confined to windows around each feature to stay fast at 1024² and above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from PIL import Image

from studio.core.sample.mesh import (
    A_UV,
    BROW_Y,
    CORNER_X,
    CORNER_Y,
    EAR_THETA,
    EAR_Y,
    EYE_HALF_WIDTH,
    EYE_X,
    EYE_Y,
    HAIRLINE_Y,
    K_UV,
    MOUTH_Y,
    base_point,
    blob,
    face_to_uv,
    front_weight,
    profile,
    smoothstep,
    theta_of,
    uv_to_face,
)
from studio.core.wrinkles.normalmap import height_to_normal

Array = np.ndarray

SEED = 2010  # the thesis' year: fixed, so the sample is the same on every run
WRINKLE_SLOPE = 1.4  # exaggeration of wrinkle slopes in the baked normal map
PORE_DEPTH = 0.00005  # model units: pores barely tilt the normals (the neutral map stays ~flat)
CANTHUS_X = EYE_X + EYE_HALF_WIDTH  # outer eye corner, where crow's feet start


@dataclass
class Texels:
    """Face coordinates of every texel centre of a square map (row 0 = top = v 1)."""

    x: Array
    y: Array
    front: Array  # 1 on the face, 0 from the ears back
    theta: Array  # (W,) azimuth of each column
    size: int

    @classmethod
    def of(cls, size: int) -> Texels:
        v = 1.0 - (np.arange(size) + 0.5) / size
        u = (np.arange(size) + 0.5) / size
        rings = profile().at_v(v).astype(np.float32)
        theta = theta_of(u, A_UV, K_UV).astype(np.float32)
        base = base_point(rings[:, None, :], theta[None, :])
        front = np.broadcast_to(front_weight(np.cos(theta))[None, :], (size, size))
        return cls(base[..., 0], base[..., 1], front, theta, size)

    def window(self, x0: float, x1: float, y0: float, y1: float) -> tuple[slice, slice]:
        """Image rows and columns that hold the face box [x0, x1] × [y0, y1] (with margin)."""
        gx, gy = np.meshgrid(np.linspace(x0, x1, 9), np.linspace(y0, y1, 9))
        uv = face_to_uv(np.stack([gx, gy], axis=-1))
        cols = uv[..., 0] * self.size
        rows = (1.0 - uv[..., 1]) * self.size
        c0, c1 = int(cols.min()) - 3, math.ceil(cols.max()) + 3
        r0, r1 = int(rows.min()) - 3, math.ceil(rows.max()) + 3
        n = self.size
        return slice(max(r0, 0), min(r1, n)), slice(max(c0, 0), min(c1, n))

    def texel_size(self, x: float, y: float) -> tuple[float, float]:
        """Model units per texel along u and along v at a face point."""
        uv = face_to_uv(np.array([x, y]))
        h = 1.0 / self.size
        du = np.linalg.norm(uv_to_face(uv + np.array([h, 0.0])) - uv_to_face(uv))
        dv = np.linalg.norm(uv_to_face(uv + np.array([0.0, h])) - uv_to_face(uv))
        return float(du), float(dv)


def _noise(size: int, cells: int, rng: np.random.Generator) -> Array:
    """Smooth value noise in about [−1, 1]: a small random grid, bicubically enlarged."""
    grid = rng.uniform(-1.0, 1.0, (cells, cells)).astype(np.float32)
    return np.asarray(Image.fromarray(grid, "F").resize((size, size), Image.BICUBIC))


def _band(dist: Array, half_width: Array | float, soft: float) -> Array:
    """1 inside |dist| < half_width, falling smoothly to 0 over ``soft``."""
    return smoothstep(half_width + soft, half_width - soft, np.abs(dist))


def _over(canvas: Array, colour: tuple[float, float, float], alpha: Array) -> None:
    canvas += (np.asarray(colour, np.float32) - canvas) * alpha[..., None]


# --- diffuse ----------------------------------------------------------------------------------

SKIN = (0.86, 0.66, 0.57)
LIPS = (0.70, 0.36, 0.36)
BROWS = (0.25, 0.17, 0.13)
HAIR = (0.20, 0.14, 0.11)
SCLERA = (0.93, 0.91, 0.88)
IRIS = (0.29, 0.43, 0.53)


def _lid_heights(dx: Array) -> tuple[Array, Array]:
    """Upper and lower eyelid curves above/below the eye centre (almond opening)."""
    t = np.clip(1.0 - (dx / EYE_HALF_WIDTH) ** 2, 0.0, None)
    skew = 1.0 + 0.25 * dx / EYE_HALF_WIDTH  # the upper lid peaks a little toward the nose
    return 0.045 * t ** 0.8 * (1.2 - 0.2 * skew), -0.03 * t ** 0.9


def paint_diffuse(tx: Texels) -> Array:
    rng = np.random.default_rng(SEED)
    n = tx.size
    img = np.empty((n, n, 3), dtype=np.float32)
    img[...] = SKIN
    tone = 0.022 * _noise(n, 24, rng) + 0.012 * _noise(n, 96, rng)
    img *= (1.0 + tone)[..., None]
    x, y, front = tx.x, tx.y, tx.front

    # warmth on cheeks, nose and ears
    rows, cols = tx.window(-0.6, 0.6, -0.6, 0.3)
    sub = img[rows, cols]
    xs, ys, fs = x[rows, cols], y[rows, cols], front[rows, cols]
    flush = (0.35 * blob(np.abs(xs), ys, 0.30, -0.16, 0.1, 0.09)
             + 0.25 * blob(xs, ys, 0.0, -0.17, 0.05, 0.05)) * fs
    _over(sub, (0.85, 0.52, 0.50), flush)

    # lips: two soft-edged lobes, the upper one with a cupid's bow
    rows, cols = tx.window(-0.3, 0.3, -0.55, -0.3)
    sub = img[rows, cols]
    xs, ys, fs = x[rows, cols], y[rows, cols], front[rows, cols]
    w = np.clip(1.0 - (xs / 0.205) ** 2, 0.0, None)
    bow = 0.008 * np.exp(-0.5 * ((np.abs(xs) - 0.04) / 0.03) ** 2)
    upper = (ys > MOUTH_Y) & (ys < MOUTH_Y + 0.005 + 0.042 * w ** 0.6 + bow)
    lower = (ys <= MOUTH_Y) & (ys > MOUTH_Y - 0.052 * w ** 0.7)
    lips_d = np.where(upper, MOUTH_Y + 0.005 + 0.042 * w ** 0.6 + bow - ys,
                      ys - (MOUTH_Y - 0.052 * w ** 0.7))
    lips_a = np.where((upper | lower) & (w > 0), smoothstep(0.0, 0.006, lips_d), 0.0) * fs
    _over(sub, LIPS, 0.9 * lips_a)
    _over(sub, (0.35, 0.15, 0.15), 0.6 * _band(ys - MOUTH_Y, 0.002, 0.003)
          * smoothstep(0.215, 0.18, np.abs(xs)) * fs)

    # nostrils
    rows, cols = tx.window(-0.12, 0.12, -0.3, -0.2)
    sub = img[rows, cols]
    xs, ys, fs = x[rows, cols], y[rows, cols], front[rows, cols]
    _over(sub, (0.30, 0.16, 0.14), 0.7 * smoothstep(0.8, 0.3, np.hypot(
        (np.abs(xs) - 0.042) / 0.026, (ys + 0.252) / 0.012)) * fs)

    # eyebrows: arched bands thinning toward the temples, with a little hair-like streaking
    rows, cols = tx.window(-0.5, 0.5, 0.12, 0.38)
    sub = img[rows, cols]
    xs, ys, fs = x[rows, cols], y[rows, cols], front[rows, cols]
    axs = np.abs(xs)
    centre = BROW_Y + 0.03 - 1.1 * (axs - 0.24) ** 2
    thick = 0.021 * smoothstep(0.46, 0.2, axs) + 0.005
    along = smoothstep(0.055, 0.085, axs) * smoothstep(0.47, 0.40, axs)
    _over(sub, BROWS, 0.88 * _band(ys - centre, thick, 0.008) * along * fs)

    # eyes: sclera inside the almond, iris, pupil, lash lines, a highlight
    rows, cols = tx.window(-0.42, 0.42, EYE_Y - 0.07, EYE_Y + 0.07)
    sub = img[rows, cols]
    xs, ys, fs = x[rows, cols], y[rows, cols], front[rows, cols]
    dx = np.abs(xs) - EYE_X
    dy = ys - EYE_Y
    up, lo = _lid_heights(dx)
    inside = np.minimum(up - dy, dy - lo)
    opening = smoothstep(0.0, 0.004, inside) * fs
    _over(sub, SCLERA, opening)
    r = np.hypot(dx, dy)
    _over(sub, IRIS, smoothstep(0.042, 0.038, r) * opening)
    _over(sub, (0.18, 0.28, 0.36), smoothstep(0.042, 0.038, r) * smoothstep(0.03, 0.041, r)
          * opening)
    _over(sub, (0.03, 0.03, 0.04), smoothstep(0.0165, 0.0135, r) * opening)
    _over(sub, (1.0, 1.0, 1.0), 0.85 * smoothstep(0.007, 0.004, np.hypot(dx + 0.009 * np.sign(
        xs), dy - 0.012)) * opening)
    lash_up = _band(dy - up, 0.0035, 0.003) * smoothstep(EYE_HALF_WIDTH + 0.01,
                                                         EYE_HALF_WIDTH - 0.01, np.abs(dx))
    lash_lo = 0.5 * _band(dy - lo, 0.002, 0.003) * smoothstep(EYE_HALF_WIDTH, EYE_HALF_WIDTH
                                                              - 0.02, np.abs(dx))
    _over(sub, (0.12, 0.08, 0.07), np.maximum(lash_up, lash_lo) * fs)
    crease = _band(dy - (up + 0.022), 0.003, 0.006) * smoothstep(0.12, 0.07, np.abs(dx))
    _over(sub, (0.62, 0.42, 0.38), 0.4 * crease * fs)

    # ears: a warmer rim around a shadowed bowl
    rows, cols = tx.window(-0.9, 0.9, EAR_Y - 0.2, EAR_Y + 0.2)
    ex = (np.abs(tx.theta[cols])[None, :] - EAR_THETA) / 0.1
    r = np.hypot(ex, (y[rows, cols] - EAR_Y) / 0.16)
    sub = img[rows, cols]
    _over(sub, (0.80, 0.50, 0.46), 0.45 * smoothstep(1.25, 0.9, r))
    _over(sub, (0.55, 0.33, 0.30), 0.55 * smoothstep(0.75, 0.45, r) * smoothstep(0.05, 0.3, r))

    # hair: the scalp above a hairline that drops past the temples and behind the ears
    theta = np.abs(tx.theta)
    hair_y = np.interp(theta, [0.0, 0.5, 1.0, 1.35, 1.55, 1.95, 2.3, math.pi],
                       [HAIRLINE_Y, HAIRLINE_Y - 0.03, 0.55, 0.30, 0.24, 0.22, -0.2, -0.42])
    edge = hair_y[None, :] + 0.01 * _noise(n, 40, rng)
    hair = smoothstep(edge - 0.015, edge + 0.035, y)
    strands = 0.85 + 0.15 * _noise(n, 200, rng)
    _over(img, HAIR, hair * 0.97)
    img *= np.where(hair > 0, 1.0 + (strands - 1.0) * hair, 1.0)[..., None]
    return (np.clip(img, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


# --- normal maps ------------------------------------------------------------------------------

def _crease(dist: Array, width: float) -> Array:
    """A wrinkle's cross-section: a narrow valley with slightly raised shoulders."""
    d = (dist / width) ** 2
    return -np.exp(-0.5 * d) + 0.25 * np.exp(-0.125 * d)


def _ends(t: Array, t0: float, t1: float, fade: float) -> Array:
    """1 between t0 and t1, tapering to 0 over ``fade`` at both ends (wrinkle tips)."""
    return smoothstep(t0, t0 + fade, t) * smoothstep(t1, t1 - fade, t)


def _forehead(x: Array, y: Array) -> Array:
    h = np.zeros_like(x)
    lines = [(0.355, 0.30, 0.8), (0.415, 0.38, 1.0), (0.475, 0.41, 1.0), (0.535, 0.40, 0.9),
             (0.595, 0.36, 0.7), (0.65, 0.28, 0.45)]
    for k, (y0, reach, depth) in enumerate(lines):
        centre = y0 + 0.018 * (x / 0.4) ** 2 + 0.007 * np.sin(6.0 * x + 1.7 * k)
        along = _ends(x, -reach, reach, 0.12)
        gap = 1.0 - 0.85 * np.exp(-0.5 * ((x - 0.08 * math.sin(2.3 * k)) / 0.02) ** 2) * (k % 2)
        swell = 0.75 + 0.25 * np.cos(9.0 * x + 2.1 * k)
        h += depth * along * gap * swell * _crease(y - centre, 0.006)
    return 0.009 * h


def _between_brows(x: Array, y: Array) -> Array:
    h = np.zeros_like(x)
    for side in (-1.0, 1.0):
        for offset, depth, top in ((0.032, 1.0, 0.33), (0.07, 0.55, 0.30)):
            centre = side * (offset + 0.13 * (y - 0.15))
            h += depth * _ends(y, 0.13, top, 0.05) * _crease(x - centre, 0.006)
    return 0.009 * h


def _crows_feet(x: Array, y: Array) -> Array:
    h = np.zeros_like(x)
    for side in (-1.0, 1.0):
        dx = side * (x - side * CANTHUS_X)  # outward from the eye
        dy = y - (EYE_Y - 0.005)
        r = np.hypot(dx, dy)
        phi = np.arctan2(dy, dx)
        for k, (deg, length, depth) in enumerate(
            ((-50, 0.11, 0.6), (-35, 0.15, 0.9), (-20, 0.17, 1.0), (-6, 0.16, 1.0),
             (8, 0.17, 1.0), (21, 0.15, 0.9), (34, 0.12, 0.7), (47, 0.09, 0.5))
        ):
            bend = (0.8 + 0.15 * (k % 3)) * (r - 0.05) * np.sign(deg + 0.5)
            angle = math.radians(deg) + bend
            dist = r * np.sin(phi - angle)
            along = _ends(r, 0.015 + 0.006 * (k % 2), 0.015 + length, 0.05)
            width = 0.005 + 0.03 * r  # lines broaden away from the eye
            h += depth * along * (np.cos(phi - angle) > 0) * _crease(dist, width)
    return 0.015 * h


def _under_eyes(x: Array, y: Array) -> Array:
    h = np.zeros_like(x)
    for side in (-1.0, 1.0):
        dx = side * x - EYE_X - 0.015
        for k, (drop, reach, depth) in enumerate(((0.05, 0.09, 1.0), (0.075, 0.10, 0.8),
                                                  (0.10, 0.09, 0.5))):
            centre = EYE_Y - drop + (1.6 - 0.3 * k) * dx ** 2
            h += depth * _ends(dx, -reach, reach + 0.02, 0.05) * _crease(y - centre, 0.0055)
    return 0.006 * h


def _cheeks(x: Array, y: Array) -> Array:
    h = np.zeros_like(x)
    ax = np.abs(x)
    # nasolabial fold: from beside the nose wing to past the mouth corner
    t = (-0.19 - y) / 0.30
    centre = 0.115 + 0.12 * t + 0.025 * np.sin(np.pi * np.clip(t, 0.0, 1.0))
    h += 1.6 * _ends(t, 0.0, 1.0, 0.25) * _crease(ax - centre, 0.009)
    # smile lines fanning down the upper cheek, below the crow's feet
    for k, (x0, slope, depth) in enumerate(((0.40, 0.55, 0.7), (0.43, 0.45, 0.55),
                                            (0.355, 0.7, 0.45))):
        yy = y + 0.02 * k
        centre = x0 - slope * (-yy - 0.0)
        h += depth * _ends(y, -0.19 + 0.03 * k, -0.02 - 0.02 * k, 0.05) * _crease(
            ax - centre, 0.005)
    return 0.007 * h


BROW_MAP = "brow"  # forehead and frown lines: what raising or knitting the brows folds
EYE_MAP = "eyes and cheeks"  # crow's feet, under the eyes, cheek lines: what a squint folds

WRINKLE_GROUPS = (  # (painter, x0, x1, y0, y1, wrinkled map)
    (_forehead, -0.55, 0.55, 0.28, 0.72, BROW_MAP),
    (_between_brows, -0.14, 0.14, 0.10, 0.36, BROW_MAP),
    (_crows_feet, -0.62, 0.62, -0.10, 0.24, EYE_MAP),
    (_under_eyes, -0.45, 0.45, -0.10, 0.09, EYE_MAP),
    (_cheeks, -0.50, 0.50, -0.56, 0.02, EYE_MAP),
)


def wrinkle_height(tx: Texels, wrinkle_map: str | None = None) -> Array:
    """Height (model units) of the wrinkles of one wrinkled map (None: all of them); 0 away
    from them."""
    h = np.zeros((tx.size, tx.size), dtype=np.float32)
    for painter, x0, x1, y0, y1, group_map in WRINKLE_GROUPS:
        if wrinkle_map not in (None, group_map):
            continue
        rows, cols = tx.window(x0, x1, y0, y1)
        xs, ys = tx.x[rows, cols], tx.y[rows, cols]
        h[rows, cols] += painter(xs, ys) * tx.front[rows, cols]
    return h


def pore_height(size: int) -> Array:
    """Fine skin grain, shared by both maps so the wrinkled map differs only by wrinkles."""
    rng = np.random.default_rng(SEED + 1)
    noise = rng.standard_normal((size + 2, size + 2), dtype=np.float32)
    blurred = (noise[:-2, 1:-1] + noise[2:, 1:-1] + noise[1:-1, :-2] + noise[1:-1, 2:]
               + 2.0 * noise[1:-1, 1:-1]) / 6.0
    return PORE_DEPTH * blurred


def bake_normal_maps(tx: Texels) -> tuple[Array, dict[str, Array]]:
    """Neutral (pores only) normal map, and one wrinkled (pores + its wrinkles) normal map per
    wrinkled-map name: the sample shows off several maps."""
    du, dv = tx.texel_size(0.0, 0.3)
    strength = (WRINKLE_SLOPE / (2.0 * du), WRINKLE_SLOPE / (2.0 * dv))
    pores = pore_height(tx.size)
    neutral = height_to_normal(pores, strength)
    wrinkled = {name: height_to_normal(pores + wrinkle_height(tx, name), strength)
                for name in (BROW_MAP, EYE_MAP)}
    return neutral, wrinkled


# --- technique 1 masks ------------------------------------------------------------------------

def _soft_ellipse(x: Array, y: Array, cx: float, cy: float, rx: float, ry: float) -> Array:
    """1 inside 60 % of the ellipse, fading smoothly to 0 at its rim (soft like Fig. 4.5)."""
    r = np.hypot((x - cx) / rx, (y - cy) / ry)
    return smoothstep(1.0, 0.6, r)


def paint_masks(tx: Texels) -> dict[str, Array]:
    x, y, front = tx.x, tx.y, tx.front
    forehead = (smoothstep(0.64, 0.44, np.abs(x)) * smoothstep(0.25, 0.34, y)
                * smoothstep(0.80, 0.67, y))
    right = smoothstep(0.05, -0.05, x)
    masks = {
        "forehead right": forehead * right,
        "forehead left": forehead * (1.0 - right),
        "between brows": _soft_ellipse(x, y, 0.0, 0.225, 0.15, 0.15),
        "eye corner right": _soft_ellipse(x, y, -(CORNER_X + 0.02), CORNER_Y, 0.15, 0.18),
        "eye corner left": _soft_ellipse(x, y, CORNER_X + 0.02, CORNER_Y, 0.15, 0.18),
        "under eye right": _soft_ellipse(x, y, -(EYE_X + 0.02), EYE_Y - 0.075, 0.17, 0.10),
        "under eye left": _soft_ellipse(x, y, EYE_X + 0.02, EYE_Y - 0.075, 0.17, 0.10),
        "cheeks": np.maximum(_soft_ellipse(np.abs(x), y, 0.22, -0.33, 0.16, 0.26),
                             _soft_ellipse(np.abs(x), y, 0.39, -0.10, 0.12, 0.14)),
    }
    return {name: np.clip(m * front, 0.0, 1.0).astype(np.float32) for name, m in masks.items()}

