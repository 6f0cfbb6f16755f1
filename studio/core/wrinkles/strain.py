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
        self._a = np.ascontiguousarray(self.edges[:, 0])
        self._b = np.ascontiguousarray(self.edges[:, 1])
        # the same sums as every frame's, so an edge that did not move is exactly as long
        self.rest_lengths = self._lengths(mesh.rest)
        self.n_welded = mesh.n_welded
        ends = self.edges.ravel()
        self._ends = ends
        self._degree = np.maximum(np.bincount(ends, minlength=self.n_welded), 1).astype(np.float32)
        self._usable = self.rest_lengths > 0

    def compression(self, positions: Array) -> Array:
        """Mean edge compression per welded vertex, (W,) in [0, 1].

        On component rows (a ``take`` per axis, squares summed in place): it runs every frame
        the strain mode shows a moving face, where row gathers and norms along a short axis
        cost several times as much."""
        lengths = self._lengths(positions)
        ratio = np.divide(lengths, self.rest_lengths, out=np.ones_like(lengths),
                          where=self._usable)
        per_edge = np.clip(1.0 - ratio, 0.0, 1.0).astype(np.float32)
        total = np.bincount(self._ends, weights=np.repeat(per_edge, 2), minlength=self.n_welded)
        return (total / self._degree).astype(np.float32)

    def _lengths(self, positions: Array) -> Array:
        """(E,) float32 edge lengths, summed per axis in one order for rest and pose alike."""
        rows = np.ascontiguousarray(np.asarray(positions).T, dtype=np.float32)
        squared = np.zeros(len(self._a), np.float32)
        for row in rows:
            step = np.take(row, self._a)
            step -= np.take(row, self._b)
            step *= step
            squared += step
        return np.sqrt(squared)

    def weights(self, positions: Array, full_at: float = DEFAULT_FULL_AT) -> Array:
        """Wrinkle weight per welded vertex: compression / ``full_at``, clamped to [0, 1]."""
        return np.clip(self.compression(positions) / max(full_at, 1e-6), 0.0, 1.0)
