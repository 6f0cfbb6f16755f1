"""The README's Blender picture: the sample exported as a folder, its face.glb and
blender_wrinkles.py run in stock Blender (scripts/blender_wrinkle_render.py, Cycles on the CPU),
a pose's shape key at 1 without and with the wrinkle material's wrinkles (technique 1 or 2),
side by side.

    python scripts/blender_picture.py [OUT.png] [--pose NAME] [--size N] [--samples N]
                                      [--technique 1|2]
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


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", type=Path,
                        default=ROOT / "docs" / "images" / "blender_wrinkles.png")
    parser.add_argument("--pose", default="browInnerUp_L")
    parser.add_argument("--size", type=int, default=480)
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--technique", type=int, choices=(1, 2), default=1)
    args = parser.parse_args()
    from studio.core.files.images import write_png
    from studio.core.formats.export import export_folder
    from studio.core.setup.sample_setup import sample_project

    with tempfile.TemporaryDirectory() as temp:
        folder, renders = Path(temp) / "folder", Path(temp) / "renders"
        export_folder(sample_project(), folder)
        subprocess.run([sys.executable, str(ROOT / "scripts" / "blender_wrinkle_render.py"),
                        str(folder), args.pose, str(renders), "--size", str(args.size),
                        "--samples", str(args.samples), "--technique", str(args.technique)],
                       check=True, capture_output=True)
        pair = []
        for name in ("pose1_off", "pose1_on"):
            with Image.open(renders / f"{name}.png") as image:
                pair.append(np.asarray(image.convert("RGB")))
    write_png(args.out, np.concatenate(pair, axis=1))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
