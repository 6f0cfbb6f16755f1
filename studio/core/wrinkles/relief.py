"""Wrinkle height from normal maps, for relief rendering.

A tangent-space normal map stores the surface's slopes, not its height; displacement and parallax
need the height. Each map's slopes are integrated with the Frankot–Chellappa method (the
least-squares surface whose gradient is nearest the slopes, solved in the Fourier domain). The
image is mirrored to twice its size where slopes reach its border, so the FFT's periodic wrap sees
no jump there.

A wrinkle's height is height(wrinkled map) − height(neutral map): integration is linear, so this
integrates the *difference* of the slopes once per wrinkled map. Pores and anything else both maps
share cancel exactly; the level of the unwrinkled skin is set to 0 (the median where the slopes
agree), valleys are negative, and all maps are scaled together so the deepest wrinkle of any map
has |h| = 1 (a renderer multiplies by a depth in model units).

Conventions are those of ``normalmap.py``: row 0 is the top (v = 1), +X toward +u, +Y (green)
toward +v, so ``dh/du = −nx/nz`` and ``dh/dv = −ny/nz`` (in texels).
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence

import numpy as np

from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS, resize_nearest

Array = np.ndarray

# model units of the deepest wrinkle, for the sample face (about 2 units tall): about the depth
# its wrinkled normal map's own slopes integrate to (0.02), deepened a little to read in profile
DEFAULT_RELIEF_DEPTH = 0.03
RELIEF_DEPTH_PER_SIZE = 0.014  # the same, as a fraction of a face's largest extent
MAX_RELIEF_SIZE = 2048  # texels: larger maps give heights at a fraction of their size
MIN_NZ = 0.05  # slopes of normals tilted further than this are clamped (about 87°)


def suggested_relief_depth(lo: Array, hi: Array) -> float:
    """A relief depth for a face with these bounds, whatever its units (metres, centimetres):
    the sample's depth scaled to its size, to two significant digits."""
    size = float(np.max(np.asarray(hi, float) - np.asarray(lo, float)))
    return float(f"{RELIEF_DEPTH_PER_SIZE * size:.2g}") if size > 0 else DEFAULT_RELIEF_DEPTH


def normal_slopes(normal_map: Array) -> tuple[Array, Array]:
    """Slopes of an encoded tangent-space normal map, in height per texel along image columns
    (x, to the right) and image rows (y, downward): ``(−nx/nz, +ny/nz)``, since +v is up."""
    image = np.asarray(normal_map)
    if np.issubdtype(image.dtype, np.integer):  # 128 (32768) is 0: a flat map has no slope
        half = (int(np.iinfo(image.dtype).max) + 1) // 2
        n = (image[..., :3].astype(np.float32) - np.float32(half)) / np.float32(half - 1)
    else:  # floats encoded in [0, 1]
        n = image[..., :3].astype(np.float32) * np.float32(2.0) - np.float32(1.0)
    nz = np.maximum(n[..., 2], np.float32(MIN_NZ))
    return -n[..., 0] / nz, n[..., 1] / nz


def integrate_slopes(p: Array, q: Array) -> Array:
    """Frankot–Chellappa: the height whose gradient (d/dx along columns, d/dy along rows) is
    nearest ``(p, q)`` in the least-squares sense; its mean is 0.

    The FFT treats the image as periodic. Where slopes reach the border, the field is mirrored
    first (even height reflection: x-slopes flip sign in the reflected columns, y-slopes in the
    reflected rows) so that the doubled field is periodic and continuous; wrinkle differences
    usually vanish at the border and are solved at their own size (four times faster).
    """
    p = np.asarray(p, np.float64)
    q = np.asarray(q, np.float64)
    h, w = p.shape
    border = np.concatenate([p[0], p[-1], p[:, 0], p[:, -1], q[0], q[-1], q[:, 0], q[:, -1]])
    if border.any():
        px = np.concatenate([p, -p[:, ::-1]], axis=1)
        qx = np.concatenate([q, q[:, ::-1]], axis=1)
        p = np.concatenate([px, px[::-1]], axis=0)
        q = np.concatenate([qx, -qx[::-1]], axis=0)
    rows, cols = p.shape
    wx = 2.0 * np.pi * np.fft.rfftfreq(cols)[None, :]
    wy = 2.0 * np.pi * np.fft.fftfreq(rows)[:, None]
    denom = wx * wx + wy * wy
    denom[0, 0] = 1.0  # the mean: free, set to 0 below
    spectrum = np.fft.rfft2(p) * (-1j * wx)
    spectrum -= np.fft.rfft2(q) * (1j * wy)
    spectrum /= denom
    spectrum[0, 0] = 0.0
    return np.fft.irfft2(spectrum, s=(rows, cols))[:h, :w].astype(np.float32)


def height_from_normals(normal_map: Array) -> Array:
    """(H, W) height of a normal map's surface in texel units, mean 0 (up to a constant)."""
    return integrate_slopes(*normal_slopes(normal_map))


def _block_mean(a: Array, k: int) -> Array:
    """Mean over k×k blocks (the last row and column of blocks repeat the edge texels)."""
    if k == 1:
        return a
    rows, cols = -(-a.shape[0] // k), -(-a.shape[1] // k)
    a = np.pad(a, ((0, rows * k - a.shape[0]), (0, cols * k - a.shape[1])), mode="edge")
    return a.reshape(rows, k, cols, k).mean(axis=(1, 3))


def wrinkle_heights(neutral: Array, wrinkled: Sequence[Array],
                    max_size: int = MAX_RELIEF_SIZE) -> Array:
    """(N, H, W) wrinkle height of each wrinkled map against the neutral map (maps of other
    sizes are resized to the largest, nearest texel, as the renderer packs them).

    0 where a map has no wrinkle, valleys negative; scaled together so max |h| over all maps
    is 1 (all zero when no map differs from the neutral one). Maps larger than ``max_size``
    give heights at a whole fraction of their size (the slopes averaged over blocks of
    texels, which keeps every wrinkle): relief needs no finer steps, and the integration's
    time grows with the area.
    """
    images = [np.asarray(neutral), *map(np.asarray, wrinkled)]
    rows = max(i.shape[0] for i in images)
    cols = max(i.shape[1] for i in images)
    sized = [resize_nearest(i, rows, cols) if i.shape[:2] != (rows, cols) else i for i in images]
    k = max(-(-max(rows, cols) // max_size), 1)
    p0, q0 = (_block_mean(a, k) for a in normal_slopes(sized[0]))
    heights = np.zeros((len(wrinkled), *p0.shape), np.float32)
    for m, image in enumerate(sized[1:]):
        p, q = (_block_mean(a, k) for a in normal_slopes(image))
        dp, dq = p - p0, q - q0
        unchanged = (dp == 0.0) & (dq == 0.0)
        if unchanged.all():
            continue
        height = integrate_slopes(dp, dq)
        # the unwrinkled skin is where the slopes agree; its level is 0
        height -= np.median(height[unchanged]) if unchanged.any() else np.median(height)
        heights[m] = height
    peak = float(np.abs(heights).max(initial=0.0))
    if peak > 0.0:
        heights /= peak
    return heights


def relief_image(neutral: Array, wrinkled: Sequence[Array]) -> Array:
    """(H, W, 4) float16: wrinkled map m's height in channel m (unused channels 0), the
    texture a shader dots with its per-map weights to get the wrinkle height at a texel."""
    if len(wrinkled) > MAX_WRINKLE_MAPS:
        raise ValueError(f"at most {MAX_WRINKLE_MAPS} wrinkled maps fit one relief image")
    heights = wrinkle_heights(neutral, wrinkled)
    n, h, w = heights.shape
    image = np.zeros((h, w, 4), np.float16)
    image[..., :n] = np.moveaxis(heights, 0, -1)
    return image


def maps_digest(neutral: Array, wrinkled: Sequence[Array]) -> bytes:
    """A short fingerprint of the maps a relief image is made from (to skip remaking it)."""
    digest = hashlib.blake2b(digest_size=16)
    for image in (neutral, *wrinkled):
        image = np.ascontiguousarray(image)
        digest.update(repr((image.shape, image.dtype.str)).encode())
        digest.update(image.data)
    return digest.digest()
