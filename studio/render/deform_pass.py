"""The deform pass: this frame's pose → normals and tangents → the GPU's interleaved buffer.

Only the render vertices the pose moved are written (DeformCache keeps the span), and nothing
at all when the positions did not change since the last draw.
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from studio.core.mesh.draw_split import moved
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache
from studio.core.wrinkles.strain import StrainField

ATTRIBUTES = "3f 3f 4f"  # position, normal, tangent (w: handedness) per render vertex
NAMES = ("in_position", "in_normal", "in_tangent")


class DeformPass:
    """Welded positions of the current pose, and their upload as vertex attributes: the numpy
    reference path (gpu_deform.GpuDeformPass does the same on the GPU)."""

    def __init__(self, ctx: moderngl.Context, mesh: FaceMesh) -> None:
        self.mesh = mesh
        self._cache = DeformCache(mesh)
        self.buffer = ctx.buffer(reserve=mesh.n_vertices * 10 * 4, dynamic=True)
        self.positions = mesh.rest.copy()
        self.version = 0  # counts pose changes: what per-pose caches of other passes key on
        self.dirty = True
        self.last_ms = 0.0  # CPU time of the last normals + tangents update
        self._strain_field: StrainField | None = None  # the strain mode's edges (on first use)

    @property
    def frame(self) -> str:
        """The tangent frame the vertex buffer holds (set by ``upload``)."""
        return self._cache.frame

    def set_positions(self, welded_positions: np.ndarray) -> None:
        np.copyto(self.positions, welded_positions)
        self.dirty = True
        self.version += 1

    def upload(self, tangent_frame: str) -> None:
        """Normals and tangents for the new pose (tangents in ``tangent_frame``), written where
        the pose moved the face; all of them again when the frame changes."""
        if tangent_frame != self._cache.frame:
            self._cache.set_frame(tangent_frame)
            self.dirty = True
        if not self.dirty:
            return
        start = time.perf_counter()
        attributes = self._cache.update(self.positions)
        self.last_ms = (time.perf_counter() - start) * 1000.0
        lo, hi = self._cache.last_span
        if hi > lo:
            self.buffer.write(attributes[lo:hi], offset=lo * attributes.strides[0])
        self.dirty = False

    @property
    def motion_key(self) -> object:
        """Changes whenever the vertices that moved may have: every pose change."""
        return self.version

    def moved_welded(self) -> np.ndarray:
        """(W,) bool: the vertices away from the neutral pose."""
        return moved(self.positions, self.mesh.rest)

    def write_strain(self, target: moderngl.Buffer, full_at: float) -> tuple[object, np.ndarray]:
        """The strain weights of this pose into ``target`` (per render vertex); returns the
        key they hold for and the weights, for the split draw."""
        if self._strain_field is None:
            self._strain_field = StrainField(self.mesh)
        weights = self._strain_field.weights(self.positions, full_at)
        render = weights[self.mesh.weld].astype("f4")
        target.write(render.tobytes())
        return (self.version, full_at), render

    def release(self) -> None:
        self.buffer.release()
