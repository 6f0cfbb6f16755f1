"""glTF 2.0 in and out: faces with morph targets become projects, projects become GLB files an
engine can use.

Import: the first triangle primitive with UVs; its morph targets become key poses (named from
``extras.targetNames``); the material's base-colour and normal textures become the diffuse and
neutral normal maps; without the studio's extras, a weights animation becomes the timeline
(core/gltf_animation.py); a face without any UVs (no TEXCOORD_0) gets them from xatlas, said
in the report. Export: render vertices with UVs, NORMAL and TANGENT in the project's
tangent frame (so viewers read the normal maps as the studio does), one morph target per key pose
(with its change of normal and tangent), the textures, every wrinkled map and mask also as an
unlit KHR_materials_variants material (a picture of the map, never a skin look; viewers list
them, the Khronos validator counts them used), the timeline as a morph-weight animation, and
the studio's per-vertex data as custom vertex attributes, every one a float VEC3 (see
:func:`vertex_attributes`): ``_WRINKLE_DIR_<n>`` (each technique-2 area's directions),
``_WRINKLE_LEN_CONE_<n>`` (its lengths, painted cone angles and whether they are painted) and
``_WELD_NOTFACE_TILE`` (the welded vertex number, 1 on vertices
never wrinkled, the UDIM tile). Everything else the studio authored (masks as 16-bit PNG
images, further wrinkled maps, which map each area reveals, links, cone angles, the timeline, the
tangent frame) rides in ``extras.wrinkleStudio``, its images named (not numbered), so a file
exported here imports back with nothing lost. A re-export by another tool that drops extras and
custom attributes (Blender, with any options) still does: ``TEXCOORD_1`` and a chunk of the
neutral normal map's PNG carry the set-up (core/formats/gltf/carry.py), and the reader says what
it could not bring back. Files of the older layout (scalar ``_WELD``, ``_WRINKLE_LEN_<n>``,
``_WRINKLE_CONE_<n>``, ``_NOT_FACE``, ``_UDIM_TILE``; images by index) still open. What the
three.js module ``wrinkles.js`` (written beside every export, with the Blender script
``blender_wrinkles.py``: core/formats/blender_material.py) plays from rides in
``extras.wrinklePlayer`` (core/formats/gltf/player.py).
"""

from __future__ import annotations

import json
import struct
from collections.abc import Callable, Collection
from pathlib import Path

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import Timeline
from studio.core.files.budgets import POSES
from studio.core.files.errors import MeshError
from studio.core.files.png import encode_png
from studio.core.formats.blender_material import ship_blender_script
from studio.core.formats.gltf.animation import animation_spec, timeline_from_animation
from studio.core.formats.gltf.carry import STUDIO_UV, find_setup, studio_uvs, with_setup
from studio.core.formats.gltf.container import BIN_CHUNK, JSON_CHUNK, MAGIC, _Gltf, _item, _list
from studio.core.formats.gltf.face import (
    FaceChoice,
    MergedFace,
    choose_face,
    merge_face,
    report_lines,
    scene_groups,
)
from studio.core.formats.gltf.materials import (
    _rgb,
    atlas_textures,
    image_data,
    image_index,
    see_through,
    texture_source,
    wrinkle_image,
)
from studio.core.formats.gltf.player import PLAYER_KEY, player_extras
from studio.core.formats.gltf.renames import pose_renames, renamed_extras, used_poses
from studio.core.formats.gltf.scene import placed, placed_meshes, scene_meshes
from studio.core.formats.gltf.survived import MAP_PREFIX, MASK_PREFIX, survived_setup
from studio.core.formats.gltf_names import VERTEX_DATA, image_names, wdv_attributes
from studio.core.formats.three_module import ship_three_module
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache
from studio.core.mesh.meshio import ObjGroup, mesh_from_render_vertices
from studio.core.mesh.tangent_frames import TANGENT_FRAMES
from studio.core.mesh.unwrap import Unwrapped, unwrap
from studio.core.mesh.uv_tiles import TileLayout, UvTiles
from studio.core.project.model import Project
from studio.core.project.view_settings import saved_view
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.response import curves_from_dict, curves_to_dict
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map, plain_diffuse
from studio.core.wrinkles.wdv import WdvArea, WdvSetup

Array = np.ndarray
EXTRAS_KEY = "wrinkleStudio"
__all__ = ["BIN_CHUNK", "JSON_CHUNK", "VERTEX_DATA", "_Gltf", "gltf_parts", "image_names",
           "load_gltf", "load_weight_animation", "save_gltf", "vertex_attributes",
           "wdv_attributes"]
# The welded vertex number, 1 on vertices never wrinkled, the UDIM tile: one VEC3 per vertex
OLD_WELD = "_WELD"  # the older layout's scalar attributes (files written before the VEC3s)


def _first_occurrence(weld: Array, n_welded: int) -> Array:
    first = np.empty(n_welded, np.int64)
    first[weld[::-1]] = np.arange(len(weld))[::-1]
    return first


def load_gltf(path: str | Path, keep: Collection[str] | None = None,
              not_face: Collection[str] | None = None, kind: str | None = None,
              report: list[str] | None = None) -> Project:
    """A project from a glTF 2.0 file (.glb or .gltf).

    A file the studio wrote comes back as it was. Any other is a scene whose face is found
    (core/formats/gltf/face.py): ``keep`` and ``not_face`` name meshes, nodes or materials
    (``kind`` "mesh" or "material": that kind only) to replace the choice found or suggested;
    what was chosen and why is appended to ``report``, a line each.
    """
    path = Path(path)
    try:
        g = _Gltf(path)
        lines = report if report is not None else []
        studio = _studio_setup(g) or _survived(g, lines)
        if studio is not None:
            if keep is not None or not_face:
                raise MeshError("this file was written by Wrinkle Studio: its face is one mesh, "
                                "with no parts to keep or mark", path)
            return _load_own(g, *studio, lines)
        return _load_scene(g, keep, not_face, kind, report)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, OverflowError,
            RecursionError, struct.error) as exc:  # a structure no check above foresaw
        raise MeshError(f"the glTF file is malformed ({type(exc).__name__}: {exc})",
                        path) from None


def _written_here(g: _Gltf) -> bool:
    return _studio_setup(g) is not None


def _studio_setup(g: _Gltf) -> tuple[dict, dict[str, Array]] | None:
    """The studio's own export: (its extras, the per-welded-vertex data carried beside them),
    None for another tool's file. Its extras at the root, or its welded numbering on a
    primitive (no arrays: the attributes hold them); else, re-exported by a tool that drops
    extras (Blender), the set-up its neutral normal map carries (core/formats/gltf/carry.py)."""
    extras = g.doc.get("extras", {}).get(EXTRAS_KEY)
    if extras is not None:
        return extras, {}
    carried = _carried_setup(g)
    if carried is not None:
        return carried
    if any(isinstance(p, dict) and {VERTEX_DATA, OLD_WELD} & set(p.get("attributes", {}))
           for m in _list(g, g.doc, "meshes") if isinstance(m, dict)
           for p in m.get("primitives", [])):
        return {}, {}
    return None


def _survived(g: _Gltf, report: list[str]) -> tuple[dict, dict[str, Array]] | None:
    """The set-up rebuilt from what survived of the studio's export re-encoded by another
    tool (core/formats/gltf/survived.py), what was lost said in ``report``; None otherwise."""
    try:
        _, prim = _triangle_primitive(g)
    except MeshError:
        return None
    found = survived_setup(g, prim["attributes"])
    if found is None:
        return None
    report.append(found[1])
    return found[0], {}


def _carried_setup(g: _Gltf) -> tuple[dict, dict[str, Array]] | None:
    """The set-up the face's neutral normal map carries, None where it carries none."""
    try:
        _, prim = _triangle_primitive(g)
        info = _material(g, prim).get("normalTexture")
        data = image_data(g, texture_source(g, info)) if isinstance(info, dict) else None
    except (MeshError, KeyError, IndexError, TypeError, AttributeError):
        return None  # no map that a set-up could ride in
    if data is None:
        return None
    try:
        return find_setup(data)
    except (KeyError, TypeError, ValueError) as exc:
        raise MeshError(f"the studio's set-up in the neutral normal map is damaged ({exc})",
                        g.path) from None


def _load_scene(g: _Gltf, keep: Collection[str] | None, not_face: Collection[str] | None,
                kind: str | None, report: list[str] | None) -> Project:
    """Another tool's file: the face found among its meshes, merged, its maps in an atlas (or,
    for a face without UVs, UVs made by xatlas and plain maps: see ``_made_uvs``)."""
    choice = choose_face(scene_meshes(g), keep, not_face, kind, str(g.path))
    if choice.suggest:
        choice.see_through = see_through(g, choice)
    merged = merge_face(choice, str(g.path))
    made = _made_uvs(g, choice, merged)
    said: list[str] = []  # textures missing or unreadable
    if made is None:
        mesh, tiles, textures = atlas_textures(g, choice, merged, said)
    else:
        mesh, tiles = made.mesh, None
        textures = FaceTextures(plain_diffuse(), flat_normal_map(), flat_normal_map())
    project = Project(g.path.stem, mesh, merged.poses, textures, not_face=merged.not_face,
                      uv_tiles=tiles)
    animated = next((choice.meshes[i] for i in choice.kept_meshes()
                     if choice.meshes[i].node is not None and choice.meshes[i].target_names),
                    None)
    if animated is not None and merged.poses:
        try:
            timeline = timeline_from_animation(g.doc, animated.node, animated.target_names,
                                               g.accessor, g.path)
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise MeshError(f"the morph-weight animation is malformed ({exc})",
                            g.path) from None
        if timeline is not None:
            project.timeline = timeline
    if report is not None:
        report += report_lines(choice, merged) + said
        if made is not None:
            report.append(made.report(g.path))
    return project


def _made_uvs(g: _Gltf, choice: FaceChoice, merged: MergedFace) -> Unwrapped | None:
    """The merged face unwrapped by xatlas when none of its primitives has UVs, else None.

    The face is unwrapped once, merged (as an FBX's is): its morph targets are key poses over
    the welded vertices (core/formats/gltf/face.py), and xatlas keeps the welded vertices and
    the triangles in their order, so the poses and the not-face flags still fit. A face of
    which only some primitives have UVs is refused, naming those that have none: made UVs
    beside given ones would put both in one unit square, and the given maps would no longer
    line up with either."""
    bare = [k for k, (i, j) in enumerate(choice.kept)
            if not choice.meshes[i].primitives[j].has_uvs]
    if not bare:
        return None

    def label(k: int) -> str:
        i, j = choice.kept[k]
        node, prim = choice.meshes[i], choice.meshes[i].primitives[j]
        return (node.label if len(node.primitives) == 1 or not prim.material_name
                else f"{node.label}/{prim.material_name}")

    if len(bare) < len(choice.kept):
        without = ", ".join(dict.fromkeys(label(k) for k in bare))
        given = ", ".join(dict.fromkeys(label(k) for k in range(len(choice.kept))
                                        if k not in bare))
        raise MeshError(f"the face mixes meshes without texture coordinates (TEXCOORD_0): "
                        f"{without}, and with them: {given}; export them all with UVs (or all "
                        "without, for the studio to make them), or keep only some (--keep)",
                        g.path)
    mesh = merged.mesh
    return unwrap(mesh.rest, mesh.welded_triangles, str(g.path))


def _load_own(g: _Gltf, extras: dict, carried: dict[str, Array], report: list[str]
              ) -> Project:
    """The studio's own file; ``carried``: the per-welded-vertex data a re-export by another
    tool kept in the neutral normal map, where the custom attributes were dropped. What could
    not come back is appended to ``report``, a line each."""
    path = g.path
    mesh_spec, prim = _triangle_primitive(g)
    attrs = prim["attributes"]
    local = g.typed(attrs["POSITION"], ("VEC3",), "POSITION")
    matrix = _node_matrix(g, mesh_spec, report)
    positions = placed(g, local, matrix, "the mesh's positions", True)
    uvs = g.typed(attrs["TEXCOORD_0"], ("VEC2",), "TEXCOORD_0")
    if len(uvs) != len(positions):
        raise MeshError(f"TEXCOORD_0 has {len(uvs)} values, POSITION has {len(positions)}", path)
    uvs = uvs[:, :2] * [1.0, -1.0] + [0.0, 1.0]  # glTF v points down
    if "indices" in prim:
        indices = g.typed(prim["indices"], ("SCALAR",), "the indices", integer=True)
        if len(indices) % 3 or indices.max() >= len(positions):
            raise MeshError(f"the indices are not triangles over the {len(positions)} vertices "
                            "(a count not divisible by 3, or a vertex that does not exist)", path)
        triangles = indices.astype(np.int64).reshape(-1, 3)
    else:
        if len(positions) % 3:
            raise MeshError(f"{len(positions)} vertices without indices are not triangles", path)
        triangles = np.arange(len(positions)).reshape(-1, 3)
    weld_attribute = next((a for a in (VERTEX_DATA, OLD_WELD, STUDIO_UV) if a in attrs), None)
    if weld_attribute:  # written by the studio: keep its welded numbering exactly
        mesh = _mesh_with_weld(g, positions, triangles, uvs,
                               g.accessor(attrs[weld_attribute])[:, 0])
    else:
        mesh = mesh_from_render_vertices(path, positions, triangles, uvs)
        if carried:
            report.append("the studio's welding was lost with the second UV map "
                          f"({STUDIO_UV}): the vertices are welded by position")
    first = _first_occurrence(mesh.weld, mesh.n_welded)
    names = (mesh_spec.get("extras", {}).get("targetNames")
             or prim.get("extras", {}).get("targetNames") or [])
    targets = prim.get("targets", [])
    POSES.check(len(targets), "the morph target count", path, MeshError)
    poses = []
    for i, target in enumerate(targets):
        if "POSITION" not in target:
            continue
        name = str(names[i]) if i < len(names) else f"target_{i}"
        offsets = g.typed(target["POSITION"], ("VEC3",), f"morph target '{name}'")
        if len(offsets) != len(local):  # numpy would broadcast a single offset silently
            raise MeshError(f"morph target '{name}' moves {len(offsets)} vertices, the mesh has "
                            f"{len(positions)}", path)
        poses.append(KeyPose(name, placed(g, local + offsets, matrix, f"morph target '{name}'",
                                          True)[first]))
    material = _material(g, prim)
    pbr = material.get("pbrMetallicRoughness", {})
    textures = FaceTextures(
        diffuse=_rgb(g.texture_image(pbr.get("baseColorTexture")), plain_diffuse()),
        normal_neutral=_rgb(g.texture_image(material.get("normalTexture")), flat_normal_map()),
        normal_wrinkled=_rgb(wrinkle_image(g, material), flat_normal_map()))
    project = Project(str(extras.get("name", path.stem)), mesh, poses, textures)
    if carried:
        report.append("the studio's set-up came back from the neutral normal map: another "
                      "tool re-exported this file without its extras")
    try:
        extras, lines = renamed_extras(extras, pose_renames(
            extras.get("poses"), [p.name for p in poses], used_poses(extras)))
        report += lines
        read_studio_extras(g, project, extras, attrs, first, carried, report)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise MeshError(f"the studio data in extras.{EXTRAS_KEY} is malformed ({exc})",
                        path) from None
    if "timeline" not in extras:  # another tool's file: its weights animation, if any
        try:
            timeline = _animated_timeline(g, mesh_spec, [p.name for p in poses])
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise MeshError(f"the morph-weight animation is malformed ({exc})", path) from None
        if timeline is not None:
            project.timeline = timeline
    return project


def _node_matrix(g: _Gltf, mesh_spec: dict, report: list[str]) -> Array:
    """The world transform of the first node showing the face: identity in the studio's own
    export; moved, turned or scaled by a person in another tool and exported without applying
    it, which the face takes on (as Blender's Apply > All Transforms would), said in a line."""
    index = next(i for i, m in enumerate(_list(g, g.doc, "meshes")) if m is mesh_spec)
    matrix = next((m for _, node, m in placed_meshes(g) if node.get("mesh") == index),
                  np.eye(4))
    if not np.allclose(matrix, np.eye(4), rtol=0, atol=1e-9):
        report.append("the face was moved, turned or scaled in another tool without applying "
                      "it: its node's transform is applied to the vertices and key poses")
    return matrix


def _animated_timeline(g: _Gltf, mesh_spec: dict, pose_names: list[str]) -> Timeline | None:
    """The timeline the weights animation of the mesh's node plays (first node using it)."""
    meshes = _list(g, g.doc, "meshes")
    index = next(i for i, m in enumerate(meshes) if m is mesh_spec)
    node = next((i for i, n in enumerate(_list(g, g.doc, "nodes"))
                 if isinstance(n, dict) and n.get("mesh") == index), None)
    if node is None or not pose_names:
        return None
    return timeline_from_animation(g.doc, node, pose_names, g.accessor, g.path)


def _mesh_with_weld(g: _Gltf, positions: Array, triangles: Array, uvs: Array,
                    weld_values: Array) -> FaceMesh:
    weld = weld_values.astype(np.int64)
    if (weld != weld_values).any() or weld.min() < 0 or weld.max() >= len(weld):
        raise MeshError("the _WELD attribute does not hold vertex numbers", g.path)
    n = int(weld.max()) + 1
    first = _first_occurrence(weld, n)
    if not np.array_equal(positions[first][weld], positions):
        raise MeshError("vertices welded by _WELD are not at one position", g.path)
    return FaceMesh(positions[first], triangles, uvs, weld, str(g.path))


def _triangle_primitive(g: _Gltf) -> tuple[dict, dict]:
    for mesh in g.doc.get("meshes", []):
        for prim in mesh.get("primitives", []):
            attrs = prim.get("attributes", {})
            if prim.get("mode", 4) == 4 and "POSITION" in attrs and "TEXCOORD_0" in attrs:
                return mesh, prim
    if any("POSITION" in p.get("attributes", {}) for m in g.doc.get("meshes", [])
           for p in m.get("primitives", [])):
        raise MeshError("the mesh has no texture coordinates (TEXCOORD_0)", g.path)
    raise MeshError("the file holds no triangle mesh", g.path)


def _material(g: _Gltf, prim: dict) -> dict:
    try:
        return g.doc["materials"][prim["material"]] if "material" in prim else {}
    except (KeyError, IndexError, TypeError):
        raise MeshError("the mesh refers to a material that does not exist", g.path) from None


def read_studio_extras(g: _Gltf | None, project: Project, extras: dict, attrs: dict,
                       first: Array, carried: dict[str, Array], report: list[str],
                       image: Callable[[object], Array] | None = None) -> None:
    """The set-up from the extras (images by name, or by index in older files) and the
    per-vertex data from the attributes, else from ``carried``. ``image`` reads an image the
    extras name (default: the glTF's own); the USD reader gives its package's, with no glTF
    (``g`` None) and no attributes."""
    if image is None:
        def image(ref: object) -> Array:
            return g.image(image_index(g, ref))
    areas = []
    for spec in extras.get("influence", {}).get("areas", []):
        mask = _unit_mask(image(spec["image"]))
        areas.append(InfluenceArea(spec["name"], mask, tuple(spec.get("colour", (255, 128, 0))),
                                   float(spec.get("activation", 0.0)),
                                   bool(spec.get("visible", True)),
                                   str(spec.get("wrinkle_map", ""))))
    influence = extras.get("influence", {})
    project.influence = InfluenceSetup(areas, influence.get("links", {}),
                                       curves_from_dict(influence.get("curves", {})))
    if extras.get("wrinkle_maps"):
        tex = project.textures
        maps = {str(m["name"]): _rgb(image(m["image"]), tex.normal_wrinkled)
                for m in extras["wrinkle_maps"]}
        project.textures = FaceTextures(tex.diffuse, tex.normal_neutral, wrinkle_maps=maps)
    n_welded = len(first)
    not_face, tiles = _vertex_data(g, attrs)
    if not_face is not None:
        project.not_face = not_face[first] > 0.5
    elif _fits(carried.get("not_face"), n_welded):
        project.not_face = carried["not_face"] > 0
    elif carried and "not_face" in carried:
        report.append("the parts marked not face were lost with the studio's welding")
    if "uv_tiles" in extras and tiles is not None:
        project.uv_tiles = UvTiles(TileLayout.from_dict(extras["uv_tiles"]),
                                   np.rint(tiles).astype(np.int16))
    elif "uv_tiles" in extras:
        report.append("the UDIM tiles are not restored: the face stays on its atlas of them")
    wdv = extras.get("wdv", {})
    wdv_areas = []
    for n, spec in enumerate(wdv.get("areas", [])):
        if spec["pose"] is None:  # its key pose is gone (core/formats/gltf/renames.py)
            continue
        data = _wdv_data(g, attrs, n, first, carried)
        if data is None:
            report.append(f"technique-2 area '{spec['name']}' was lost with the custom vertex "
                          "attributes: rebuild it (Auto Setup)")
            continue
        dirs, lengths, cones = data
        wdv_areas.append(WdvArea(spec["name"], spec["pose"], dirs, lengths,
                                 tuple(spec.get("colour", (0, 170, 255))),
                                 float(spec.get("cone_angle_deg", 20.0)),
                                 bool(spec.get("enabled", True)),
                                 str(spec.get("wrinkle_map", "")), cones))
    project.wdv = WdvSetup(wdv_areas, float(wdv.get("expression_factor", 1.0)),
                           bool(wdv.get("scale_free", True)))
    if "timeline" in extras:
        project.timeline = Timeline.from_dict(extras["timeline"])
    if extras.get("tangent_frame") in TANGENT_FRAMES:  # the frame its maps were made for
        project.view["view"] = {"tangent_frame": extras["tangent_frame"]}


def _unit_mask(image: Array) -> Array:
    """A mask image as float32 in [0, 1]: the studio writes 16-bit grey, another tool's
    re-encoding may hold 8-bit grey or RGB (its first channel)."""
    if image.ndim == 3:
        image = image[..., 0]
    return image.astype(np.float32) / float(np.iinfo(image.dtype).max)


def _vertex_data(g: _Gltf, attrs: dict) -> tuple[Array | None, Array | None]:
    """(not-face values, UDIM tiles) per render vertex, each None where the file has none:
    the VEC3's columns (a not-face column of zeros is no marking), or the older scalars; the
    tiles else from the studio's second UV map."""
    if VERTEX_DATA in attrs:
        data = g.accessor(attrs[VERTEX_DATA])
        return (data[:, 1] if (data[:, 1] > 0.5).any() else None), data[:, 2]
    not_face, tiles = (g.accessor(attrs[name])[:, 0] if name in attrs else None
                       for name in ("_NOT_FACE", "_UDIM_TILE"))
    if tiles is None and STUDIO_UV in attrs:
        tiles = g.accessor(attrs[STUDIO_UV])[:, 1]
    return not_face, tiles


def _fits(array: Array | None, n_welded: int) -> bool:
    return array is not None and len(array) == n_welded


def _wdv_data(g: _Gltf, attrs: dict, n: int, first: Array, carried: dict[str, Array]
              ) -> tuple[Array, Array, Array | None] | None:
    """Area ``n``'s directions, lengths and painted cone angles (None: not painted) per welded
    vertex: from its attributes (this layout's or the older one's), else from ``carried``;
    None when neither holds them."""
    directions, sizes = wdv_attributes(n)
    if directions in attrs and sizes in attrs:
        data = g.accessor(attrs[sizes])[first]
        return (g.accessor(attrs[directions])[first], data[:, 0],
                data[:, 1] if (data[:, 2] > 0.5).any() else None)
    cones, lengths = f"_WRINKLE_CONE_{n}", f"_WRINKLE_LEN_{n}"
    if directions in attrs and lengths in attrs:
        return (g.accessor(attrs[directions])[first], g.accessor(attrs[lengths])[first, 0],
                g.accessor(attrs[cones])[first, 0] if cones in attrs else None)
    key = f"wdv{n}."
    if not all(_fits(carried.get(key + k), len(first)) for k in ("directions", "lengths")):
        return None
    return (carried[key + "directions"], carried[key + "lengths"],
            carried.get(key + "cones"))


def carried_arrays(project: Project) -> dict[str, Array]:
    """What the custom attributes hold, per welded vertex, for the neutral normal map to carry
    through a tool that drops them (core/formats/gltf/carry.py)."""
    out: dict[str, Array] = {}
    if project.not_face is not None:
        out["not_face"] = project.not_face
    for n, area in enumerate(project.wdv.areas):
        out[f"wdv{n}.directions"] = area.directions
        out[f"wdv{n}.lengths"] = area.lengths
        if area.cone_angles_deg is not None:
            out[f"wdv{n}.cones"] = area.cone_angles_deg
    return out


# --- writing ---------------------------------------------------------------------------------
class _Builder:
    """Accumulates buffer views and accessors for one GLB binary chunk."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def view(self, data: bytes, target: int | None = None) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.blob += data
        self.views.append(view)
        return len(self.views) - 1

    def accessor(self, array: Array, kind: str, bounds: bool = False,
                 indices: bool = False, vertex: bool = True) -> int:
        """A float accessor (uint32 for ``indices``) on its own buffer view; ``vertex`` False
        for data that is not a vertex attribute (animation samplers): such a view must not
        declare the vertex-buffer target."""
        array = np.ascontiguousarray(array, np.uint32 if indices else np.float32)
        target = 34963 if indices else 34962 if vertex else None
        acc = {"bufferView": self.view(array.tobytes(), target),
               "componentType": 5125 if indices else 5126, "count": len(array), "type": kind}
        if bounds:
            flat = array.reshape(len(array), -1)
            acc["min"] = flat.min(axis=0).tolist()
            acc["max"] = flat.max(axis=0).tolist()
        self.accessors.append(acc)
        return len(self.accessors) - 1


def _surface_attributes(project: Project, b: _Builder, frame: str) -> tuple[dict, list[dict]]:
    """NORMAL and TANGENT (VEC4, w = ±1) at rest in the project's tangent frame, and each key
    pose's change of both as morph-target deltas, so a viewer shades the posed face (and reads
    the normal maps) as the studio does instead of generating a frame of its own."""
    mesh = project.mesh
    cache = DeformCache(mesh, frame)
    rest = cache.update(mesh.rest).copy()
    attributes = {"NORMAL": b.accessor(rest[:, 3:6], "VEC3"),
                  "TANGENT": b.accessor(rest[:, 6:10], "VEC4")}
    deltas = []
    for pose in project.poses:
        posed = cache.update(pose.positions)
        deltas.append({"NORMAL": b.accessor(posed[:, 3:6] - rest[:, 3:6], "VEC3"),
                       "TANGENT": b.accessor(posed[:, 6:9] - rest[:, 6:9], "VEC3")})
    return attributes, deltas


def _variants(textures: list[dict], wrinkle_maps: list[dict], masks: list[tuple[str, int]]
              ) -> tuple[list[dict], dict, dict]:
    """Each wrinkled map and each influence mask shown as a picture on the face (unlit, as
    Substance Painter shows a channel), offered as KHR_materials_variants: a viewer that knows
    the extension lists them by name, the glTF validator counts their textures and images as
    used, and another tool's re-export keeps the images (core/formats/gltf/survived.py reads
    them back by these materials' names). Never a skin look with a whole wrinkled map as its
    normal map: that would show every wrinkle at once, unmasked, which the face never does
    (the wrinkles play through ``wrinkles.js``). Returns the extra materials, the root
    extension and the primitive's mappings (materials numbered after the skin, 0)."""
    def texture(image: int) -> int:
        """The texture of an image, made if no texture shows it yet."""
        for i, spec in enumerate(textures):
            if spec["source"] == image:
                return i
        textures.append({"source": image})
        return len(textures) - 1

    shown = [(f"{MAP_PREFIX}{spec['name']}", spec["image"]) for spec in wrinkle_maps]
    shown += [(f"{MASK_PREFIX}{name}", image) for name, image in masks]
    materials = [{"name": name, "extensions": {"KHR_materials_unlit": {}},
                  "pbrMetallicRoughness": {"baseColorTexture": {"index": texture(image)},
                                           "metallicFactor": 0.0}}
                 for name, image in shown]
    root = {"variants": [{"name": name} for name, _ in shown]}
    mappings = {"mappings": [{"material": 1 + i, "variants": [i]} for i in range(len(shown))]}
    return materials, root, mappings


def vertex_attributes(project: Project) -> dict[str, Array]:
    """The studio's custom vertex attributes, name → (render vertices, 3) float32.

    Why all VEC3: Blender's glTF importer (4.2 to 5.1, glTF-Blender-IO #2658) fails on a
    primitive whose custom ``_`` attributes differ in type, so every scalar rides in a column of
    a VEC3. The welded vertex number is exact in float32 below 2**24 vertices; the UDIM tile is
    the atlas cell's, so the original UVs come back; a painted cone angle of 0 is the area's.
    """
    weld = project.mesh.weld
    n = len(weld)
    data = np.zeros((n, 3), np.float32)
    data[:, 0] = weld
    if project.not_face is not None:
        data[:, 1] = project.not_face[weld]
    if project.uv_tiles is not None:
        data[:, 2] = project.uv_tiles.vertex_tile
    out = {VERTEX_DATA: data}
    for k, area in enumerate(project.wdv.areas):
        directions, sizes = wdv_attributes(k)
        size = np.zeros((n, 3), np.float32)
        size[:, 0] = area.lengths[weld]
        if area.cone_angles_deg is not None:
            size[:, 1] = area.cone_angles_deg[weld]
            size[:, 2] = 1.0
        out[directions] = area.directions[weld]
        out[sizes] = size
    return out


def _studio_extras(project: Project, frame: str, map_images: list[str],
                   mask_images: list[str]) -> dict:
    """``extras.wrinkleStudio``: everything the studio authored that glTF has no place for,
    each image named (``map_images``: the wrinkled maps', ``mask_images``: the masks')."""
    tex = project.textures
    return {
        "name": project.name, "timeline": project.timeline.to_dict(), "tangent_frame": frame,
        "poses": [p.name for p in project.poses],  # their order: renamed keys are found by it
        "influence": {"links": project.influence.links,
                      "curves": curves_to_dict(project.influence.curves), "areas": [
            {"name": a.name, "colour": list(a.colour), "activation": a.activation,
             "visible": a.visible, "wrinkle_map": a.wrinkle_map, "image": image}
            for a, image in zip(project.influence.areas, mask_images, strict=True)]},
        "wrinkle_maps": [{"name": name, "image": image}
                         for name, image in zip(tex.wrinkle_map_names, map_images, strict=True)],
        **({"uv_tiles": project.uv_tiles.layout.to_dict()} if project.uv_tiles else {}),
        "wdv": {"expression_factor": project.wdv.expression_factor,
                "scale_free": project.wdv.scale_free,
                "areas": [{"name": a.name, "pose": a.pose, "colour": list(a.colour),
                           "cone_angle_deg": a.cone_angle_deg, "enabled": a.enabled,
                           "wrinkle_map": a.wrinkle_map}
                          for a in project.wdv.areas]}}


def save_gltf(project: Project, path: str | Path, tangent_frame: str | None = None
              ) -> list[Path]:
    """Write the project as a binary glTF (.glb); returns the files written beside it (the
    three.js module, its example page and the Blender script), for the user to be told.

    ``tangent_frame`` (default: the one the project's view settings name) is the frame the
    TANGENT attribute is written in: the one the normal maps were made for.
    """
    path = Path(path)
    frame = tangent_frame or saved_view(project.view).tangent_frame
    mesh, weld = project.mesh, project.mesh.weld
    b = _Builder()
    rest = mesh.rest[weld]
    attributes = {
        "POSITION": b.accessor(rest, "VEC3", bounds=True),
        "TEXCOORD_0": b.accessor(mesh.uvs * [1.0, -1.0] + [0.0, 1.0], "VEC2"),
    }
    surface, surface_deltas = _surface_attributes(project, b, frame)
    attributes.update(surface)
    for name, data in vertex_attributes(project).items():
        attributes[name] = b.accessor(data, "VEC3")
    targets = [{"POSITION": b.accessor(pose.positions[weld] - rest, "VEC3", bounds=True),
                **deltas} for pose, deltas in zip(project.poses, surface_deltas, strict=True)]
    tiles = None if project.uv_tiles is None else project.uv_tiles.vertex_tile
    attributes[STUDIO_UV] = b.accessor(studio_uvs(weld, tiles), "VEC2")
    tex = project.textures
    map_images, mask_images = image_names(project)
    studio = _studio_extras(project, frame, map_images, mask_images)
    images: list[dict] = []

    def image(data: Array | bytes, name: str) -> int:
        png = data if isinstance(data, bytes) else encode_png(data)
        images.append({"bufferView": b.view(png), "mimeType": "image/png", "name": name})
        return len(images) - 1

    neutral = with_setup(encode_png(tex.normal_neutral), studio, carried_arrays(project))
    textures = [{"source": image(tex.diffuse, "diffuse")},
                {"source": image(neutral, "normal_neutral")}]
    maps = [image(im, name) for im, name in zip(tex.wrinkle_maps.values(), map_images,
                                                strict=True)]
    textures.append({"source": maps[0]})
    masks = [(a.name, image(np.round(a.mask * 65535.0).astype(np.uint16), name))
             for a, name in zip(project.influence.areas, mask_images, strict=True)]
    skin = {"name": "skin", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.7},
        "normalTexture": {"index": 1}}
    variant_materials, variants, mappings = _variants(
        textures, [{"name": n, "image": i} for n, i in zip(tex.wrinkle_map_names, maps,
                                                            strict=True)], masks)
    primitive = {"attributes": attributes, "indices": b.accessor(mesh.triangles.ravel(),
                                                                  "SCALAR", indices=True),
                 "material": 0, "mode": 4,
                 "extensions": {"KHR_materials_variants": mappings}}
    if targets:
        primitive["targets"] = targets
    animation = animation_spec(project, b)
    used = ["KHR_materials_variants", "KHR_materials_unlit"]
    doc = {
        "asset": {"version": "2.0", "generator": "Wrinkle Studio"},
        "extensionsUsed": used,
        "extensions": {"KHR_materials_variants": variants},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": project.name}],
        "meshes": [{"name": project.name, "primitives": [primitive],
                    "weights": [0.0] * len(targets),
                    "extras": {"targetNames": [p.name for p in project.poses]}}],
        # the index for readers of the JSON, the image's name for after another tool's
        # re-export (which keeps names and renumbers textures)
        "materials": [{**skin, "extras": {"wrinkleNormalTexture": {
            "index": 2, "image": map_images[0]}}}, *variant_materials],
        "textures": textures, "images": images,
        **({"animations": [animation]} if animation else {}),
        "accessors": b.accessors, "bufferViews": b.views,
        "extras": {EXTRAS_KEY: studio},
    }
    doc["extras"][PLAYER_KEY] = player_extras(project, b.view, map_images, mask_images)
    doc["buffers"] = [{"byteLength": len(b.blob)}]
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    blob = bytes(b.blob) + b"\0" * (-len(b.blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    data = (struct.pack("<4sII", MAGIC, 2, total) + struct.pack("<II", len(text), JSON_CHUNK)
            + text + struct.pack("<II", len(blob), BIN_CHUNK) + blob)
    from studio.core.files.atomic_write import write_atomic

    write_atomic(path, data, MeshError, what="file")
    beside = ship_three_module(path)
    beside.append(ship_blender_script(project, path))  # techniques 1 and 2 in Blender
    return beside


def load_weight_animation(path: str | Path) -> tuple[list[str], Array, Array]:
    """The first animation channel of a glTF file that drives a mesh's morph-target weights:
    (the targets' names from ``extras.targetNames``, key times in seconds, (keys, targets)
    weights). A STEP channel comes back as linear keys that hold each value until just before
    the next; a CUBICSPLINE one is refused (its tangents would be lost)."""
    path = Path(path)
    try:
        return _weight_animation(_Gltf(path))
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, OverflowError,
            RecursionError, struct.error) as exc:
        raise MeshError(f"the glTF file is malformed ({type(exc).__name__}: {exc})",
                        path) from None


def _weight_animation(g: _Gltf) -> tuple[list[str], Array, Array]:
    for animation in _list(g, g.doc, "animations"):
        samplers = animation.get("samplers", [])
        for channel in animation.get("channels", []):
            target = channel.get("target", {})
            if target.get("path") != "weights" or "node" not in target:
                continue
            mesh = _item(g, "meshes", _item(g, "nodes", target["node"]).get("mesh"))
            count = len(mesh["primitives"][0].get("targets", []))
            names = [str(n) for n in mesh.get("extras", {}).get("targetNames", [])]
            if count == 0 or len(names) != count:
                raise MeshError(f"the animated mesh '{mesh.get('name', '')}' does not name its "
                                f"{count} morph targets in extras.targetNames", g.path)
            sampler = samplers[channel["sampler"]]
            mode = sampler.get("interpolation", "LINEAR")
            if mode not in ("LINEAR", "STEP"):
                raise MeshError(f"the weights animation is {mode}; re-export it sampled "
                                "(LINEAR)", g.path)
            times = g.typed(sampler["input"], ("SCALAR",), "the animation's key times")[:, 0]
            values = g.typed(sampler["output"], ("SCALAR",), "the animation's weights")[:, 0]
            if len(values) != len(times) * count:
                raise MeshError(f"the weights animation has {len(values)} values for "
                                f"{len(times)} keys of {count} targets", g.path)
            values = values.reshape(len(times), count)
            if mode == "STEP" and len(times) > 1:  # hold each value until just before the next
                gap = np.minimum(np.diff(times), 1e-3) * 1e-3
                times = np.insert(times, np.arange(1, len(times)), times[1:] - gap)
                values = np.repeat(values, 2, axis=0)[:-1]
            return names, times, values
    raise MeshError("no animation of morph-target weights in the glTF file", g.path)


def gltf_parts(path: str | Path) -> tuple[list[ObjGroup], set[str], set[str]]:
    """A glTF scene's meshes and materials for a parts table (kinds "mesh" and "material",
    with triangle counts), the names the face found keeps and those suggested as not face."""
    path = Path(path)
    try:
        g = _Gltf(path)
        if _written_here(g):
            return [], set(), set()
        choice = choose_face(scene_meshes(g), None, None, None, str(path))
        merge_face(choice, str(path))
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, OverflowError,
            RecursionError, struct.error) as exc:
        raise MeshError(f"the glTF file is malformed ({type(exc).__name__}: {exc})",
                        path) from None
    keep: set[str] = set()
    flagged: dict[str, list[bool]] = {}
    for i, j in choice.kept:
        node, prim = choice.meshes[i], choice.meshes[i].primitives[j]
        marked = (i, j) in choice.not_face
        for name in (node.label, prim.material_name):
            if name:
                keep.add(name)
                flagged.setdefault(name, []).append(marked)
    return scene_groups(choice.meshes), keep, {n for n, f in flagged.items() if all(f)}
