"""Blender's glTF importer (and exporter) run over files, as a user of stock Blender would.

    python scripts/blender_gltf.py IN.glb [IN2.glb ...]
    python scripts/blender_gltf.py IN.glb --export OUT.glb [--extras] [--rename OLD=NEW]
        [--images JPEG|WEBP] [--move]

Needs the ``bpy`` package (the test extra). For each file it imports into an empty scene and
prints one JSON line (after ``MARK``): whether the import worked (and Blender's error if not),
each mesh object's vertices, shape keys, UV layers, materials with their image names, custom
attributes and the scene's actions; with ``--keys`` also every shape key's coordinates (in glTF
axes, Y up), each loop's UV and each shape key's keyframe values. With ``--export`` it then
writes what it imported back out with Blender's default glTF options (``--extras``: with custom
properties too). The edits a person makes before exporting: ``--rename`` a shape key,
``--images`` written as JPEG or WebP (the exporter's Images option), ``--move`` the object
(moved, turned and scaled, not applied).

Why a script run in a subprocess: importing bpy loads all of Blender into the process (and a
crash inside it must not take the test run with it), and each file wants a fresh scene.
"""

from __future__ import annotations

import argparse
import json
import sys
import traceback

# each report on a line of its own, after this: Blender prints its own lines (without a last
# newline, at times) to the same stdout
MARK = "BLENDER_GLTF_REPORT "


def emit(report: dict) -> None:
    print("\n" + MARK + json.dumps(report), flush=True)


def _materials(obj) -> list[dict]:
    out = []
    for slot in obj.material_slots:
        material = slot.material
        if material is None:
            continue
        images = sorted(node.image.name for node in (material.node_tree.nodes
                                                     if material.node_tree else [])
                        if node.type == "TEX_IMAGE" and node.image is not None)
        out.append({"name": material.name, "images": images})
    return out


def _mesh_report(obj, keys: bool) -> dict:
    import numpy as np

    mesh = obj.data
    n = len(mesh.vertices)
    report = {"name": obj.name, "mesh": mesh.name, "vertices": n,
              "polygons": len(mesh.polygons), "materials": _materials(obj),
              "attributes": sorted(a.name for a in mesh.attributes if a.name.startswith("_")),
              "uv_layers": [layer.name for layer in mesh.uv_layers], "shape_keys": []}
    if mesh.uv_layers:
        loops = np.zeros(len(mesh.loops), np.int64)
        mesh.loops.foreach_get("vertex_index", loops)
        uvs = np.zeros(2 * len(mesh.loops), np.float32)
        mesh.uv_layers[0].data.foreach_get("uv", uvs)
        report["loop_vertices"] = loops.tolist() if keys else None
        report["loop_uvs"] = uvs.reshape(-1, 2).tolist() if keys else None
    if mesh.shape_keys is not None:
        for block in mesh.shape_keys.key_blocks:
            entry = {"name": block.name, "value": block.value}
            if keys:
                co = np.zeros(3 * n, np.float32)
                block.data.foreach_get("co", co)
                x, y, z = co.reshape(-1, 3).T  # Blender's Z up back to glTF's Y up
                entry["co"] = np.stack([x, z, -y], axis=1).tolist()
            report["shape_keys"].append(entry)
    return report


def import_file(path: str, keys: bool) -> dict:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        result = bpy.ops.import_scene.gltf(filepath=path)
    except Exception as exc:  # Blender's importer raises what it meets; report it, go on
        return {"file": path, "ok": False, "error": f"{type(exc).__name__}: {exc}",
                "trace": traceback.format_exc()[-2000:]}
    meshes = [_mesh_report(o, keys) for o in bpy.context.scene.objects if o.type == "MESH"]
    return {"file": path, "ok": "FINISHED" in result, "meshes": meshes,
            "actions": [a.name for a in bpy.data.actions],
            "keyed": _keyed_values(bpy) if keys else None,
            "images": sorted(i.name for i in bpy.data.images)}


def _keyed_values(bpy) -> dict[str, list[float]]:
    """Each shape key's keyframe values in the imported actions, in frame order."""
    out = {}
    for action in bpy.data.actions:
        curves = getattr(action, "fcurves", None)
        if curves is None:  # Blender 5's layered actions: the curves live in channelbags
            curves = [c for layer in action.layers for strip in layer.strips
                      for bag in strip.channelbags for c in bag.fcurves]
        for curve in curves:
            path = curve.data_path
            if path.startswith('key_blocks["') and path.endswith('"].value'):
                points = sorted((k.co[0], k.co[1]) for k in curve.keyframe_points)
                out[path[len('key_blocks["'):-len('"].value')]] = [v for _, v in points]
    return out


def edit(args: argparse.Namespace) -> None:
    """What a person does in Blender between the import and the export."""
    import bpy

    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    for rename in args.rename:
        old, new = rename.split("=", 1)
        for obj in meshes:
            keys = obj.data.shape_keys
            if keys is not None and old in keys.key_blocks:
                keys.key_blocks[old].name = new
    if args.move:
        for obj in meshes:
            obj.location = (0.05, -0.02, 0.1)
            obj.rotation_mode = "XYZ"  # the importer leaves quaternions on
            obj.rotation_euler = (0.0, 0.0, 0.3)
            obj.scale = (1.5, 1.5, 1.5)


def export_file(path: str, extras: bool, images: str) -> None:
    import bpy

    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_extras=extras,
                              export_image_format=images)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="+")
    parser.add_argument("--keys", action="store_true", help="report coordinates and UVs")
    parser.add_argument("--export", help="write the (one) imported file back out with "
                                         "Blender's default glTF export options")
    parser.add_argument("--extras", action="store_true",
                        help="with --export: include custom properties (glTF extras)")
    parser.add_argument("--rename", action="append", default=[], metavar="OLD=NEW",
                        help="with --export: rename a shape key first")
    parser.add_argument("--images", choices=("AUTO", "JPEG", "WEBP"), default="AUTO",
                        help="with --export: the exporter's Images option")
    parser.add_argument("--move", action="store_true",
                        help="with --export: move, turn and scale the object, not applied")
    args = parser.parse_args()
    import bpy

    emit({"bpy": bpy.app.version_string})
    for path in args.files:
        report = import_file(path, args.keys)
        emit(report)
        if args.export and report["ok"]:
            edit(args)
            export_file(args.export, args.extras, args.images)
    return 0


if __name__ == "__main__":
    sys.exit(main())
