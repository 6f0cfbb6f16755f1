"""The README's picture of an engine export: each channel of each mask texture the export wrote,
labelled with the engine's region and our areas in it, read back from the files themselves.

    python scripts/engine_picture.py PROJECT [--layout metahuman] [-o docs/images/engine_masks.png]

Runs `wrinkle-studio export PROJECT --folder TMP --layout L`, then lays out every channel of
every mask texture named in TMP/engine_layout.json as a small greyscale tile (white = strong).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

TILE = 150


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("project")
    parser.add_argument("--layout", default="metahuman")
    parser.add_argument("-o", "--output", default="docs/images/engine_masks.png")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="engine-"))
    subprocess.run([sys.executable, "-m", "studio.cli", "export", args.project, "--folder",
                    str(folder), "--layout", args.layout], check=True)
    sheet = json.loads((folder / "engine_layout.json").read_text())
    tiles: list[tuple[np.ndarray, str]] = []
    for texture in sheet["mask_textures"]:
        pixels = np.asarray(Image.open(folder / texture["file"]))
        pixels = pixels[..., None] if pixels.ndim == 2 else pixels
        for k, (channel, what) in enumerate(texture["channels"].items()):
            if k >= pixels.shape[2]:
                break
            plane = pixels[..., k].astype(np.float32)
            plane = plane / max(float(plane.max()), 1.0) * 255.0 if plane.max() > 255 else plane
            areas = ", ".join(a["area"] for a in what.get("areas", [])) or "(none)"
            region = what.get("region", "").split("_", 2)[-1]
            name = texture["texture"].removeprefix("T_head_")
            tiles.append((plane.astype(np.uint8), f"{name}.{channel} {region}\n{areas}"))
    columns = 8
    rows = -(-len(tiles) // columns)
    out = Image.new("RGB", (columns * TILE, rows * (TILE + 26)), (24, 24, 28))
    draw = ImageDraw.Draw(out)
    for i, (plane, label) in enumerate(tiles):
        x, y = (i % columns) * TILE, (i // columns) * (TILE + 26)
        out.paste(Image.fromarray(plane).resize((TILE - 6, TILE - 6)).convert("RGB"),
                  (x + 3, y + 3))
        draw.multiline_text((x + 4, y + TILE - 2), label[:60], fill=(220, 220, 220),
                            spacing=1)
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    out.save(args.output)
    print(f"wrote {args.output}: {len(tiles)} channels of {len(sheet['mask_textures'])} "
          f"textures ({sheet['engine']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
