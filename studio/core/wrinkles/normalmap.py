"""Height maps to tangent-space normal maps, and green-channel flipping.

Images follow the project's convention: row 0 is the top of the UV square (v = 1), normals are
OpenGL-style (+X toward +u, +Y / green toward +v, i.e. *up* the image). So a surface rising toward
+u tilts its normal toward −X, and one rising toward +v (toward row 0) tilts it toward −Y.
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray


def height_to_normal(
    height: Array, strength: float | tuple[float, float] = 1.0, *, bits: int = 8,
    max_tilt: float | None = None,
) -> Array:
    """Central-difference bump-to-normal conversion of a height map [3.2].

    ``gx = h(x−1) − h(x+1)`` along columns (u) and ``gy = h(v−1) − h(v+1)`` along v, where "v−1"
    is the texel *below* (the next image row, since row 0 is the top); ``n = normalize(gx·s,
    gy·s, 1)``, encoded as ``(n·0.5 + 0.5)·max``. Edges are clamped (the border texel is
    repeated). ``strength`` may be a pair ``(s_u, s_v)`` for maps whose texels are not square
    on the surface. ``max_tilt`` (degrees) eases slopes toward that tilt and never past it
    (``|g| → S·tanh(|g|/S)``, S = tan(max_tilt)): gentle slopes keep their shape, cliffs
    where deep furrows add up become walls skin could have. Returns (H, W, 3) uint8, or
    uint16 with ``bits=16``.
    """
    if bits not in (8, 16):
        raise ValueError(f"bits must be 8 or 16, got {bits}")
    h = np.asarray(height, dtype=np.float32)
    if h.ndim != 2 or min(h.shape) < 1:
        raise ValueError(f"a height map must be a 2-D array, got shape {h.shape}")
    p = np.pad(h, 1, mode="edge")
    su, sv = (strength, strength) if np.isscalar(strength) else strength
    gx = (p[1:-1, :-2] - p[1:-1, 2:]) * np.float32(su)
    gy = (p[2:, 1:-1] - p[:-2, 1:-1]) * np.float32(sv)  # below minus above: rising toward +v → −y
    if max_tilt is not None:
        limit = np.float32(np.tan(np.radians(max_tilt)))
        slope = np.sqrt(gx * gx + gy * gy)
        ease = np.where(slope > 0, limit * np.tanh(slope / limit) / np.maximum(slope, 1e-12),
                        1.0).astype(np.float32)
        gx, gy = gx * ease, gy * ease
    inv = 1.0 / np.sqrt(gx * gx + gy * gy + 1.0)
    top = 255 if bits == 8 else 65535
    out = np.empty((*h.shape, 3), dtype=np.uint8 if bits == 8 else np.uint16)
    for channel, value in enumerate((gx * inv, gy * inv, inv)):
        out[..., channel] = np.clip(np.floor((value * 0.5 + 0.5) * top + 0.5), 0, top)
    return out


def flip_green(image: Array) -> Array:
    """Convert between DirectX (−Y) and OpenGL (+Y) normal maps by inverting green.

    Integer images are inverted against their type's maximum; float images are taken as
    encoded in [0, 1]. Returns a new array; the input is left alone.
    """
    img = np.array(image, copy=True)
    if img.ndim != 3 or img.shape[2] < 3:
        raise ValueError(f"a normal map must be an (H, W, 3+) image, got shape {img.shape}")
    if np.issubdtype(img.dtype, np.integer):
        img[..., 1] = np.iinfo(img.dtype).max - img[..., 1]
    else:
        img[..., 1] = 1.0 - img[..., 1]
    return img
