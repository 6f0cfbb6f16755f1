"""Texture coordinates for a face that came without any, made by xatlas.

Everything the studio paints, masks and bakes lives in UV space, so a mesh without UVs used to
be refused. xatlas (the unwrapper Blender's and Godot's lightmappers use, PyPI ``xatlas``) cuts
the surface into charts along creases and packs them into the unit square with little stretch:
what a UV unwrap by hand would give, and better than any projection of our own (a planar or
cylindrical one folds the nostrils, lips and ears onto themselves). The welded positions keep
their order, so key poses read against the file's vertices still fit; only render vertices are
added where a chart's border splits a vertex.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh

Array = np.ndarray


@dataclass(frozen=True)
class Unwrapped:
    mesh: FaceMesh
    charts: int

    def report(self, path: object) -> str:
        """The one line a user reads: what was missing and what was done about it."""
        return f"no UVs in {path}: made them with xatlas, {self.charts} charts"


def unwrap(rest: Array, triangles: Array, source: str = "") -> Unwrapped:
    """A FaceMesh over welded ``rest`` and ``triangles`` (indices into ``rest``) with UVs made
    by xatlas; its ``weld`` maps each new render vertex to the welded position it came from."""
    try:
        import xatlas
    except ImportError as exc:  # pragma: no cover - xatlas is a dependency
        raise MeshError("the mesh has no texture coordinates (UVs), and xatlas, which makes "
                        "them, is not installed", source or None) from exc
    positions = np.ascontiguousarray(rest, np.float32)
    indices = np.ascontiguousarray(triangles, np.uint32)
    atlas = xatlas.Atlas()
    atlas.add_mesh(positions, indices)
    atlas.generate()
    vmapping, faces, uvs = atlas[0]
    mesh = FaceMesh(rest=positions, triangles=faces, uvs=uvs, weld=vmapping, source=source)
    return Unwrapped(mesh, int(atlas.chart_count))
