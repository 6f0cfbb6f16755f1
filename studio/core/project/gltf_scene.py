"""A glTF scene as meshes placed in the world: the node tree walked from the scene's roots (each
node's ``matrix`` or translation, rotation and scale, applied parent to child), every mesh a node
shows and every triangle primitive of it (lists, strips and fans), with its morph targets, its
material and UVs (the TEXCOORD set its base-colour texture reads, through KHR_texture_transform).

A skinned mesh keeps its bind pose: glTF ignores the transform of a skinned mesh's node, and the
joints are not applied (an avatar's bind pose is the pose its morph targets were made in).
Positions keep the file's units and axes; the studio finds the face's own frame later.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from studio.core.files.errors import MeshError
from studio.core.project.gltf_container import _Gltf, _item, _list, _whole

Array = np.ndarray
TRIANGLES, STRIP, FAN = 4, 5, 6


@dataclass
class Primitive:
    """One triangle primitive of a placed mesh, in world space."""

    material: int | None
    material_name: str
    positions: Array  # (n, 3) float64, world
    triangles: Array  # (m, 3) int64 into positions
    uvs: Array  # (n, 2) float64, v up (the studio's convention), after any texture transform
    offsets: dict[int, Array]  # morph target index -> (n, 3) world offsets (POSITION only)


@dataclass
class MeshNode:
    """A mesh as one node shows it: its triangle primitives with UVs, welded later as one."""

    node: int | None  # None: a file without nodes, whose meshes are taken as they are
    node_name: str
    mesh: int
    mesh_name: str
    skinned: bool
    target_names: list[str]  # one per morph target of the mesh
    primitives: list[Primitive] = field(default_factory=list)

    @property
    def names(self) -> list[str]:
        """The names a user may call it by: the mesh's and the node's, each once."""
        return list(dict.fromkeys(n for n in (self.mesh_name, self.node_name) if n))

    @property
    def label(self) -> str:
        return self.mesh_name or self.node_name or f"mesh {self.mesh}"

    @property
    def n_vertices(self) -> int:
        return sum(len(p.positions) for p in self.primitives)

    @property
    def n_triangles(self) -> int:
        return sum(len(p.triangles) for p in self.primitives)

    def moving_targets(self) -> list[int]:
        """The morph targets that move any vertex of the mesh."""
        return sorted({i for p in self.primitives for i, o in p.offsets.items()
                       if np.abs(o).max(initial=0.0) > 0.0})


def local_matrix(g: _Gltf, node: dict, index: int) -> Array:
    """A node's 4 × 4 transform: its ``matrix`` (column-major) or T · R · S."""
    try:
        if "matrix" in node:
            m = np.array(node["matrix"], np.float64)
            if m.shape != (16,):
                raise ValueError("a matrix of 16 numbers")
            out = m.reshape(4, 4).T
        else:
            t = np.array(node.get("translation", (0.0, 0.0, 0.0)), np.float64).reshape(3)
            x, y, z, w = np.array(node.get("rotation", (0.0, 0.0, 0.0, 1.0)),
                                  np.float64).reshape(4)
            s = np.array(node.get("scale", (1.0, 1.0, 1.0)), np.float64).reshape(3)
            rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            out = np.eye(4)
            out[:3, :3] = rot * s
            out[:3, 3] = t
    except (TypeError, ValueError) as exc:
        raise MeshError(f"node {index}'s transform is malformed ({exc})", g.path) from None
    if not np.isfinite(out).all():
        raise MeshError(f"node {index}'s transform holds non-finite numbers", g.path)
    return out


def _roots(g: _Gltf, nodes: list) -> list[int]:
    """The nodes of the scene shown (``scene``, else the first), or every node no other node
    lists as a child when the file names no scene."""
    scenes = _list(g, g.doc, "scenes")
    if scenes:
        scene = _item(g, "scenes", g.doc.get("scene", 0), scenes)
        return list(_list(g, scene, "nodes"))
    children = {c for n in nodes if isinstance(n, dict) for c in n.get("children", [])}
    return [i for i in range(len(nodes)) if i not in children]


def placed_meshes(g: _Gltf) -> list[tuple[int | None, dict, Array]]:
    """(node, node object, world matrix) for each node of the scene that shows a mesh, in the
    order of a depth-first walk; a file without nodes gives each mesh once, unmoved."""
    nodes = _list(g, g.doc, "nodes")
    if not nodes:
        return [(None, {"mesh": i}, np.eye(4)) for i in range(len(_list(g, g.doc, "meshes")))]
    out: list[tuple[int | None, dict, Array]] = []
    seen: set[int] = set()
    stack = [(i, np.eye(4)) for i in reversed(_roots(g, nodes))]
    while stack:
        index, parent = stack.pop()
        node = _item(g, "nodes", index, nodes)
        if index in seen:
            raise MeshError(f"node {index} is its own ancestor or has two parents", g.path)
        seen.add(index)
        world = parent @ local_matrix(g, node, index)
        if "mesh" in node:
            out.append((index, node, world))
        children = _list(g, node, "children")
        stack.extend((c, world) for c in reversed(children))
    return out


def scene_meshes(g: _Gltf) -> list[MeshNode]:
    """Every placed mesh with its triangle primitives that have UVs (primitives of points or
    lines, or without UVs, are left out); meshes left with none are left out."""
    out = []
    for node_index, node, world in placed_meshes(g):
        mesh_index = node["mesh"]
        spec = _item(g, "meshes", mesh_index)
        skinned = "skin" in node
        matrix = np.eye(4) if skinned else world
        prims = _list(g, spec, "primitives")
        names = _target_names(spec, prims)
        placed = MeshNode(node_index, str(node.get("name", "")), mesh_index,
                          str(spec.get("name", "")), skinned, names)
        for prim in prims:
            if isinstance(prim, dict) and _is_surface(prim):
                placed.primitives.append(_primitive(g, prim, matrix, names))
        if placed.primitives:
            out.append(placed)
    if out:
        return out
    if any(isinstance(p, dict) and "POSITION" in p.get("attributes", {})
           for m in _list(g, g.doc, "meshes") if isinstance(m, dict)
           for p in m.get("primitives", [])):
        raise MeshError("the mesh has no texture coordinates (TEXCOORD_0)", g.path)
    raise MeshError("the file holds no triangle mesh", g.path)


def _is_surface(prim: dict) -> bool:
    attrs = prim.get("attributes", {})
    return (prim.get("mode", TRIANGLES) in (TRIANGLES, STRIP, FAN) and "POSITION" in attrs
            and "TEXCOORD_0" in attrs)


def _target_names(spec: dict, prims: list) -> list[str]:
    """Target names from the mesh's extras, else the first primitive's, else numbered."""
    count = max((len(p.get("targets", [])) for p in prims if isinstance(p, dict)), default=0)
    names = (spec.get("extras", {}).get("targetNames")
             or next((p.get("extras", {}).get("targetNames") for p in prims
                      if isinstance(p, dict) and p.get("extras", {}).get("targetNames")), None)
             or [])
    return [str(names[i]) if i < len(names) else f"target_{i}" for i in range(count)]


def _primitive(g: _Gltf, prim: dict, matrix: Array, target_names: list[str]) -> Primitive:
    attrs = prim["attributes"]
    local = g.typed(attrs["POSITION"], ("VEC3",), "POSITION")
    n = len(local)
    positions = local @ matrix[:3, :3].T + matrix[:3, 3]
    material, info = _material(g, prim)
    uvs = _uvs(g, attrs, info, n)
    triangles = _triangles(g, prim, n)
    offsets = {}
    for i, target in enumerate(prim.get("targets", [])):
        if "POSITION" not in target:
            continue
        name = target_names[i]
        moved = g.typed(target["POSITION"], ("VEC3",), f"morph target '{name}'")
        if len(moved) != n:  # numpy would broadcast a single offset silently
            raise MeshError(f"morph target '{name}' moves {len(moved)} vertices, the mesh has "
                            f"{n}", g.path)
        offsets[i] = moved @ matrix[:3, :3].T
    index = prim.get("material")
    return Primitive(index, str(material.get("name", "")), positions, triangles, uvs, offsets)


def _material(g: _Gltf, prim: dict) -> tuple[dict, dict]:
    """The primitive's material and its base-colour texture reference (empty when none)."""
    if "material" not in prim:
        return {}, {}
    try:
        material = g.doc["materials"][prim["material"]]
        if not _whole(prim["material"]) or not isinstance(material, dict):
            raise TypeError
    except (KeyError, IndexError, TypeError):
        raise MeshError("the mesh refers to a material that does not exist", g.path) from None
    info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture") or {}
    return material, info if isinstance(info, dict) else {}


def _uvs(g: _Gltf, attrs: dict, info: dict, n: int) -> Array:
    """The UVs the base-colour texture reads (its TEXCOORD set, through its
    KHR_texture_transform), with v flipped to point up."""
    transform = (info.get("extensions") or {}).get("KHR_texture_transform") or {}
    texcoord = transform.get("texCoord", info.get("texCoord", 0))
    key = f"TEXCOORD_{texcoord}" if f"TEXCOORD_{texcoord}" in attrs else "TEXCOORD_0"
    uvs = g.typed(attrs[key], ("VEC2",), key)[:, :2]
    if len(uvs) != n:
        raise MeshError(f"{key} has {len(uvs)} values, POSITION has {n}", g.path)
    if transform:
        try:
            offset = np.array(transform.get("offset", (0.0, 0.0)), np.float64).reshape(2)
            angle = float(transform.get("rotation", 0.0))
            scale = np.array(transform.get("scale", (1.0, 1.0)), np.float64).reshape(2)
        except (TypeError, ValueError) as exc:
            raise MeshError(f"a KHR_texture_transform is malformed ({exc})", g.path) from None
        c, s = np.cos(angle), np.sin(angle)
        rotation = np.array([[c, s], [-s, c]])  # the extension's matrix, rows as written
        uvs = (uvs * scale) @ rotation.T + offset
    return uvs * [1.0, -1.0] + [0.0, 1.0]


def _triangles(g: _Gltf, prim: dict, n: int) -> Array:
    mode = prim.get("mode", TRIANGLES)
    if "indices" in prim:
        indices = g.typed(prim["indices"], ("SCALAR",), "the indices", integer=True)[:, 0]
        if (mode == TRIANGLES and len(indices) % 3) or indices.max() >= n:
            raise MeshError(f"the indices are not triangles over the {n} vertices "
                            "(a count not divisible by 3, or a vertex that does not exist)",
                            g.path)
        order = indices.astype(np.int64)
    else:
        if mode == TRIANGLES and n % 3:
            raise MeshError(f"{n} vertices without indices are not triangles", g.path)
        order = np.arange(n)
    if mode == TRIANGLES:
        return order.reshape(-1, 3)
    k = np.arange(max(len(order) - 2, 0))
    if mode == STRIP:  # every other triangle turns the other way round
        odd = k % 2 == 1
        a, b = np.where(odd, k + 1, k), np.where(odd, k, k + 1)
        return np.stack([order[a], order[b], order[k + 2]], axis=1)
    return np.stack([np.full(len(k), order[0]), order[k + 1], order[k + 2]], axis=1)
