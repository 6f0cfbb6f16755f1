"""Polygon meshes as the glTF path's triangle primitives, for the formats that store polygons.

FBX and USD both give a mesh as polygons of any size over a list of points, a UV per corner
through an index (so a seam is two UVs on one point), a material per polygon and blend shapes
as sparse offsets of the points. The face is found and merged the glTF way
(core/formats/gltf/face.py), which wants triangle primitives with render vertices: so the
corners are split per (point, UV) pair, polygons fanned, and the triangles cut by material,
once here for both readers.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from studio.core.formats.gltf.scene import Primitive
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.unwrap import unwrap

Array = np.ndarray


@dataclass
class PolygonMesh:
    """One placed mesh as a polygon reader gives it, in the studio's space."""

    positions: Array  # (N, 3) float64 points
    sizes: Array  # (P,) int64 corners of each polygon
    corner_v: Array  # (C,) int64 point of each corner, polygon after polygon
    uvs: Array  # (M, 2) float64, v up; empty when the mesh has none
    corner_uv: Array  # (C,) int64 into ``uvs``
    face_material: Array  # (P,) int64 into ``material_names``
    material_names: list[str] = field(default_factory=lambda: [""])
    # per blend shape: (indices of the points it moves, (K, 3) float64 offsets of those points)
    shapes: list[tuple[Array, Array]] = field(default_factory=list)


def fan_corners(sizes: Array) -> tuple[Array, Array]:
    """(the polygon of each triangle, (T, 3) corner numbers) for polygons fanned from their
    first corner; polygons of fewer than three corners give none."""
    keep = sizes >= 3
    starts = (np.cumsum(sizes) - sizes)[keep]
    per = sizes[keep] - 2
    face = np.repeat(np.arange(len(per)), per)
    k = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per) + 1
    corners = np.stack([starts[face], starts[face] + k, starts[face] + k + 1], axis=1)
    return np.flatnonzero(keep)[face], corners


def primitives(mesh: PolygonMesh) -> list[Primitive]:
    """The mesh's triangle primitives, one per material it uses: corners split per (point,
    UV), polygons fanned, each blend shape's offsets on every render vertex."""
    uvs, corner_uv = mesh.uvs, mesh.corner_uv
    if len(uvs) == 0:
        uvs, corner_uv = np.zeros((1, 2)), np.zeros_like(mesh.corner_v)
    polygon, corners = fan_corners(mesh.sizes)
    key = mesh.corner_v * len(uvs) + corner_uv
    unique, inverse = np.unique(key, return_inverse=True)
    render_v, render_uv = unique // len(uvs), unique % len(uvs)
    triangles = inverse.reshape(-1)[corners]
    names = mesh.material_names or [""]
    material = np.clip(mesh.face_material[polygon], 0, len(names) - 1)
    offsets_all = []
    for index, offset in mesh.shapes:
        full = np.zeros_like(mesh.positions)
        full[index] = offset
        offsets_all.append(full[render_v])
    prims = []
    for m in np.unique(material):
        used, local = np.unique(triangles[material == m], return_inverse=True)
        prims.append(Primitive(material=int(m), material_name=names[int(m)],
                               positions=mesh.positions[render_v[used]],
                               triangles=local.reshape(-1, 3), uvs=uvs[render_uv[used]],
                               offsets={s: o[used] for s, o in enumerate(offsets_all)}))
    return prims


def unwrapped(mesh: FaceMesh, path: object) -> tuple[FaceMesh, str]:
    """The merged face with UVs made by xatlas, as one (a mesh of it had none: UVs made for
    part of it beside given ones would share one square), and the report's line saying so."""
    made = unwrap(mesh.rest, mesh.welded_triangles, str(path))
    return (FaceMesh(made.mesh.rest, made.mesh.triangles, made.mesh.uvs, made.mesh.weld,
                     str(path)), made.report(path))
