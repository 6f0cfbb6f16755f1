"""The sparse technique-1 masks equal the straightforward sum where at most K areas overlap."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.mask_sparse import K, composed_weight, quantise, sparse_masks

pytestmark = pytest.mark.core


def direct_sum(masks, activations):
    q = quantise(masks).astype(np.float32) / 255.0
    return np.clip(np.tensordot(activations, q, axes=1), 0.0, 1.0)


def test_few_areas_are_exact():
    rng = np.random.default_rng(1)
    masks = rng.random((3, 8, 5)).astype(np.float32)
    act = np.array([0.2, 1.0, 0.5], np.float32)
    sparse = sparse_masks(masks)
    assert sparse.dropped_weight == 0.0
    np.testing.assert_allclose(composed_weight(sparse, act), direct_sum(masks, act), atol=1e-6)


def test_many_areas_with_little_overlap_are_exact():
    n, h, w = 40, 16, 20
    masks = np.zeros((n, h, w), np.float32)
    for i in range(n):  # each area covers a few texels, at most K overlap anywhere
        masks[i, (i * 3) % h: (i * 3) % h + 2, (i * 7) % w: (i * 7) % w + 3] = (i + 1) / n
    assert (masks > 0).sum(axis=0).max() <= K
    act = np.linspace(0.0, 1.0, n).astype(np.float32)
    sparse = sparse_masks(masks)
    np.testing.assert_allclose(composed_weight(sparse, act), direct_sum(masks, act), atol=1e-6)


def test_overlap_beyond_k_keeps_the_strongest_and_reports_the_loss():
    masks = np.zeros((6, 1, 1), np.float32)
    masks[:, 0, 0] = [0.1, 0.9, 0.3, 0.8, 0.2, 0.7]
    sparse = sparse_masks(masks)
    assert sorted(sparse.indices[0, 0].tolist()) == [1, 2, 3, 5]
    assert abs(sparse.dropped_weight - round(0.2 * 255) / 255) < 1e-9
