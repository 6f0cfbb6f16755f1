"""A new project from the user's own files: neutral mesh, key-pose meshes, texture maps.

Shared by File ▸ New from Files and the command line. A glTF, VRM, FBX or USD file is a whole
head: its blend shapes are the key poses and its face is found among its meshes. Missing normal
maps default to flat ones (a face may come with no detail at rest, or no wrinkled map yet); a
missing diffuse map to plain skin colour. An OBJ's objects, groups and materials, or a glTF's
meshes, nodes and materials, can be kept in part (``keep``) and marked as not face
(``not_face``: eyes, teeth — never wrinkled); a glTF's face is found and its not-face parts
suggested when they are not named. UDIM-tiled UVs are packed into one atlas and texture sets
composed into it (``uv_tiles``, ``texture_sets``).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.animation.poses import NEUTRAL
from studio.core.files.errors import MeshError
from studio.core.formats.face_parts import Part, choose_parts, suggest_names, suggest_parts
from studio.core.formats.fbx import load_fbx
from studio.core.formats.gltf.codec import load_gltf
from studio.core.formats.gltf.container import _Gltf
from studio.core.formats.gltf.materials import _rgb
from studio.core.formats.head_maps import HeadMaps
from studio.core.formats.obj_maps import obj_head_maps
from studio.core.formats.texture_sets import load_texture
from studio.core.formats.usd import is_usd
from studio.core.formats.usd.reader import load_usd
from studio.core.formats.vrm import SUFFIX as VRM_SUFFIX
from studio.core.formats.vrm import apply_expressions, check_suffix, vrm_info, vrm_target_names
from studio.core.mesh.meshio import KINDS, load_mesh, load_pose, not_face_vertices, obj_groups
from studio.core.mesh.uv_tiles import FIRST_TILE, TileLayout, atlas_size, compose_atlas, pack_mesh
from studio.core.project.model import Project
from studio.core.wrinkles.textures import SKIN, FaceTextures, flat_normal_map, plain_diffuse

FLAT_NORMAL = (128, 128, 255)


VRM_SNIFF = 1 << 20  # bytes of a .glb searched for a VRM extension's name (in its JSON)
RIGID_SAMPLE = 8  # key-pose files read to suggest parts the poses move rigidly


def suggest_not_face(names: Iterable[str]) -> list[str]:
    """The part names that look like eyes, teeth or tongue: a starting choice for the user."""
    return suggest_names(names)


def _obj_parts(mesh: str | Path, kind: str, poses: Mapping[str, str | Path] | None,
               sample: int | None) -> tuple[list[str], list[Part], list[set[int]]]:
    """An OBJ's parts of ``kind`` as ``face_parts.Part``s (names, positions, triangles, their
    positions in the key poses: up to ``sample`` pose files spread over the list, None for
    all; one that cannot be read is left out here, the project's load reports it) and, for
    each, the parts it shares a vertex with."""
    face = load_mesh(mesh)
    names = [g.name for g in obj_groups(mesh) if g.kind == kind]
    paths = list((poses or {}).values())
    if sample is not None and len(paths) > sample:
        paths = [paths[i] for i in np.linspace(0, len(paths) - 1, sample).round()
                 .astype(int)]
    shapes = []
    for path in paths:
        try:
            shapes.append(load_pose(path, face).positions)
        except MeshError:
            continue
    tris = face.welded_triangles
    parts, owner = [], np.full(face.n_welded, -1)
    shared: list[set[int]] = [set() for _ in names]
    for k, name in enumerate(names):
        inside = not_face_vertices(face, [name], kind)
        own = tris[inside[tris].all(axis=1)]
        vertices, local = np.unique(own, return_inverse=True)
        for other in set(owner[vertices].tolist()) - {-1}:
            shared[k].add(other)
            shared[other].add(k)
        owner[vertices] = k
        parts.append(Part([name], face.rest[vertices], local.reshape(-1, 3),
                          [shape[vertices] for shape in shapes]))
    return names, parts, shared


def suggest_obj_parts(mesh: str | Path, kind: str,
                      poses: Mapping[str, str | Path] | None = None) -> dict[str, str]:
    """An OBJ's parts of ``kind`` (object, group or material) that look not face, each with
    why (``face_parts.suggest_parts``): by name, as a small closed shell, or — with key-pose
    files — moved rigidly by every pose that moves it (up to ``RIGID_SAMPLE`` of them, spread
    over the list: a suggestion, made while the user picks files, not a proof). A pose file
    that cannot be read is left out here (Create reports it). Never every part: the largest
    stays face."""
    names, parts, _ = _obj_parts(mesh, kind, poses, RIGID_SAMPLE)
    flagged = {names[i]: why for i, why in suggest_parts(parts).items()}
    if names and len(flagged) == len(names):
        del flagged[names[int(np.argmax([len(p.triangles) for p in parts]))]]
    return flagged


@dataclass
class ObjChoice:
    """What ``choose_obj_parts`` found in an OBJ: the kind of part it split by, the face's
    parts, and the parts left out and not face, each with why."""

    kind: str
    face: list[str]
    left_out: dict[str, str]
    not_face: dict[str, str]

    def line(self) -> str:
        """The one line of report: what was chosen, and the options that change it."""
        def listed(parts: dict[str, str]) -> str:
            return ", ".join(f"{n} ({why})" for n, why in parts.items())

        kinds = f"{self.kind}s" if self.kind != "material" else "materials"
        text = (f"OBJ {kinds}: {len(self.face) + len(self.left_out)}; the face: "
                f"{', '.join(n for n in self.face if n not in self.not_face)}")
        if self.not_face:
            text += f"; not face: {listed(self.not_face)}"
        if self.left_out:
            text += f"; left out: {listed(self.left_out)}"
        return text + " (change with --keep and --not-face)"


def choose_obj_parts(mesh: str | Path, poses: Mapping[str, str | Path] | None = None
                     ) -> ObjChoice | None:
    """The face in an OBJ of several parts (a head with its eyes and teeth, a whole body with
    hair cards, joint markers and helpers): split by the kind of part that divides it most
    (objects, groups or materials), the parts left out and the parts not face chosen by
    ``face_parts.choose_parts`` from names, shells and every key pose's motion. None for an
    OBJ of one part, or not an OBJ."""
    if Path(mesh).suffix.lower() != ".obj":
        return None
    groups = obj_groups(mesh)
    counts = {kind: sum(g.kind == kind for g in groups) for kind in KINDS}
    kind = max(KINDS, key=lambda k: counts[k])
    if counts[kind] < 2:
        return None
    names, parts, shared = _obj_parts(mesh, kind, poses, None)
    left, not_face = choose_parts(parts, shared)
    return ObjChoice(kind, [n for i, n in enumerate(names) if i not in left],
                     {names[i]: why for i, why in left.items()},
                     {names[i]: why for i, why in not_face.items()})


def suggest_obj_choice(mesh: str | Path, kind: str,
                       poses: Mapping[str, str | Path] | None = None
                       ) -> tuple[dict[str, str], dict[str, str]]:
    """(parts to leave out, parts not face) of ``kind``, each with why: what ``new --auto``
    chooses (``choose_obj_parts``: helpers, hair cards and joint markers left out) when it
    splits the OBJ by that kind, else only the not-face suggestion for it. What File ▸ New
    from Files ticks to start with, so the dialog and the command line agree."""
    choice = choose_obj_parts(mesh, poses)
    if choice is not None and choice.kind == kind:
        return choice.left_out, choice.not_face
    return {}, suggest_obj_parts(mesh, kind, poses)


def project_from_files(mesh: str | Path, poses: Mapping[str, str | Path] | None = None,
                       diffuse: str | Path | None = None, normal: str | Path | None = None,
                       wrinkled: str | Path | None = None, name: str | None = None, *,
                       keep: Collection[str] | None = None,
                       not_face: Collection[str] | None = None, part_kind: str | None = None,
                       report: list[str] | None = None) -> Project:
    """``keep``: the parts (OBJ objects, groups, materials; glTF meshes, nodes, materials) to
    load, None for all of an OBJ or the face a glTF's morph targets show; ``not_face``: parts
    whose vertices get no wrinkles (``Project.not_face``), None for none of an OBJ or the
    suggestion for a glTF; ``part_kind``: "object", "group", "material" or "mesh" when the
    names are of that kind only (None: any); ``report``: a line for each choice made for
    the user (a glTF's face, its not-face parts, what was left out)."""
    if Path(mesh).suffix.lower() in (".glb", ".gltf", VRM_SUFFIX):
        said = report if report is not None else []
        project = load_gltf(mesh, keep, not_face, part_kind, said)
        _vrm_expressions(project, mesh, said)
        return _from_gltf(mesh, poses, diffuse, normal, wrinkled, name, project)
    if Path(mesh).suffix.lower() == ".fbx" or is_usd(mesh):  # blend shapes as key poses
        load = load_usd if is_usd(mesh) else load_fbx
        return _from_gltf(mesh, poses, diffuse, normal, wrinkled, name,
                          load(mesh, keep, not_face, part_kind, report))
    not_face = not_face or ()
    face = load_mesh(mesh, keep, part_kind)
    from studio.core.mesh.meshio import made_uvs

    made = made_uvs(face)  # a mesh without UVs: the studio made them, and says so
    if made and report is not None:
        report.append(made)
    flags = not_face_vertices(face, not_face, part_kind) if not_face else None
    if flags is not None and flags.all():
        raise MeshError(f"marking {', '.join(sorted(not_face))} as not face leaves no skin "
                        "to wrinkle", mesh)
    key_poses = []
    for pose_name, pose_path in (poses or {}).items():
        if pose_name == NEUTRAL or pose_name in (p.name for p in key_poses):
            raise MeshError(f"two key poses are named '{pose_name}'", pose_path)
        key_poses.append(load_pose(pose_path, face, pose_name))
    not_skin = flags if flags is not None and flags.any() else None
    own = obj_head_maps(mesh, face, not_skin) if not (diffuse and normal) else HeadMaps()
    if report is not None:
        report += own.lines
    face, tiles = pack_mesh(face, None if not_skin is None else ~not_skin)
    layout = tiles.layout if tiles is not None else None
    textures = FaceTextures(
        diffuse=_own_or_given(diffuse, own, "diffuse", layout, SKIN) if diffuse
        or own.diffuse is not None else plain_diffuse(),
        normal_neutral=_own_or_given(normal, own, "normal", layout, FLAT_NORMAL) if normal
        or own.normal is not None else flat_normal_map(),
        normal_wrinkled=_texture(wrinkled, layout, FLAT_NORMAL) if wrinkled
        else flat_normal_map(),
    )
    return Project(name or Path(mesh).stem, face, key_poses, textures, not_face=not_skin,
                   uv_tiles=tiles)


def _vrm_expressions(project: Project, path: str | Path, report: list[str]) -> None:
    """A VRM's expressions as the key poses and its axes (core/formats/vrm.py). A file of
    another suffix is read again only when it names a VRM extension (one renamed .glb)."""
    if project.influence.areas or project.wdv.areas:  # the studio's own file, set up already
        return
    if not check_suffix(path):
        with open(path, "rb") as file:
            head = file.read(VRM_SNIFF)
        if head[:4] == b"glTF" and len(head) >= 20:  # only the JSON chunk: not image bytes
            head = head[20:20 + int.from_bytes(head[12:16], "little")]
        if b'"VRM' not in head:
            return
    doc = _Gltf(Path(path)).doc
    info = vrm_info(doc, path)
    if info is not None:
        apply_expressions(project, info, vrm_target_names(doc), report)


def _embedded_to_atlas(textures: FaceTextures, layout: TileLayout) -> None:
    """A glTF's own maps (one image each, for the first tile) placed in the atlas."""
    def place(image: np.ndarray, fill: tuple[int, int, int]) -> np.ndarray:
        size = atlas_size(layout, max(image.shape[:2]))
        return compose_atlas({FIRST_TILE: image}, layout, np.array(fill, np.uint8), size)

    textures.diffuse = place(textures.diffuse, SKIN)
    textures.normal_neutral = place(textures.normal_neutral, FLAT_NORMAL)
    for name, image in list(textures.wrinkle_maps.items()):
        textures.set_wrinkle_map(name, place(image, FLAT_NORMAL))


def _texture(path: str | Path, layout: TileLayout | None, fill: tuple[int, int, int]
             ) -> np.ndarray:
    """A texture file, or a UDIM set of them composed into the face's atlas."""
    return load_texture(path, layout, np.array(fill, np.uint8))


def _own_or_given(given: str | Path | None, own: HeadMaps, slot: str,
                  layout: TileLayout | None, fill: tuple[int, int, int]) -> np.ndarray:
    """The map the user gave, else the one the OBJ's material names: as read for a face on
    one tile, its file's UDIM set composed into the atlas otherwise."""
    if given:
        return _texture(given, layout, fill)
    if layout is not None and not layout.trivial and slot in own.files:
        return _texture(own.files[slot], layout, fill)
    return _rgb(getattr(own, slot))


def _from_gltf(path: str | Path, poses: Mapping[str, str | Path] | None,
               diffuse: str | Path | None, normal: str | Path | None,
               wrinkled: str | Path | None, name: str | None, project: Project) -> Project:
    """A glTF brings its morph targets as key poses and its textures; files given override."""
    if project.uv_tiles is None:  # a glTF from elsewhere with UDIM coordinates
        project.mesh, project.uv_tiles = pack_mesh(project.mesh, None if project.not_face is None
                                                   else ~project.not_face)
        if project.uv_tiles is not None:  # its own images are tile 1001's
            _embedded_to_atlas(project.textures, project.uv_tiles.layout)
    layout = project.uv_tiles.layout if project.uv_tiles is not None else None
    for pose_name, pose_path in (poses or {}).items():
        if pose_name in project.pose_names:
            raise MeshError(f"two key poses are named '{pose_name}'", pose_path)
        project.poses.append(load_pose(pose_path, project.mesh, pose_name))
    textures = project.textures
    for attr, file in (("diffuse", diffuse), ("normal_neutral", normal),
                       ("normal_wrinkled", wrinkled)):
        if file:
            setattr(textures, attr, _texture(file, layout, SKIN if attr == "diffuse"
                                             else FLAT_NORMAL))
    project.textures = FaceTextures(textures.diffuse, textures.normal_neutral,  # re-checked
                                    wrinkle_maps=dict(textures.wrinkle_maps))
    if name:
        project.name = name
    return project
