"""A USD stage's meshes placed in the studio's space, as the glTF path's ``MeshNode``s.

Every mesh prim the stage shows (instances too; not invisible ones, nor guides) is read: its
points placed by its transform (a skinned mesh's by its ``geomBindTransform`` and its skeleton's:
the bind pose, the joints not applied, as glTF's), its polygons (holes left out, a left-handed
or mirrored one turned so its normals face out), its UVs and its blend shapes. Sizes are checked
against the glTF reader's budgets on what the file declares: points and polygons as they are
read, every key pose's numbers before any offset is read.

UVs are the primvar the mesh's texture reads (``primvars:st`` by convention, else the first
texture-coordinate primvar), of any interpolation (per face corner, per point, per polygon,
constant), indexed or not: each corner's UV is found through the index, so a seam splits the
render vertices as an FBX's or OBJ's does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.files.budgets import GLTF_VALUES, MESH_TRIANGLES, MESH_VERTICES, POSES
from studio.core.files.errors import MeshError
from studio.core.formats.gltf.scene import MeshNode
from studio.core.formats.polygons import PolygonMesh, primitives
from studio.core.formats.usd.materials import FaceMaterials, face_materials, uv_name
from studio.core.formats.usd.shapes import read_shape, shape_plan
from studio.core.formats.usd.stage import StageFrame

Array = np.ndarray
UV_TYPES = ("texCoord2f[]", "texCoord2d[]", "texCoord2h[]", "float2[]", "double2[]")


@dataclass
class UsdMesh:
    """One placed mesh, with what its textures need: its materials, and whether it has UVs."""

    node: MeshNode
    materials: FaceMaterials
    has_uvs: bool


class _Sizes:
    """What the meshes read so far declare, against the budgets."""

    def __init__(self, path: object) -> None:
        self.path, self.points, self.triangles, self.values = path, 0, 0, 0

    def add_mesh(self, points: int, triangles: int) -> None:
        self.points += points
        self.triangles += triangles
        MESH_VERTICES.check(self.points, "the USD file's mesh points", self.path, MeshError)
        MESH_TRIANGLES.check(self.triangles, "the USD file's triangles", self.path, MeshError)

    def add_values(self, values: int, where: str) -> None:
        self.values += values
        GLTF_VALUES.check(self.values, f"the numbers the stage's meshes decode to, with {where},",
                          self.path, MeshError)


def _array(value, dtype, shape: tuple[int, ...]) -> Array:
    return np.asarray(value if value is not None else [], dtype).reshape(shape)


def read_meshes(stage, frame: StageFrame, path: object) -> list[UsdMesh]:
    """Every mesh the stage shows, in the order the stage lists them."""
    from pxr import Usd, UsdGeom

    xforms = UsdGeom.XformCache(Usd.TimeCode.Default())
    sizes = _Sizes(path)
    out: list[UsdMesh] = []
    for prim in Usd.PrimRange(stage.GetPseudoRoot(),
                              Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)):
        if not prim.IsA(UsdGeom.Mesh):
            continue
        shown = UsdGeom.Imageable(prim)
        if (shown.ComputeVisibility() == UsdGeom.Tokens.invisible
                or shown.ComputePurpose() == UsdGeom.Tokens.guide):
            continue
        mesh = _read_mesh(prim, len(out), xforms, frame, sizes, path)
        if mesh is not None:
            out.append(mesh)
    return out


def _placement(prim, xforms) -> tuple[Array, bool]:
    """(4, 4) row-vector transform of the mesh's points into the world, and whether the mesh
    is skinned: then its bind pose (``geomBindTransform``, then the skeleton's transform)."""
    from pxr import UsdSkel

    binding = UsdSkel.BindingAPI(prim)
    skinned = binding.GetJointIndicesPrimvar().HasAuthoredValue()
    skeleton = binding.GetInheritedSkeleton() if skinned else None
    if not skeleton:
        return np.array(xforms.GetLocalToWorldTransform(prim), np.float64), skinned
    bind = binding.GetGeomBindTransformAttr().Get()
    geom = np.array(bind, np.float64) if bind is not None else np.eye(4)
    return geom @ np.array(xforms.GetLocalToWorldTransform(skeleton.GetPrim()), np.float64), True


def _read_mesh(prim, number: int, xforms, frame: StageFrame, sizes: _Sizes,
               path: object) -> UsdMesh | None:
    """One mesh prim, None when it has no polygons to show."""
    from pxr import UsdGeom

    geom = UsdGeom.Mesh(prim)
    where = f"mesh {prim.GetPath()}"
    points = _array(geom.GetPointsAttr().Get(), np.float64, (-1, 3))
    counts = _array(geom.GetFaceVertexCountsAttr().Get(), np.int64, (-1,))
    corner_v = _array(geom.GetFaceVertexIndicesAttr().Get(), np.int64, (-1,))
    if len(points) == 0 or len(counts) == 0:
        return None
    sizes.add_mesh(len(points), int(np.maximum(counts - 2, 0).sum()))
    if counts.min() < 0:
        raise MeshError(f"{where}'s faceVertexCounts hold a negative count "
                        f"({int(counts.min())})", path)
    if counts.sum() != len(corner_v):
        raise MeshError(f"{where}'s faceVertexCounts add up to {int(counts.sum())}, its "
                        f"faceVertexIndices are {len(corner_v)}", path)
    outside = corner_v[(corner_v < 0) | (corner_v >= len(points))]
    if len(outside):
        raise MeshError(f"{where} uses point {int(outside[0])}: it has {len(points)}", path)
    if not np.isfinite(points).all():
        raise MeshError(f"{where} has a non-finite point (NaN or infinity)", path)
    targets = shape_plan(prim, path)
    POSES.check(len(targets), f"the blend shapes of {where}", path, MeshError)
    sizes.add_values(len(points) * 3 * (1 + len(targets)) + len(corner_v) * 2, where)
    materials = face_materials(prim, len(counts), where, path)
    uvs, corner_uv = _uvs(prim, materials, counts, corner_v, len(points), where, path)
    matrix, skinned = _placement(prim, xforms)
    if not np.isfinite(matrix).all():
        raise MeshError(f"{where}'s transform holds a non-finite number", path)
    linear = frame.to_studio @ matrix[:3, :3].T
    positions = points @ linear.T + frame.to_studio @ matrix[3, :3]
    shapes = []
    for target in targets:
        index, offset = read_shape(target, len(points), where, path)
        shapes.append((index, offset @ linear.T))
    keep = _shown_faces(geom, len(counts), where, path) & (counts >= 3)
    if not keep.any():  # points, lines or holes only: nothing a face is made of
        return None
    flip = (str(geom.GetOrientationAttr().Get()) == UsdGeom.Tokens.leftHanded) != (
        np.linalg.det(linear) < 0)
    order = _corner_order(counts, keep, flip)
    polygons = PolygonMesh(positions, counts[keep], corner_v[order], uvs, corner_uv[order],
                           materials.face_material[keep], materials.names, shapes)
    node = MeshNode(node=number, node_name=str(prim.GetPath()), mesh=number,
                    mesh_name=prim.GetName(), skinned=skinned,
                    target_names=[t.name for t in targets], primitives=primitives(polygons))
    return UsdMesh(node, materials, len(uvs) > 0)


def _shown_faces(geom, n_faces: int, where: str, path: object) -> Array:
    """(P,) the polygons that are not holes (``holeIndices``)."""
    holes = _array(geom.GetHoleIndicesAttr().Get(), np.int64, (-1,))
    outside = holes[(holes < 0) | (holes >= n_faces)]
    if len(outside):
        raise MeshError(f"{where}'s holeIndices list face {int(outside[0])}: it has {n_faces}",
                        path)
    keep = np.ones(n_faces, bool)
    keep[holes] = False
    return keep


def _corner_order(counts: Array, keep: Array, flip: bool) -> Array:
    """The corners of the polygons kept, each polygon's backwards when it is to be turned."""
    starts = np.cumsum(counts) - counts
    polygon = np.repeat(np.arange(len(counts)), counts)
    local = np.arange(int(counts.sum())) - starts[polygon]
    if flip:
        local = counts[polygon] - 1 - local
    order = starts[polygon] + local
    return order[keep[polygon]]


def _uv_primvar(prim, materials: FaceMaterials):
    """The primvar holding the mesh's UVs: the one its texture reads, ``st``, or the first of
    a texture-coordinate type; None when it has none."""
    from pxr import UsdGeom

    api = UsdGeom.PrimvarsAPI(prim)
    named = [uv_name(m) for m in materials.materials if m is not None]
    for name in [*(n for n in named if n), "st"]:
        primvar = api.GetPrimvar(name)
        if primvar and primvar.HasValue():
            return primvar
    return next((p for p in api.GetPrimvarsWithValues()
                 if str(p.GetTypeName()) in UV_TYPES), None)


def _uvs(prim, materials: FaceMaterials, counts: Array, corner_v: Array, n_points: int,
         where: str, path: object) -> tuple[Array, Array]:
    """(the UV values, (C,) each corner's index into them); both empty when the mesh has no
    UVs. Any interpolation, indexed or not."""
    from pxr import UsdGeom

    primvar = _uv_primvar(prim, materials)
    if primvar is None:
        return np.zeros((0, 2)), np.zeros(len(corner_v), np.int64)
    name = primvar.GetPrimvarName()
    try:
        values = _array(primvar.Get(), np.float64, (-1, 2))
    except ValueError:
        raise MeshError(f"{where}'s UVs ({name}) are not pairs of numbers", path) from None
    if not np.isfinite(values).all():
        raise MeshError(f"{where}'s UVs ({name}) hold a non-finite number", path)
    indices = (_array(primvar.GetIndices(), np.int64, (-1,)) if primvar.IsIndexed()
               else np.arange(len(values)))
    interpolation = primvar.GetInterpolation()
    per = {UsdGeom.Tokens.faceVarying: (len(corner_v), "face corners"),
           UsdGeom.Tokens.vertex: (n_points, "points"), UsdGeom.Tokens.varying: (n_points,
                                                                                 "points"),
           UsdGeom.Tokens.uniform: (len(counts), "faces"), UsdGeom.Tokens.constant: (1, "mesh")}
    wanted, what = per.get(interpolation, (len(corner_v), "face corners"))
    if len(indices) < wanted:
        raise MeshError(f"{where}'s UVs ({name}, {interpolation}) give {len(indices)} values "
                        f"for {wanted} {what}", path)
    outside = indices[(indices < 0) | (indices >= len(values))]
    if len(outside):
        raise MeshError(f"{where}'s UV index {int(outside[0])} is past its {len(values)} UVs "
                        f"({name})", path)
    if interpolation in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
        return values, indices[corner_v]
    if interpolation == UsdGeom.Tokens.uniform:
        return values, indices[np.repeat(np.arange(len(counts)), counts)]
    if interpolation == UsdGeom.Tokens.constant:
        return values, np.full(len(corner_v), indices[0])
    return values, indices[:len(corner_v)]
