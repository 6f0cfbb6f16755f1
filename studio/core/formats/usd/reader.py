"""A project from a USD stage: its meshes read (usd/meshes.py), the face found and merged as a
glTF's is, the skin's diffuse texture as the albedo, and what was found said a line at a time.

The albedo is the texture of the face's skin material (its largest part not marked not face):
the studio has one diffuse map, so the eyes' or teeth's own textures, when they differ, are not
shown, and the report says so. UVs outside the unit square (UDIM tiles) are packed into the
atlas by the project assembly, the texture then being tile 1001's, as a glTF's is.
"""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

from studio.core.files.errors import MeshError
from studio.core.formats.gltf.face import FaceChoice, choose_face, merge_face, report_lines
from studio.core.formats.gltf.materials import _rgb
from studio.core.formats.head_maps import ImageBudget, skin_part
from studio.core.formats.polygons import unwrapped
from studio.core.formats.usd.materials import Diffuse, diffuse_image, texture_path
from studio.core.formats.usd.meshes import UsdMesh, read_meshes
from studio.core.formats.usd.setup import neutral_map as _neutral_map
from studio.core.formats.usd.setup import restore_setup, studio_mesh
from studio.core.formats.usd.stage import heard, listen, open_stage, stage_frame, usd_reason
from studio.core.project.model import Project
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map, plain_diffuse


def load_usd(path: str | Path, keep: Collection[str] | None = None,
             not_face: Collection[str] | None = None, kind: str | None = None,
             report: list[str] | None = None) -> Project:
    """A project from a USD file (``.usd``, ``.usda``, ``.usdc``, ``.usdz``): the face found
    among its meshes, blend shapes as key poses; ``keep``, ``not_face``, ``kind`` and
    ``report`` as ``load_gltf``'s. MeshError naming the file for anything wrong with it."""
    path = Path(path)
    listener = listen(path)
    from pxr import Tf

    try:
        project, lines = _project(open_stage(path), path, keep, not_face, kind)
    except Tf.ErrorException as exc:  # USD refusing a value the file declares
        raise MeshError(f"the USD file is malformed ({usd_reason(exc)})", path) from None
    except (ValueError, TypeError, IndexError, KeyError, OverflowError) as exc:
        # a structure no check foresaw: still one line naming the file
        raise MeshError(f"the USD file is malformed ({type(exc).__name__}: {exc})",
                        path) from None
    warned = heard(listener)
    if report is not None:
        report += lines + ([warned] if warned else [])
    return project


def _project(stage, path: Path, keep: Collection[str] | None,
             not_face: Collection[str] | None, kind: str | None) -> tuple[Project, list[str]]:
    """The project and the report's lines on what was found."""
    from pxr import UsdGeom

    frame = stage_frame(stage, path)
    meshes = read_meshes(stage, frame, path)
    if not meshes:
        raise MeshError("the stage holds no mesh with faces", path)
    choice = choose_face([m.node for m in meshes], keep, not_face, kind, str(path))
    merged = merge_face(choice, str(path))
    mesh = merged.mesh
    lines = [line.replace("glTF scene:", "USD stage:", 1)
             for line in report_lines(choice, merged)]
    bare = [i for i in choice.kept_meshes() if not meshes[i].has_uvs]
    if bare:  # a face mesh without UVs: the merged face unwrapped as one
        mesh, line = unwrapped(mesh, path)
        lines.append(line)
        diffuse = Diffuse(None, None)
    else:
        diffuse = _skin_diffuse(meshes, choice, merged.primitive_of_triangle, path, lines)
    if diffuse.note:
        lines.append(diffuse.note)
    lines.append(frame.line())
    textures = FaceTextures(_rgb(diffuse.image) if diffuse.image is not None
                            else plain_diffuse(), flat_normal_map(), flat_normal_map())
    project = Project(path.stem, mesh, merged.poses, textures, not_face=merged.not_face)
    own = studio_mesh(stage)
    if own is not None and len(choice.kept) == 1 and \
            len(UsdGeom.Mesh(own).GetPointsAttr().Get()) == mesh.n_welded:
        project.textures = FaceTextures(textures.diffuse, _neutral_map(own, path),
                                        flat_normal_map())
        restore_setup(own, project, path, lines)  # the studio's own export: its set-up
    if frame.authored:  # the stage says which way is up: turned to +Y, it is the studio's word
        project.view["up"] = "+y"
    return project, lines


def _skin_diffuse(meshes: list[UsdMesh], choice: FaceChoice, primitive_of_triangle,
                  path: Path, lines: list[str]) -> Diffuse:
    """The diffuse image of the face's skin material: that of its largest kept part not
    marked not face; the other materials' textures, when they differ, said to be left out."""
    materials = []
    for i, j in choice.kept:
        node = meshes[i].node
        materials.append(meshes[i].materials.materials[node.primitives[j].material])
    face = materials[skin_part(choice, primitive_of_triangle)]
    diffuse = diffuse_image(face, ImageBudget(path))
    shown = texture_path(face)
    others = sorted({m.GetPrim().GetName() for m in materials
                     if texture_path(m) not in (None, shown)})
    if others:
        lines.append(f"diffuse map: {'the texture' if shown else 'no texture'} of material "
                     f"{face.GetPrim().GetName() if face is not None else '(none)'}; the "
                     f"textures of {', '.join(others)} are not shown (one map for the face)")
    return diffuse
