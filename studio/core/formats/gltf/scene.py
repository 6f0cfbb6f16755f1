"""A glTF scene as meshes placed in the world: the node tree walked from the scene's roots (each
node's ``matrix`` or translation, rotation and scale, applied parent to child), every mesh a node
shows and every triangle primitive of it (lists, strips and fans), with its morph targets, its
material and UVs (the TEXCOORD set its base-colour texture reads, through KHR_texture_transform).
A primitive without UVs is read too (``has_uvs`` False, its UVs zero): a face that has none gets
them made once it is merged (core/formats/gltf/codec.py), so a file exported without a UV map opens;
one beside primitives that have UVs and that no morph target moves (an untextured prop) is left
out, as it always was.

A skinned mesh keeps its bind pose: glTF ignores the transform of a skinned mesh's node, and the
joints are not applied (an avatar's bind pose is the pose its morph targets were made in).
Positions keep the file's units and axes; the studio finds the face's own frame later.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import coordinate_problem
from studio.core.files.budgets import GLTF_VALUES, MESH_VERTICES, POSES
from studio.core.files.errors import MeshError
from studio.core.files.naming import shown
from studio.core.formats.gltf.container import _Gltf, _item, _list, _whole

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
    has_uvs: bool = True  # False: the file gives no TEXCOORD (``uvs`` are zeros, to be made)


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


_IDENTITY = np.eye(4)
# UVs beyond this are damage, not a layout: UDIM tiles reach 10 across, tiling textures some
# hundreds; past it the atlas's arithmetic in 32 bits loses the texel and can overflow.
UV_LIMIT = 1e6
_SHOWING = frozenset({"mesh", "matrix", "translation", "rotation", "scale"})


def _numbers(g: _Gltf, node: dict, index: int, key: str, default: tuple, size: int) -> Array:
    """One node's ``key`` as ``size`` floats, refused naming the node when it is not."""
    try:
        return np.array(node.get(key, default), np.float64).reshape(size)
    except (TypeError, ValueError, OverflowError):
        raise MeshError(f"node {index}'s transform is malformed ({key} is not a list of {size} "
                        "numbers)", g.path) from None


def _stacked(g: _Gltf, nodes: list, indices: list[int], key: str, default: tuple,
             size: int) -> Array:
    """``key`` of every node in ``indices`` as a ``(len(indices), size)`` array, made by one
    call to numpy (one per node costs as much as the rest of a node's work); when that fails,
    node by node, to name the first one that is malformed."""
    try:
        out = np.array([nodes[i].get(key, default) for i in indices], np.float64)
        if out.shape == (len(indices), size):
            return out
    except (TypeError, ValueError, OverflowError):
        pass
    return np.array([_numbers(g, nodes[i], i, key, default, size) for i in indices])


def local_matrices(g: _Gltf, nodes: list, indices: list[int]) -> Array:
    """The 4 × 4 transforms of ``indices``' nodes, ``(len(indices), 4, 4)``: each node's
    ``matrix`` (column-major) or T · R · S, all of them at once."""
    n = len(indices)
    given = np.array(["matrix" in nodes[i] for i in indices], bool).reshape(n)
    trs = [i for i in indices if "matrix" not in nodes[i]]
    x, y, z, w = _stacked(g, nodes, trs, "rotation", (0.0, 0.0, 0.0, 1.0), 4).reshape(-1, 4).T
    rot = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                    2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                    2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
                   axis=1).reshape(-1, 3, 3)
    out = np.tile(np.eye(4), (n, 1, 1))
    scale = _stacked(g, nodes, trs, "scale", (1.0, 1.0, 1.0), 3).reshape(-1, 3)
    out[~given, :3, :3] = rot * scale[:, None, :]
    out[~given, :3, 3] = _stacked(g, nodes, trs, "translation", (0.0, 0.0, 0.0), 3).reshape(-1, 3)
    if given.any():
        matrices = [i for i in indices if "matrix" in nodes[i]]
        out[given] = _stacked(g, nodes, matrices, "matrix", (), 16).reshape(-1, 4, 4) \
            .transpose(0, 2, 1)
    bad = ~np.isfinite(out).all(axis=(1, 2))
    if bad.any():
        raise MeshError(f"node {indices[int(np.argmax(bad))]}'s transform holds non-finite or "
                        "overflowing numbers", g.path)
    return out


def _roots(g: _Gltf, nodes: list) -> Iterable[object]:
    """The nodes of the scene shown (``scene``, else the first), or every node no other node
    lists as a child when the file names no scene (given one at a time: a file can hold two
    million of them)."""
    scenes = _list(g, g.doc, "scenes")
    if scenes:
        scene = _item(g, "scenes", g.doc.get("scene", 0), scenes)
        return _list(g, scene, "nodes")
    children = {c for n in nodes if isinstance(n, dict) for c in n.get("children", [])
                if _whole(c) and c < len(nodes)}
    if len(children) == len(nodes):
        raise MeshError("the file names no scene, and its nodes form a cycle (every node is "
                        "another's child), so no node is a root to show", g.path)
    return (i for i in range(len(nodes)) if i not in children)


def _walk(g: _Gltf, nodes: list) -> tuple[list[int], list[int]]:
    """The scene's nodes that move their children or show a mesh, in depth-first order, and
    each one's nearest such ancestor's place in that list (−1 for none): the tree the world
    matrices follow, without the nodes that change nothing. A node met twice (a cycle, or two
    parents) is refused."""
    kept: list[int] = []
    above: list[int] = []
    count = len(nodes)
    seen = bytearray(count)
    for root in _roots(g, nodes):  # each root's tree in turn: the stack holds one path's
        stack = [(root, -1)]
        while stack:
            index, parent = stack.pop()
            node = nodes[index] if type(index) is int and 0 <= index < count else None
            if type(node) is not dict:
                _item(g, "nodes", index, nodes)  # says what is wrong with the reference
            if seen[index]:
                raise MeshError(f"node {index} is its own ancestor or has two parents", g.path)
            seen[index] = 1
            if not node.keys().isdisjoint(_SHOWING):
                kept.append(index)
                above.append(parent)
                parent = len(kept) - 1
            children = node.get("children")
            if children:
                if not isinstance(children, list):
                    raise MeshError("'children' is not a JSON list", g.path)
                stack.extend([(c, parent) for c in reversed(children)])
    return kept, above


def chain_products(world: Array, up: Array) -> int:
    """Turn each local matrix into its world matrix, in place, by pointer jumping: ``up[k]``
    is the index of k's nearest kept ancestor (-1: none); each round multiplies every matrix
    by its nearest unmultiplied ancestor's, all at once. Returns the rounds taken: about
    log2 of the longest chain (seventeen for a hundred thousand levels), never its length."""
    up = up.copy()
    pending = np.flatnonzero(up >= 0)
    rounds = 0
    while len(pending):
        world[pending] = world[up[pending]] @ world[pending]
        up[pending] = up[up[pending]]
        pending = pending[up[pending] >= 0]
        rounds += 1
    return rounds


def placed_meshes(g: _Gltf) -> list[tuple[int | None, dict, Array]]:
    """(node, node object, world matrix) for each node of the scene that shows a mesh, in the
    order of a depth-first walk; a file without nodes gives each mesh once, unmoved.

    Why this way: a scene of 200 000 empty nodes, or 100 000 levels deep, must cost
    microseconds a node. The walk only follows references and keeps the nodes that move or
    show something; their transforms are computed together, and the world matrices by pointer
    jumping: each round multiplies every matrix by its nearest unmultiplied ancestor's, all at
    once, so a chain of a hundred thousand takes seventeen rounds."""
    nodes = _list(g, g.doc, "nodes")
    if not nodes:
        return [(None, {"mesh": i}, np.eye(4)) for i in range(len(_list(g, g.doc, "meshes")))]
    kept, above = _walk(g, nodes)
    with np.errstate(over="ignore", invalid="ignore"):  # checked below, said in one line
        world = local_matrices(g, nodes, kept)
        chain_products(world, np.array(above, np.int64).reshape(len(kept)))
    out = [(i, nodes[i], world[k]) for k, i in enumerate(kept) if "mesh" in nodes[i]]
    for index, _, matrix in out:
        if not np.isfinite(matrix).all():
            raise MeshError(f"node {index}'s place in the scene overflows (its transform and "
                            "its ancestors' multiply past the largest number)", g.path)
    return out


def _plan(g: _Gltf, placed: list[tuple[int | None, dict, Array]]) -> None:
    """Check, from what the file declares and before any accessor is read, that the placed
    meshes fit the budgets: morph targets per mesh, vertices placed in all (a mesh placed by a
    thousand nodes counts a thousand times) and the numbers they decode to (positions, UVs,
    indices and every target's offsets, for every placement)."""
    vertices = values = 0
    for node_index, node, _ in placed:
        spec = _item(g, "meshes", node["mesh"])
        for prim in _list(g, spec, "primitives"):
            if not (isinstance(prim, dict) and _is_surface(prim)):
                continue
            targets = _list(g, prim, "targets")
            POSES.check(len(targets), "the morph target count",
                        g.path, MeshError)
            n = g.declared_count(prim["attributes"].get("POSITION"))
            moved = sum(1 for t in targets if isinstance(t, dict) and "POSITION" in t)
            vertices += n
            values += n * (3 + 2 + 3 * moved) + g.declared_count(prim.get("indices"))
        where = f"placed by node {node_index}" if node_index is not None else "in the file"
        MESH_VERTICES.check(vertices, f"the vertices of the scene's meshes, with mesh "
                            f"{node['mesh']} {where},", g.path, MeshError)
        GLTF_VALUES.check(values, f"the numbers the scene's meshes decode to, with mesh "
                          f"{node['mesh']} {where},", g.path, MeshError)


def scene_meshes(g: _Gltf) -> list[MeshNode]:
    """Every placed mesh with its triangle primitives (primitives of points or lines are left
    out, and those without UVs beside others that have them, unless a morph target moves
    them: see ``_without_bare_props``); meshes left with none are left out."""
    out = []
    placed = placed_meshes(g)
    _plan(g, placed)
    for node_index, node, world in placed:
        mesh_index = node["mesh"]
        spec = _item(g, "meshes", mesh_index)
        skinned = "skin" in node
        matrix = np.eye(4) if skinned else world
        prims = _list(g, spec, "primitives")
        names = _target_names(spec, prims)
        placed_mesh = MeshNode(node_index, shown(node.get("name", "")), mesh_index,
                               shown(spec.get("name", "")), skinned, names)
        for prim in prims:
            if isinstance(prim, dict) and _is_surface(prim):
                placed_mesh.primitives.append(_primitive(g, prim, matrix, names))
        if placed_mesh.primitives:
            out.append(placed_mesh)
    out = _without_bare_props(out)
    if out:
        return out
    if not placed and _list(g, g.doc, "meshes"):
        raise MeshError("the scene shows no mesh (none of its nodes places one)", g.path)
    raise MeshError("the file holds no triangle mesh", g.path)


def _without_bare_props(meshes: list[MeshNode]) -> list[MeshNode]:
    """Primitives without UVs left out where others have UVs and no morph target moves them.

    Why: before UVs were made for a face without any, such primitives were never read, and in
    an avatar or a scene beside a textured face they are untextured props (a collider, a
    plain-coloured accessory): kept, a file without morph targets (which keeps every mesh)
    would mix made and given UVs. One a morph target moves is part of the face's rig and stays,
    for the face to be refused naming it when the rest has UVs."""
    if not any(p.has_uvs for m in meshes for p in m.primitives):
        return meshes
    out = []
    for mesh in meshes:
        mesh.primitives = [p for p in mesh.primitives if p.has_uvs or any(
            np.abs(o).max(initial=0.0) > 0.0 for o in p.offsets.values())]
        if mesh.primitives:
            out.append(mesh)
    return out


def _is_surface(prim: dict) -> bool:
    """A primitive of triangles with positions: what a face can be made of, UVs or not."""
    attrs = prim.get("attributes", {})
    return prim.get("mode", TRIANGLES) in (TRIANGLES, STRIP, FAN) and "POSITION" in attrs


def target_names(spec: dict) -> list[str]:
    """A mesh's morph target names, as its poses are named (VRM expressions bind them)."""
    prims = spec.get("primitives")
    return _target_names(spec, prims if isinstance(prims, list) else [])


def _target_names(spec: dict, prims: list) -> list[str]:
    """Target names from the mesh's extras, else the first primitive's, else numbered."""
    count = max((len(p.get("targets", [])) for p in prims if isinstance(p, dict)), default=0)
    names = (spec.get("extras", {}).get("targetNames")
             or next((p.get("extras", {}).get("targetNames") for p in prims
                      if isinstance(p, dict) and p.get("extras", {}).get("targetNames")), None)
             or [])
    if not isinstance(names, list):
        names = []
    return [shown(names[i]) if i < len(names) else f"target_{i}" for i in range(count)]


def _primitive(g: _Gltf, prim: dict, matrix: Array, target_names: list[str]) -> Primitive:
    attrs = prim["attributes"]
    local = g.attribute(attrs["POSITION"], "POSITION", ("VEC3",))
    n = len(local)
    positions = placed(g, local, matrix, "the mesh's positions", True)
    material, info = _material(g, prim)
    uvs = _uvs(g, attrs, info, n)
    has_uvs = uvs is not None
    if uvs is None:
        uvs = np.zeros((n, 2))
    triangles = _triangles(g, prim, n)
    offsets = {}
    for i, target in enumerate(prim.get("targets", [])):
        if "POSITION" not in target:
            continue
        name = target_names[i]
        moved = g.attribute(target["POSITION"], "POSITION", ("VEC3",), f"morph target '{name}'")
        if len(moved) != n:  # numpy would broadcast a single offset silently
            raise MeshError(f"morph target '{name}' moves {len(moved)} vertices, the mesh has "
                            f"{n}", g.path)
        offsets[i] = placed(g, moved, matrix, f"morph target '{name}'", False)
    index = prim.get("material")
    return Primitive(index, shown(material.get("name", "")), positions, triangles, uvs, offsets,
                     has_uvs)


def placed(g: _Gltf, local: Array, matrix: Array, what: str, point: bool) -> Array:
    """``local`` rows moved by the node's ``matrix`` (points, or offsets without its
    translation), refused in one line when the product leaves the range the studio computes
    in (numpy would warn of the overflow and carry infinities on). Unmoved rows are the
    accessor's own (read-only) values: most meshes sit at the origin, and a copy of every
    morph target would double what the file costs."""
    if np.array_equal(matrix, _IDENTITY):
        out = local
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            out = local @ matrix[:3, :3].T
            if point:
                out += matrix[:3, 3]
    problem = coordinate_problem(out, f"{what}, placed in the scene,")
    if problem:
        raise MeshError(problem, g.path)
    return out


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


def _uvs(g: _Gltf, attrs: dict, info: dict, n: int) -> Array | None:
    """The UVs the base-colour texture reads (its TEXCOORD set, through its
    KHR_texture_transform), with v flipped to point up; None when the primitive has none."""
    transform = (info.get("extensions") or {}).get("KHR_texture_transform") or {}
    texcoord = transform.get("texCoord", info.get("texCoord", 0))
    key = f"TEXCOORD_{texcoord}" if f"TEXCOORD_{texcoord}" in attrs else "TEXCOORD_0"
    if key not in attrs:
        return None
    uvs = g.attribute(attrs[key], key, ("VEC2",))[:, :2]
    if len(uvs) != n:
        raise MeshError(f"{key} has {len(uvs)} values, POSITION has {n}", g.path)
    if transform:
        try:
            offset = np.array(transform.get("offset", (0.0, 0.0)), np.float64).reshape(2)
            angle = float(transform.get("rotation", 0.0))
            scale = np.array(transform.get("scale", (1.0, 1.0)), np.float64).reshape(2)
        except (TypeError, ValueError, OverflowError) as exc:
            raise MeshError(f"a KHR_texture_transform is malformed ({exc})", g.path) from None
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below
            c, s = np.cos(angle), np.sin(angle)
            rotation = np.array([[c, s], [-s, c]])  # the extension's matrix, rows as written
            uvs = (uvs * scale) @ rotation.T + offset
    finite = np.isfinite(uvs).all(axis=1) & (np.abs(uvs) <= UV_LIMIT).all(axis=1)
    if not finite.all():
        v = int(np.argmin(finite))
        through = " (through its KHR_texture_transform)" if transform else ""
        raise MeshError(f"{key}{through} has the texture coordinate ({uvs[v, 0]:.3g}, "
                        f"{uvs[v, 1]:.3g}) at vertex {v}: UVs past {UV_LIMIT:.0e} (a texture "
                        "repeated a million times) are taken for damage", g.path)
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
