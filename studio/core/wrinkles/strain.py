"""Automatic wrinkles: skin compression measured each frame, no authoring needed.

Each edge's compression is ``max(0, 1 − length / rest length)``; a vertex takes the mean over its
edges, and the wrinkle weight is that compression times a gain (``gain = 1 / compression at
which wrinkles are fully visible``), clamped to [0, 1]. Stretching shows nothing.
"""

from __future__ import annotations

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh

Array = np.ndarray
DEFAULT_FULL_AT = 0.12  # 12 % compression shows the wrinkles fully


class StrainField:
    """Per-vertex compression against the neutral pose, with the edges prepared once."""

    def __init__(self, mesh: FaceMesh) -> None:
        tri = mesh.welded_triangles
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        edges.sort(axis=1)
        self.edges = np.unique(edges, axis=0)
        self.edges = self.edges[self.edges[:, 0] != self.edges[:, 1]]
        rest = mesh.rest
        self.rest_lengths = np.linalg.norm(rest[self.edges[:, 0]] - rest[self.edges[:, 1]],
                                           axis=1).astype(np.float32)
        self.n_welded = mesh.n_welded
        ends = self.edges.ravel()
        self._ends = ends
        self._degree = np.maximum(np.bincount(ends, minlength=self.n_welded), 1).astype(np.float32)
        self._usable = self.rest_lengths > 0

    def compression(self, positions: Array) -> Array:
        """Mean edge compression per welded vertex, (W,) in [0, 1]."""
        a, b = self.edges[:, 0], self.edges[:, 1]
        lengths = np.linalg.norm(positions[a] - positions[b], axis=1)
        ratio = np.divide(lengths, self.rest_lengths, out=np.ones_like(lengths),
                          where=self._usable)
        per_edge = np.clip(1.0 - ratio, 0.0, 1.0).astype(np.float32)
        total = np.bincount(self._ends, weights=np.repeat(per_edge, 2), minlength=self.n_welded)
        return (total / self._degree).astype(np.float32)

    def weights(self, positions: Array, full_at: float = DEFAULT_FULL_AT) -> Array:
        """Wrinkle weight per welded vertex: compression / ``full_at``, clamped to [0, 1]."""
        return np.clip(self.compression(positions) / max(full_at, 1e-6), 0.0, 1.0)
