"""The README's USD picture: the sample written as one ``.usdz`` (``export --usd``), imported by
stock Blender's own USD importer (``bpy`` from PyPI, run as a separate process), then a pose's
shape key at 0 and at 1, rendered by Blender (Workbench, the imported material's texture) and
put side by side: what a person who takes the package to Blender, Houdini or Omniverse gets.

    python scripts/usd_picture.py [OUT.png] [--pose NAME] [--size N]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent

# run inside Blender's Python: import, find the face, render the pose's key at 0 and at 1
BLENDER = """
import sys
import bpy
from mathutils import Vector

usdz, pose, size, out0, out1 = sys.argv[-5:]
bpy.ops.wm.read_factory_settings(use_empty=True)
assert bpy.ops.wm.usd_import(filepath=usdz) == {"FINISHED"}
face = max((o for o in bpy.context.scene.objects if o.type == "MESH"),
           key=lambda o: len(o.data.vertices))
keys = face.data.shape_keys.key_blocks
face.data.shape_keys.animation_data_clear()  # the timeline's keyframes would set the weights
corners = [face.matrix_world @ Vector(c) for c in face.bound_box]
lo = Vector([min(c[i] for c in corners) for i in range(3)])
hi = Vector([max(c[i] for c in corners) for i in range(3)])
centre, reach = (lo + hi) / 2, max(hi - lo)
scene = bpy.context.scene
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
camera.location = centre + Vector((0.3 * reach, -1.9 * reach, 0.15 * reach))
camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
scene.camera = camera
scene.world = bpy.data.worlds.new("world")
scene.world.color = (0.03, 0.035, 0.045)
scene.render.engine = "BLENDER_WORKBENCH"
scene.display.shading.light = "STUDIO"
scene.display.shading.color_type = "TEXTURE"
scene.render.resolution_x = scene.render.resolution_y = int(size)
for weight, out in ((0.0, out0), (1.0, out1)):
    keys[pose].value = weight
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
print("shape keys:", len(keys) - 1)
"""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", type=Path,
                        default=ROOT / "docs" / "images" / "usd_blender.png")
    parser.add_argument("--pose", default="jawOpen")
    parser.add_argument("--size", type=int, default=360)
    args = parser.parse_args()
    from studio.core.files.images import write_png
    from studio.core.formats.usd.writer import save_usdz
    from studio.core.setup.sample_setup import sample_project

    with tempfile.TemporaryDirectory() as temp:
        usdz, script = Path(temp) / "sample.usdz", Path(temp) / "render.py"
        save_usdz(sample_project(), usdz)
        script.write_text(BLENDER)
        renders = [Path(temp) / "neutral.png", Path(temp) / "posed.png"]
        subprocess.run([sys.executable, str(script), str(usdz), args.pose, str(args.size),
                        *map(str, renders)], check=True)
        images = [np.asarray(Image.open(p).convert("RGB")) for p in renders]
    write_png(args.out, np.concatenate(images, axis=1))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
