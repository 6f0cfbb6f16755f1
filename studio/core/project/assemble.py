"""A new project from the user's own files: neutral mesh, key-pose meshes, texture maps.

Shared by File ▸ New from Files and the command line. Missing normal maps default to flat ones
(a face may come with no detail at rest, or no wrinkled map yet); a missing diffuse map to plain
skin colour. An OBJ's objects, groups and materials, or a glTF's meshes, nodes and materials, can
be kept in part (``keep``) and marked as not face (``not_face``: eyes, teeth — never wrinkled); a
glTF's face is found and its not-face parts suggested when they are not named. UDIM-tiled UVs
are packed into one atlas and texture sets composed into it (``uv_tiles``, ``texture_sets``).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from pathlib import Path

import numpy as np

from studio.core.animation.poses import NEUTRAL
from studio.core.files.errors import MeshError
from studio.core.mesh.meshio import load_mesh, load_pose, not_face_vertices, obj_groups
from studio.core.mesh.uv_tiles import FIRST_TILE, TileLayout, atlas_size, compose_atlas, pack_mesh
from studio.core.project.face_parts import Part, suggest_names, suggest_parts
from studio.core.project.fbx import load_fbx
from studio.core.project.gltf import load_gltf
from studio.core.project.model import Project
from studio.core.project.texture_sets import load_texture
from studio.core.wrinkles.textures import SKIN, FaceTextures, flat_normal_map, plain_diffuse

FLAT_NORMAL = (128, 128, 255)


RIGID_SAMPLE = 8  # key-pose files read to suggest parts the poses move rigidly


def suggest_not_face(names: Iterable[str]) -> list[str]:
    """The part names that look like eyes, teeth or tongue: a starting choice for the user."""
    return suggest_names(names)


def suggest_obj_parts(mesh: str | Path, kind: str,
                      poses: Mapping[str, str | Path] | None = None) -> dict[str, str]:
    """An OBJ's parts of ``kind`` (object, group or material) that look not face, each with
    why (``face_parts.suggest_parts``): by name, as a small closed shell, or — with key-pose
    files — moved rigidly by every pose that moves it (up to ``RIGID_SAMPLE`` of them, spread
    over the list: a suggestion, made while the user picks files, not a proof). A pose file
    that cannot be read is left out here (Create reports it). Never every part: the largest
    stays face."""
    face = load_mesh(mesh)
    names = [g.name for g in obj_groups(mesh) if g.kind == kind]
    paths = list((poses or {}).values())
    if len(paths) > RIGID_SAMPLE:
        paths = [paths[i] for i in np.linspace(0, len(paths) - 1, RIGID_SAMPLE).round()
                 .astype(int)]
    shapes = []
    for path in paths:
        try:
            shapes.append(load_pose(path, face).positions)
        except MeshError:
            continue
    tris = face.welded_triangles
    parts, sizes = [], []
    for name in names:
        inside = not_face_vertices(face, [name], kind)
        own = tris[inside[tris].all(axis=1)]
        vertices, local = np.unique(own, return_inverse=True)
        parts.append(Part([name], face.rest[vertices], local.reshape(-1, 3),
                          [shape[vertices] for shape in shapes]))
        sizes.append(len(own))
    flagged = {names[i]: why for i, why in suggest_parts(parts).items()}
    if names and len(flagged) == len(names):
        del flagged[names[int(np.argmax(sizes))]]
    return flagged


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
    if Path(mesh).suffix.lower() in (".glb", ".gltf"):
        return _from_gltf(mesh, poses, diffuse, normal, wrinkled, name,
                          load_gltf(mesh, keep, not_face, part_kind, report))
    if Path(mesh).suffix.lower() == ".fbx":  # blend shapes as key poses, the face found
        return _from_gltf(mesh, poses, diffuse, normal, wrinkled, name,
                          load_fbx(mesh, keep, not_face, part_kind, report))
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
    face, tiles = pack_mesh(face, None if not_skin is None else ~not_skin)
    layout = tiles.layout if tiles is not None else None
    textures = FaceTextures(
        diffuse=_texture(diffuse, layout, SKIN) if diffuse else plain_diffuse(),
        normal_neutral=_texture(normal, layout, FLAT_NORMAL) if normal else flat_normal_map(),
        normal_wrinkled=_texture(wrinkled, layout, FLAT_NORMAL) if wrinkled
        else flat_normal_map(),
    )
    return Project(name or Path(mesh).stem, face, key_poses, textures, not_face=not_skin,
                   uv_tiles=tiles)


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
