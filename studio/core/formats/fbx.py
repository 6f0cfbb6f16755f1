"""FBX in: what Maya, MetaHuman, Character Creator and most rigs export, read by ufbx.

Why ufbx (PyPI ``ufbx``, the binding of ufbx, the fuzzed single-file C reader Godot's FBX
importer uses): it has cp311 manylinux wheels and reads blend shape channels with their target
shapes as sparse offsets, the file's axes and UnitScaleFactor. The
Assimp bindings were weighed: ``assimp-py`` ships wheels but exposes no anim meshes (no blend
shapes); ``pyassimp`` and ``impasse`` load a system libassimp through ctypes/cffi, which no
wheel brings. ufbx's binding is young (0.0.5): its blend channel wrappers crash the interpreter
when garbage-collected, so the file is read in a child process that copies every array out,
writes them to an .npz and exits without collecting (``os._exit``). A crash there is one line
naming the file, never the studio going down.

The file's scene then goes the glTF way (core/formats/gltf/face.py): each mesh instance a
``MeshNode``, placed in world space by its node's transform (a skeleton's bind pose included),
each material a primitive, each blend channel a morph target; the face is found among the
meshes by the targets that move them, eyes and teeth suggested as not face. Axes come from the
file (its up and front axes turned to Y up, Z front); lengths stay in the file's units and the
unit is said. A face without UVs gets them from xatlas (core/mesh/unwrap.py), said too.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from collections.abc import Collection
from pathlib import Path, PureWindowsPath

import numpy as np

from studio.core.files.budgets import FILE_BYTES, MESH_TRIANGLES, MESH_VERTICES
from studio.core.files.errors import MeshError
from studio.core.formats.gltf.face import FaceChoice, choose_face, merge_face, report_lines
from studio.core.formats.gltf.scene import MeshNode
from studio.core.formats.head_maps import HeadMaps, MapSource, read_head_maps, skin_part
from studio.core.formats.polygons import PolygonMesh, primitives, unwrapped
from studio.core.project.model import Project

Array = np.ndarray
CHILD_SECONDS = 300  # a reader stuck on a damaged file must not hold the studio forever
# ufbx's CoordinateAxis: +X, -X, +Y, -Y, +Z, -Z
_AXIS_VECTORS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
                         np.float64)
_UNITS = {1.0: "metres", 0.01: "centimetres", 0.001: "millimetres", 0.1: "decimetres",
          0.0254: "inches", 0.3048: "feet"}


def load_fbx(path: str | Path, keep: Collection[str] | None = None,
             not_face: Collection[str] | None = None, kind: str | None = None,
             report: list[str] | None = None) -> Project:
    """A project from an FBX file: the face found among its meshes, blend shapes as key poses;
    ``keep``, ``not_face``, ``kind`` and ``report`` as ``load_gltf``'s."""
    path = Path(path)
    if not path.is_file():
        raise MeshError("no such file", path)
    FILE_BYTES.check(path.stat().st_size, "the FBX file", path, MeshError)
    data = _read_in_child(path)
    count = int(data["count"])
    MESH_VERTICES.check(sum(len(data[f"m{i}_positions"]) for i in range(count)),
                        "the FBX file's meshes", path, MeshError)
    MESH_TRIANGLES.check(sum(len(data[f"m{i}_corners"]) for i in range(count)),
                         "the FBX file's face corners", path, MeshError)
    unit = float(data["unit_meters"])
    to_studio = _axes_matrix(path, [int(a) for a in data["axes"]])
    meshes = [_mesh_node(data, i, to_studio) for i in range(count)]
    if not meshes:
        raise MeshError("the file holds no mesh", path)
    choice = choose_face(meshes, keep, not_face, kind, str(path))
    merged = merge_face(choice, str(path))
    mesh = merged.mesh
    lines = [line.replace("glTF scene:", "FBX scene:", 1) for line in report_lines(choice, merged)]
    bare = [i for i in choice.kept_meshes() if len(data[f"m{i}_uvs"]) == 0]
    if bare:  # a face mesh without UVs: the merged face unwrapped as one
        mesh, line = unwrapped(mesh, path)
        lines.append(line)
    name = _UNITS.get(round(unit, 6), f"{unit:g} m")
    lines.append(f"units: the file's ({name}); axes: the file's, turned to Y up, Z front")
    maps = _skin_maps(data, choice, merged.primitive_of_triangle, path) if not bare \
        else HeadMaps()
    lines += maps.lines
    project = Project(path.stem, mesh, merged.poses, maps.textures(), not_face=merged.not_face)
    if report is not None:
        report += lines
    return project


def _skin_maps(data, choice: FaceChoice, primitive_of_triangle: Array, path: Path) -> HeadMaps:
    """The skin material's base colour and normal map (core/formats/head_maps.py)."""
    i, j = choice.kept[skin_part(choice, primitive_of_triangle)]
    material = choice.meshes[i].primitives[j].material
    names = [str(n) for n in data[f"m{i}_materials"]]
    if material is None or material >= len(names):
        return HeadMaps()
    numbers = np.asarray(data[f"m{i}_maps"]).reshape(-1, 2)[material]
    sources = {slot: _map_source(data, int(n), path) if n >= 0 else None
               for slot, n in zip(("diffuse", "normal"), numbers, strict=True)}
    return read_head_maps(sources, names[material], path)


def _map_source(data, n: int, path: Path) -> MapSource:
    """Where texture ``n`` of the file is: its embedded bytes, else the file it names —
    resolved by ufbx, relative to the FBX, absolute as written, or beside the FBX by name
    (where Blender looks for a texture moved with its file)."""
    resolved, relative, absolute, _ = (str(n) for n in data[f"t{n}_names"])
    written = relative or absolute or resolved
    name = PureWindowsPath(written).name  # "/" and "\\" both separate
    paths = [Path(p) for p in (resolved, absolute) if p]
    if relative:
        paths.insert(0, path.parent / relative.replace("\\", "/"))
    if name:
        paths.append(path.parent / name)
    embedded = bytes(np.asarray(data[f"t{n}_data"], np.uint8))
    return MapSource(written, embedded or None, paths)


def _axes_matrix(path: Path, axes: list[int]) -> Array:
    """(3, 3): the file's right, up and front axes onto the studio's X, Y and Z."""
    if len(axes) != 3 or not all(0 <= a < 6 for a in axes) or len({a // 2 for a in axes}) != 3:
        raise MeshError("the file's coordinate axes are not three distinct axes", path)
    return np.stack([_AXIS_VECTORS[a] for a in axes])


def _mesh_node(data, i: int, to_studio: Array) -> MeshNode:
    """One mesh instance as the glTF path's ``MeshNode`` (core/formats/polygons.py: corners
    split per (vertex, UV), polygons fanned, one primitive per material)."""
    world = np.asarray(data[f"m{i}_matrix"], np.float64).reshape(4, 4)
    linear = to_studio @ world[:3, :3]
    positions = (np.asarray(data[f"m{i}_positions"], np.float64) @ linear.T
                 + to_studio @ world[:3, 3])
    shape_names = [str(n) for n in data[f"m{i}_shapes"]]
    shapes = [(np.asarray(data[f"m{i}_s{s}_index"], np.int64),
               np.asarray(data[f"m{i}_s{s}_offset"], np.float64) @ linear.T)
              for s in range(len(shape_names))]
    mesh = PolygonMesh(positions, np.asarray(data[f"m{i}_sizes"], np.int64),
                       np.asarray(data[f"m{i}_corners"], np.int64),
                       np.asarray(data[f"m{i}_uvs"], np.float64).reshape(-1, 2),
                       np.asarray(data[f"m{i}_uv_index"], np.int64),
                       np.asarray(data[f"m{i}_face_material"], np.int64),
                       [str(n) for n in data[f"m{i}_materials"]] or [""], shapes)
    return MeshNode(node=i, node_name=str(data[f"m{i}_node"]), mesh=i,
                    mesh_name=str(data[f"m{i}_name"]), skinned=bool(data[f"m{i}_skinned"]),
                    target_names=shape_names, primitives=primitives(mesh))


def _read_in_child(path: Path) -> dict[str, Array]:
    """The file's meshes as plain arrays, read by ufbx in a child process (see the module's
    docstring for why)."""
    with tempfile.TemporaryDirectory(prefix="wrinkle-fbx-") as folder:
        out = Path(folder) / "scene.npz"
        try:
            done = subprocess.run([sys.executable, "-m", "studio.core.formats.fbx", str(path),
                                   str(out)], capture_output=True, text=True,
                                  timeout=CHILD_SECONDS, env={**os.environ, "PYTHONPATH": _root()})
        except subprocess.TimeoutExpired:
            raise MeshError(f"the FBX reader took over {CHILD_SECONDS} s", path) from None
        if done.returncode != 0 or not out.is_file():
            last = (done.stderr.strip().splitlines() or ["it stopped without a word"])[-1]
            raise MeshError(f"cannot read the FBX file ({last})", path)
        with np.load(out, allow_pickle=False) as loaded:
            return {k: loaded[k] for k in loaded.files}


def _root() -> str:
    """The folder holding the ``studio`` package, first on the child's path."""
    here = str(Path(__file__).resolve().parents[3])
    rest = os.environ.get("PYTHONPATH", "")
    return here + (os.pathsep + rest if rest else "")


def _dump(path: str, out: str) -> None:
    """In the child: every mesh instance's arrays, each list element touched once (ufbx
    0.0.5's wrappers go stale when a list is indexed twice, and crash the cyclic collector)."""
    import gc

    gc.disable()
    import ufbx

    try:
        scene = ufbx.load_file(path)
    except Exception as exc:  # ufbx raises a class per problem; the user needs one line
        print(f"{type(exc).__name__}: {exc}", file=sys.stderr)
        sys.stderr.flush()
        os._exit(1)
    settings = scene.settings
    axes = settings.axes
    arrays: dict[str, object] = {"unit_meters": float(settings.unit_meters),
                                 "axes": np.array([int(axes.right), int(axes.up),
                                                   int(axes.front)])}
    count = 0
    textures: dict[int, int] = {}  # ufbx element id -> number in the .npz
    for mesh in scene.meshes:
        positions = np.array(memoryview(mesh.vertices), np.float64).reshape(-1, 3)
        corners = np.fromiter(mesh.vertex_indices, np.int64)
        sizes = np.array([f.num_indices for f in mesh.faces], np.int64)
        uv = mesh.vertex_uv
        has_uv = bool(uv.exists)
        uvs = np.array(memoryview(uv.values), np.float64) if has_uv else np.zeros((0, 2))
        uv_index = np.fromiter(uv.indices, np.int64) if has_uv else np.zeros(0, np.int64)
        materials, maps = [], []
        for material in mesh.materials:  # each wrapper touched once (see above)
            materials.append(material.name)
            maps.append([_texture_slot(material, slot, textures) for slot in _MAP_SLOTS])
        face_material = (np.fromiter(mesh.face_material, np.int64) if materials
                         else np.zeros(len(sizes), np.int64))
        shapes, indices, offsets = [], [], []
        for deformer in mesh.blend_deformers:
            for channel in deformer.channels:
                shape = channel.target_shape
                if shape is None:
                    continue
                shapes.append(channel.name)
                indices.append(np.fromiter(shape.offset_vertices, np.int64))
                offsets.append(np.array(memoryview(shape.position_offsets), np.float64))
        skinned = len(mesh.skin_deformers) > 0
        for node in mesh.instances:
            g = node.geometry_to_world
            matrix = np.eye(4)
            matrix[:3, :] = np.array([tuple(g.c0), tuple(g.c1), tuple(g.c2), tuple(g.c3)]).T
            prefix = f"m{count}_"
            arrays.update({prefix + "name": mesh.name, prefix + "node": node.name,
                           prefix + "matrix": matrix, prefix + "positions": positions,
                           prefix + "corners": corners, prefix + "sizes": sizes,
                           prefix + "uvs": uvs.reshape(-1, 2), prefix + "uv_index": uv_index,
                           prefix + "materials": np.array(materials, dtype=str),
                           prefix + "maps": np.array(maps, np.int64).reshape(-1, 2),
                           prefix + "face_material": face_material,
                           prefix + "shapes": np.array(shapes, dtype=str),
                           prefix + "skinned": skinned})
            for s, (index, offset) in enumerate(zip(indices, offsets, strict=True)):
                arrays[prefix + f"s{s}_index"] = index
                arrays[prefix + f"s{s}_offset"] = offset.reshape(-1, 3)
            count += 1
    arrays["count"] = count
    for texture, n in textures.items():
        arrays[f"t{n}_names"], arrays[f"t{n}_data"] = _texture_files[texture]
    np.savez(out, **arrays)
    sys.stdout.flush()
    os._exit(0)  # no collection: the binding's wrappers crash when freed


_MAP_SLOTS = (("base_color", "diffuse_color"), ("normal_map", "normal_map"))
_texture_files: dict[int, tuple[Array, Array]] = {}  # in the child: each texture's files


def _texture_slot(material, slot: tuple[str, str], textures: dict[int, int]) -> int:
    """In the child: the number of the texture a material shows in ``slot`` (its PBR map,
    else its classic FBX one), -1 for none; the texture's names and embedded bytes kept."""
    texture = getattr(material.pbr, slot[0]).texture or getattr(material.fbx, slot[1]).texture
    if texture is None:
        return -1
    key = int(texture.element_id)
    if key not in textures:
        textures[key] = len(textures)
        names = [str(texture.filename), str(texture.relative_filename),
                 str(texture.absolute_filename), str(texture.name)]
        content = texture.content
        _texture_files[key] = (np.array(names, dtype=str),
                               np.frombuffer(bytes(content) if content else b"", np.uint8))
    return textures[key]


if __name__ == "__main__":
    _dump(sys.argv[1], sys.argv[2])
