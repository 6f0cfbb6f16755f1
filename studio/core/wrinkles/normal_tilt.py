"""How steeply a wrinkled map's furrows tilt the skin: the figure skin itself bounds.

Expression lines are 0.1–1 mm deep and 0.5–2 mm wide, which tilts the normal by at most about
35° at a furrow's wall, mostly under 25° (``../shared/LOOK.md``); a map whose walls tilt 60°
and more reads as carved. The tilt is the angle between a wrinkled map's normal and the
neutral map's at the same texel, over the texels where they differ at all — so a head's own
detail (pores, a painted normal map), which both maps share, does not count.
"""

from __future__ import annotations

import numpy as np

from studio.core.files.images import to_unit_float
from studio.core.wrinkles.textures import resize_nearest

Array = np.ndarray


def decode_normals(image: Array) -> Array:
    """(H, W, 3) unit normals from an encoded tangent-space map (any integer depth)."""
    n = to_unit_float(np.asarray(image)[..., :3]).astype(np.float32) * 2.0 - 1.0
    return n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-6)


def tilt_degrees(wrinkled: Array, neutral: Array) -> tuple[Array, Array]:
    """(H, W) degrees between the two maps' normals, and (H, W) bool: where they differ by
    more than one step of the wrinkled map's encoding in any channel."""
    if neutral.shape[:2] != wrinkled.shape[:2]:
        neutral = resize_nearest(neutral, *wrinkled.shape[:2])
    a, b = decode_normals(wrinkled), decode_normals(neutral)
    cos = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)
    step = 1.5 / np.iinfo(wrinkled.dtype).max if np.issubdtype(wrinkled.dtype, np.integer) \
        else 1.5 / 255.0
    differs = np.any(np.abs(to_unit_float(wrinkled[..., :3])
                            - to_unit_float(neutral[..., :3])) > step, axis=-1)
    return np.degrees(np.arccos(cos)), differs


def furrow_tilt(wrinkled: Array, neutral: Array) -> tuple[float, float, float]:
    """(p90, p99, max) of the tilt in degrees over the texels the furrows change; zeros for
    a map equal to the neutral."""
    degrees, differs = tilt_degrees(wrinkled, neutral)
    values = degrees[differs]
    if values.size == 0:
        return 0.0, 0.0, 0.0
    p90, p99 = np.percentile(values, [90, 99])
    return float(p90), float(p99), float(values.max())
