"""The face mesh: triangles over render vertices that are split where UVs differ.

A vertex on a UV seam appears once per UV chart (a *render vertex*) but has one *welded* position.
Positions, poses and normals live on welded vertices, so seams never crease the shading; UVs and
tangents live on render vertices. ``weld`` maps each render vertex to its welded position.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from studio.core.animation.poses import coordinate_problem
from studio.core.files.errors import MeshError

Array = np.ndarray


@dataclass(eq=False)
class FaceMesh:
    """Neutral-pose geometry. Triangles are counter-clockwise seen from outside."""

    rest: Array  # (W, 3) float32 welded positions of the neutral pose
    triangles: Array  # (F, 3) int32 indices into render vertices
    uvs: Array  # (V, 2) float32, one per render vertex
    weld: Array  # (V,) int32, render vertex -> welded position
    source: str = field(default="")  # file it came from, for messages

    def __post_init__(self) -> None:
        self.rest = np.ascontiguousarray(self.rest, dtype=np.float32)
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.int32)
        self.uvs = np.ascontiguousarray(self.uvs, dtype=np.float32)
        self.weld = np.ascontiguousarray(self.weld, dtype=np.int32)
        self._validate()

    def _validate(self) -> None:
        where = self.source or None
        if self.rest.ndim != 2 or self.rest.shape[1] != 3 or len(self.rest) == 0:
            raise MeshError("the mesh has no vertices", where)
        if self.triangles.ndim != 2 or self.triangles.shape[1] != 3 or len(self.triangles) == 0:
            raise MeshError("the mesh has no faces", where)
        if self.uvs.shape != (len(self.weld), 2):
            raise MeshError("the mesh has no texture coordinates (UVs) for every vertex", where)
        if not np.isfinite(self.rest).all():
            raise MeshError("the mesh has non-finite vertex coordinates (NaN or infinity)", where)
        problem = coordinate_problem(self.rest, "the mesh")
        if problem:
            raise MeshError(problem, where)
        if not np.isfinite(self.uvs).all():
            raise MeshError("the mesh has non-finite texture coordinates", where)
        if self.triangles.min() < 0 or self.triangles.max() >= len(self.weld):
            raise MeshError("a face refers to a vertex that does not exist", where)
        if self.weld.min() < 0 or self.weld.max() >= len(self.rest):
            raise MeshError("a texture vertex refers to a position that does not exist", where)

    @property
    def n_welded(self) -> int:
        return len(self.rest)

    @property
    def n_vertices(self) -> int:
        """Number of render vertices (after splitting at UV seams)."""
        return len(self.weld)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @cached_property
    def welded_triangles(self) -> Array:
        """Triangles over welded positions: what normals and poses are computed on."""
        return self.weld[self.triangles]

    def bounds(self) -> tuple[Array, Array]:
        return self.rest.min(axis=0), self.rest.max(axis=0)
