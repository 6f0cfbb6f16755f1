"""Renders an export folder's face in Blender with its wrinkle material, as a user would make it.

    python scripts/blender_wrinkle_render.py FOLDER POSE OUT_DIR [--size N] [--samples N]
                                             [--technique 1|2] [--weight W]

Needs the ``bpy`` package (the test extra). Imports FOLDER/face.glb, runs the folder's
``blender_wrinkles.py`` (the export's script), and renders the upper face from the front with
Cycles on the CPU four times: POSE's shape key at 1 (or W) and at 0, each with the object's
``wrinkle_strength`` at 1 and at 0, into OUT_DIR/{pose1,pose0}_{on,off}.png, with the object's
``wrinkle_technique`` as asked (default: the one the script set, the project's). Prints one JSON
line (after MARK): bpy's version, the value each driver gives at POSE = 1 (or W; by its label), and
the picture's frame (its centre's Blender x and z, and the width it spans).
"""

from __future__ import annotations

import argparse
import json
import math
import runpy
import sys
from pathlib import Path

MARK = "BLENDER_WRINKLE_RENDER "


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("pose")
    parser.add_argument("out", type=Path)
    parser.add_argument("--size", type=int, default=160)
    parser.add_argument("--samples", type=int, default=8)
    parser.add_argument("--technique", type=int, choices=(1, 2))
    parser.add_argument("--weight", type=float, default=1.0, help="POSE's weight in pose1_*")
    args = parser.parse_args()
    import bpy
    from mathutils import Vector

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(args.folder / "face.glb"))
    runpy.run_path(str(args.folder / "blender_wrinkles.py"), run_name="__main__")
    scene = bpy.context.scene
    face = next(o for o in scene.objects if o.type == "MESH" and o.data.shape_keys)
    corners = [face.matrix_world @ Vector(c) for c in face.bound_box]
    low = Vector([min(c[i] for c in corners) for i in range(3)])
    high = Vector([max(c[i] for c in corners) for i in range(3)])
    centre, height = (low + high) / 2, high.z - low.z
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 0.6 * height
    # glTF's front (+Z) is Blender's -Y: look along +Y at the upper half of the face
    camera.location = (centre.x, low.y - height, centre.z + 0.2 * height)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.rotation_euler = (math.radians(60), 0.0, math.radians(20))  # from above the brow
    sun.data.energy = 4.0
    for obj in (camera, sun):
        scene.collection.objects.link(obj)
    scene.camera = camera
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = 1
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.image_settings.file_format = "PNG"
    # the timeline came in as an action on the shape keys: it would set them every frame
    face.data.shape_keys.animation_data_clear()
    for block in face.data.shape_keys.key_blocks:  # and left its values at the first frame's
        block.value = 0.0
    key = face.data.shape_keys.key_blocks[args.pose]
    if args.technique is not None:
        face["wrinkle_technique"] = args.technique
    args.out.mkdir(parents=True, exist_ok=True)
    activations = {}
    for weight, pose in ((args.weight, "pose1"), (0.0, "pose0")):
        for strength, label in ((1.0, "on"), (0.0, "off")):
            key.value = weight
            face["wrinkle_strength"] = strength
            scene.frame_set(scene.frame_current)  # drivers follow
            bpy.context.view_layer.update()
            if pose == "pose1" and strength == 1.0:
                material = face.active_material
                activations = {n.label: n.outputs[0].default_value
                               for n in material.node_tree.nodes if n.type == "VALUE"}
            scene.render.filepath = str(args.out / f"{pose}_{label}.png")
            bpy.ops.render.render(write_still=True)
    # where the picture is: its centre (Blender's x, z) and the width it spans
    frame = [centre.x, camera.location.z, camera.data.ortho_scale]
    print("\n" + MARK + json.dumps({"bpy": bpy.app.version_string, "activations": activations,
                                    "frame": frame}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
