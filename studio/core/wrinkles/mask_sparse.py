"""Technique 1 with a per-pixel cost independent of the number of areas.

Only a few influence areas overlap at any texel, so each texel keeps the ``K`` strongest areas
(index and mask value), built once when the masks change. Each frame the renderer composes
``s = Σ_k weight_k · activation[index_k]`` into one weight texture; the face shader then reads a
single texel. The result equals the straightforward sum wherever at most ``K`` areas overlap;
elsewhere the weakest contributions are dropped (``dropped_weight`` says how much).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

K = 4
ROWS_PER_CHUNK = 64  # bounds the temporary memory for hundreds of areas


@dataclass
class SparseMasks:
    indices: np.ndarray  # (H, W, K) uint16 area index per slot
    weights: np.ndarray  # (H, W, K) uint8 mask value per slot (0 = unused)
    dropped_weight: float  # the largest mask value that did not fit in K slots


def quantise(masks: np.ndarray) -> np.ndarray:
    """Masks as the GPU stores them: 8 bits, rounded (already-quantised masks pass through)."""
    if masks.dtype == np.uint8:
        return masks
    scaled = np.multiply(masks, np.float32(255.0), dtype=np.float32)  # one temporary, in place
    np.clip(scaled, 0.0, 255.0, out=scaled)  # after: the same rounding as clip-then-scale
    np.rint(scaled, out=scaled)
    return scaled.astype(np.uint8)


def sparse_masks(masks: np.ndarray) -> SparseMasks:
    """The ``K`` strongest areas per texel of an (N, H, W) stack (floats in [0, 1] or uint8)."""
    n, h, w = masks.shape
    indices = np.zeros((h, w, K), np.uint16)
    weights = np.zeros((h, w, K), np.uint8)
    dropped = 0
    for r0 in range(0, h, ROWS_PER_CHUNK):
        chunk = quantise(masks[:, r0:r0 + ROWS_PER_CHUNK])  # (N, rows, W)
        if n <= K:
            top = np.broadcast_to(np.arange(n)[:, None, None], chunk.shape)
        else:
            top = np.argpartition(chunk, n - K, axis=0)[n - K:]
            rest = np.partition(chunk, n - K - 1, axis=0)[n - K - 1]
            dropped = max(dropped, int(rest.max()))
        values = np.take_along_axis(chunk, top, axis=0)
        slots = min(n, K)
        indices[r0:r0 + ROWS_PER_CHUNK, :, :slots] = np.moveaxis(top, 0, -1)
        weights[r0:r0 + ROWS_PER_CHUNK, :, :slots] = np.moveaxis(values, 0, -1)
    return SparseMasks(indices, weights, dropped / 255.0)


def composed_weight(sparse: SparseMasks, activations: np.ndarray) -> np.ndarray:
    """What the GPU's compose pass computes when every area reveals the first map: (H, W)."""
    return composed_weights(sparse, activations, np.zeros(len(activations), np.int64))[..., 0]


def composed_weights(sparse: SparseMasks, activations: np.ndarray, area_maps: np.ndarray
                     ) -> np.ndarray:
    """The numpy reference of shaders/t1_compose.frag: (H, W, 4), per wrinkled map m,
    ``clamp(Σ_k weight_k · activation[index_k] [map of index_k = m], 0, 1)``."""
    act = np.asarray(activations, np.float32)
    maps = np.asarray(area_maps, np.int64)
    values = sparse.weights.astype(np.float32) / 255.0 * act[sparse.indices]
    out = np.zeros((*values.shape[:2], 4), np.float32)
    for m in range(4):
        out[..., m] = np.where(maps[sparse.indices] == m, values, 0.0).sum(axis=-1)
    return np.clip(out, 0.0, 1.0)
