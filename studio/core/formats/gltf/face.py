"""Finding the face in a glTF scene and making it one mesh with key poses.

An avatar file holds a whole character: head, eyes, teeth, hair, glasses, body, clothes. The
face is found by itself: the meshes with morph targets that move them (the poses' meshes); of
those, the parts that are eyes, teeth, tongue or lashes (core/formats/face_parts.py: names,
small closed shells, rigid motion) are kept but marked not face; meshes without morph targets
(body, hair, clothes, glasses) are left out. ``keep`` and ``not_face`` (mesh, node or material
names; ``kind`` "mesh" or "material" to match one kind only) replace either choice. A file with
no morph targets keeps every mesh.

The kept meshes become one: each mesh's render vertices welded where position and every morph
offset agree (so closed lips whose poses part them stay two), the meshes side by side; each
morph target name is one key pose across meshes, zero on a mesh without it.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.files.budgets import POSES
from studio.core.files.errors import MeshError
from studio.core.formats.face_parts import Part, suggest_parts
from studio.core.formats.gltf.scene import MeshNode
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import ObjGroup

Array = np.ndarray
KINDS = ("mesh", "material")
_HASH_PRIME = np.uint64(0x9E3779B97F4A7C15)  # odd, its bits well spread (the golden ratio's)


@dataclass
class FaceChoice:
    """Which primitives of which placed meshes make the face, and why."""

    meshes: list[MeshNode]
    kept: list[tuple[int, int]]  # (mesh, primitive), in file order
    not_face: dict[tuple[int, int], str]  # kept primitive -> why ("named", "name", …)
    automatic: bool  # the face was found, not named by ``keep``
    suggest: bool  # not face is to be suggested, not named by ``not_face``
    # kept primitive -> why its material is see-through (``gltf_materials.see_through``)
    see_through: dict[tuple[int, int], str] = field(default_factory=dict)

    def kept_meshes(self) -> list[int]:
        return list(dict.fromkeys(m for m, _ in self.kept))


@dataclass
class MergedFace:
    mesh: FaceMesh
    poses: list[KeyPose]
    not_face: Array | None  # (W,) bool
    primitive_of_triangle: Array  # (F,) index into FaceChoice.kept
    pose_names_by_mesh: dict[int, list[str]] = field(default_factory=dict)


def _names(node: MeshNode, prim_material: str, kind: str | None) -> set[str]:
    names = set(node.names) if kind in (None, "mesh") else set()
    if kind in (None, "material") and prim_material:
        names.add(prim_material)
    return names


def _matching(meshes: list[MeshNode], wanted: Collection[str], kind: str | None, path: str,
              what: str) -> set[tuple[int, int]]:
    """The primitives a list of names picks; a name that matches nothing is refused, with the
    names the file has."""
    wanted = set(wanted)
    found, used = set(), set()
    for i, node in enumerate(meshes):
        for j, prim in enumerate(node.primitives):
            hit = _names(node, prim.material_name, kind) & wanted
            if hit:
                found.add((i, j))
                used |= hit
    missing = sorted(wanted - used)
    if missing:
        known = sorted({n for node in meshes for p in node.primitives
                        for n in _names(node, p.material_name, kind)})
        raise MeshError(f"{what} {', '.join(missing)}: no mesh, node or material has that name "
                        f"(the file has {', '.join(known) or 'no names'})", path)
    return found


def choose_face(meshes: list[MeshNode], keep: Collection[str] | None,
                not_face: Collection[str] | None, kind: str | None, path: str) -> FaceChoice:
    every = [(i, j) for i, m in enumerate(meshes) for j in range(len(m.primitives))]
    if keep is not None:
        chosen = _matching(meshes, keep, kind, path, "--keep")
        kept = [k for k in every if k in chosen]
    else:
        posed = _posed(meshes)
        kept = [k for k in every if k[0] in posed] if posed else every
    choice = FaceChoice(meshes, kept, {}, keep is None, not_face is None)
    if not_face is not None:
        marked = _matching(meshes, not_face, kind, path, "--not-face")
        choice.not_face = {k: "named" for k in kept if k in marked}
    return choice


def _posed(meshes: list[MeshNode]) -> set[int]:
    """The meshes of the face's rig: those a morph target moves, and those carrying targets of
    the same names that happen not to move them (the right eye when only the left looks up,
    teeth in a rig without a jaw pose)."""
    moving = {i for i, m in enumerate(meshes) if m.moving_targets()}
    names = {meshes[i].target_names[t] for i in moving for t in meshes[i].moving_targets()}
    return moving | {i for i, m in enumerate(meshes)
                     if any(p.offsets for p in m.primitives) and names & set(m.target_names)}


def merge_face(choice: FaceChoice, path: str) -> MergedFace:
    """One FaceMesh of the kept primitives, its key poses and not-face flags (suggested when
    the choice names none)."""
    meshes = choice.meshes
    rests, tris, uvs, welds, prim_of_tri = [], [], [], [], []
    offsets: dict[str, list[Array]] = {}
    pose_order: list[str] = []
    base_render = base_welded = 0
    by_mesh: dict[int, list[int]] = {}
    for k, (i, _) in enumerate(choice.kept):
        by_mesh.setdefault(i, []).append(k)
    names_by_mesh: dict[int, list[str]] = {}
    welded_offsets: list[tuple[int, int, dict[str, Array]]] = []
    for i, ks in by_mesh.items():
        node = meshes[i]
        prims = [node.primitives[choice.kept[k][1]] for k in ks]
        targets = sorted({t for p in prims for t in p.offsets})
        names = [node.target_names[t] for t in targets]
        if len(set(names)) != len(names):
            twice = next(n for n in names if names.count(n) > 1)
            raise MeshError(f"mesh '{node.label}' has two morph targets named '{twice}'", path)
        names_by_mesh[i] = names
        positions = _joined([p.positions for p in prims])
        moved = [_joined([p.offsets.get(t, np.zeros_like(p.positions)) for p in prims])
                 for t in targets]
        starts = np.cumsum([0] + [len(p.positions) for p in prims])
        triangles = np.concatenate([p.triangles + s for p, s in zip(prims, starts, strict=False)])
        first, inverse = _weld([positions, *moved])
        order = np.argsort(first)
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        weld = rank[inverse.reshape(-1)]
        keep_rows = first[order]
        rests.append(positions[keep_rows])
        uvs.append(np.concatenate([p.uvs for p in prims]))
        tris.append(triangles + base_render)
        welds.append(weld + base_welded)
        prim_of_tri.append(np.repeat(ks, [len(p.triangles) for p in prims]))
        unwelded = len(keep_rows) == len(positions)  # then keep_rows is every row, in order
        welded_offsets.append((base_welded, len(keep_rows),
                               {n: m if unwelded else m[keep_rows]
                                for n, m in zip(names, moved, strict=True)}))
        pose_order += [n for n in names if n not in offsets]
        for n in names:
            offsets.setdefault(n, [])
        base_render += len(positions)
        base_welded += len(keep_rows)
    rest = np.concatenate(rests)
    POSES.check(len(pose_order), "the morph target count", path, MeshError)
    poses = []
    for name in pose_order:
        moved = rest.copy()
        for start, count, table in welded_offsets:
            if name in table:
                moved[start:start + count] += table[name]
        poses.append(KeyPose(name, moved))
    mesh = FaceMesh(rest, np.concatenate(tris), np.concatenate(uvs), np.concatenate(welds),
                    path)
    merged = MergedFace(mesh, poses, None, np.concatenate(prim_of_tri), names_by_mesh)
    if choice.suggest:
        choice.not_face = _suggest(choice, merged)
    merged.not_face = _vertex_flags(choice, merged, path)
    return merged


def _joined(arrays: list[Array]) -> Array:
    """The arrays one after the other; the array itself when there is one (no copy)."""
    return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)


def _weld(columns: list[Array]) -> tuple[Array, Array]:
    """(first, inverse) as ``np.unique(rows, axis=0, return_index=True,
    return_inverse=True)`` gives them for the rows the ``columns`` blocks make side by side
    (position, then every morph offset): the vertices that agree in all of them.

    Why not that call: it sorts a copy of every row as one record, about four times the
    offsets of a face with a hundred targets (435 MB for 30 000 vertices). Here each row is
    hashed, a block at a time, and the hashes are sorted; rows whose hashes agree are then
    checked equal, block by block, and a collision (never seen) falls back to the exact call.
    """
    n = len(columns[0])
    hashes = np.zeros(n, np.uint64)
    prime, shift = _HASH_PRIME, np.uint64(29)
    for block in columns:
        bits = (np.ascontiguousarray(block, np.float64) + 0.0).view(np.uint64)  # -0.0 is 0.0
        for c in range(bits.shape[1]):  # mixed both ways: float32 values end in zero bits
            hashes ^= bits[:, c]
            hashes *= prime
            hashes ^= hashes >> shift
    _, first, inverse = np.unique(hashes, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    same = first[inverse]
    if all(np.array_equal(block[same], block) for block in columns):
        return first, inverse
    _, first, inverse = np.unique(np.concatenate(columns, axis=1), axis=0, return_index=True,
                                  return_inverse=True)
    return first, inverse.reshape(-1)


def _suggest(choice: FaceChoice, merged: MergedFace) -> dict[tuple[int, int], str]:
    """The suggestion over the kept primitives, never all of them: when every one looks not
    face, the largest with morph targets stays face."""
    tris = merged.mesh.welded_triangles
    parts, keys = [], []
    for k, (i, j) in enumerate(choice.kept):
        node = choice.meshes[i]
        own = tris[merged.primitive_of_triangle == k]
        vertices, local = np.unique(own, return_inverse=True)
        parts.append(Part([*node.names, node.primitives[j].material_name],
                          merged.mesh.rest[vertices], local.reshape(-1, 3),
                          [p.positions[vertices] for p in merged.poses],
                          choice.see_through.get((i, j), "")))
        keys.append((i, j))
    flagged = {keys[n]: why for n, why in suggest_parts(parts).items()}
    if flagged and len(flagged) == len(keys):
        largest = max(keys, key=lambda k: (bool(choice.meshes[k[0]].moving_targets()),
                                           len(choice.meshes[k[0]].primitives[k[1]].triangles)))
        del flagged[largest]
    return flagged


def _vertex_flags(choice: FaceChoice, merged: MergedFace, path: str) -> Array | None:
    """A welded vertex is not face when every triangle around it is (the eyelid's seam stays
    skin)."""
    if not choice.not_face:
        return None
    marked = np.array([k in choice.not_face for k in choice.kept])[merged.primitive_of_triangle]
    tris = merged.mesh.welded_triangles
    n = merged.mesh.n_welded
    every = np.bincount(tris.ravel(), minlength=n)
    flagged = np.bincount(tris[marked].ravel(), minlength=n)
    flags = (every > 0) & (flagged == every)
    if flags.all():
        names = sorted({choice.meshes[i].label for i, _ in choice.not_face})
        raise MeshError(f"marking {', '.join(names)} as not face leaves no skin to wrinkle",
                        path)
    return flags if flags.any() else None


def scene_groups(meshes: list[MeshNode]) -> list[ObjGroup]:
    """The file's meshes and materials with their triangle counts, for a parts table."""
    counts: dict[tuple[str, str], int] = {}
    for node in meshes:
        counts[("mesh", node.label)] = counts.get(("mesh", node.label), 0) + node.n_triangles
        for prim in node.primitives:
            if prim.material_name:
                key = ("material", prim.material_name)
                counts[key] = counts.get(key, 0) + len(prim.triangles)
    return [ObjGroup(kind, name, faces) for (kind, name), faces in counts.items()]


def report_lines(choice: FaceChoice, merged: MergedFace) -> list[str]:
    """What was found, in one report: the face, what is not face and why, what was left out,
    skinned meshes' bind pose."""
    meshes = choice.meshes
    kept = choice.kept_meshes()
    face = ", ".join(meshes[i].label for i in kept)
    lines = [f"glTF scene: {len(meshes)} mesh{'es' * (len(meshes) != 1)}; the face: {face} "
             f"({merged.mesh.n_welded} vertices, {len(merged.poses)} morph targets)"]
    if choice.not_face:
        parts = {}
        for i, j in choice.not_face:
            prim = meshes[i].primitives[j]
            label = (meshes[i].label if len(meshes[i].primitives) == 1 or not prim.material_name
                     else f"{meshes[i].label}/{prim.material_name}")
            parts[label] = choice.not_face[(i, j)]
        lines.append("not face: " + ", ".join(f"{n} ({why})" for n, why in parts.items()))
    out = [m.label for i, m in enumerate(meshes) if i not in kept]
    if out:
        why = "no morph targets" if choice.automatic else "not kept"
        lines.append(f"left out ({why}): {', '.join(out)}")
    skinned = [meshes[i].label for i in kept if meshes[i].skinned]
    if skinned:
        lines.append(f"skinned ({', '.join(skinned)}): the bind pose is used, the joints are "
                     "not applied")
    return lines
