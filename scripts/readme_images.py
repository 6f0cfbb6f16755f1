"""Renders the README's pictures of the sample face (run: python scripts/readme_images.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from studio.core.sample import make_sample
from studio.render.offscreen import OffscreenStudio
from studio.render.renderer import RenderSettings

OUT = Path(__file__).resolve().parent.parent / "docs" / "images"
PANELS = [
    ("surprise · no wrinkles", "none", "surprise", "shaded"),
    ("surprise · technique 2", "t2", "surprise", "shaded"),
    ("surprise · technique 1", "t1", "surprise", "shaded"),
    ("squeeze · technique 2", "t2", "squeeze", "shaded"),
    ("frown · technique 2", "t2", "frown", "shaded"),
    ("squeeze · t2 visibility", "t2", "squeeze", "heat"),
]


def labelled(image: np.ndarray, text: str) -> Image.Image:
    img = Image.fromarray(image)
    draw = ImageDraw.Draw(img)
    draw.rectangle((0, 0, img.width, 22), fill=(20, 20, 24))
    draw.text((8, 5), text, fill=(230, 230, 230))
    return img


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    project = make_sample()
    size = (420, 440)
    with OffscreenStudio(project, *size) as studio:
        studio.camera.yaw = 12.0
        studio.camera.frame(*project.mesh.bounds(), margin=0.98)
        tiles = [labelled(studio.render(RenderSettings(technique=t, view=v),
                                        project.single_pose_weights(p)), label)
                 for label, t, p, v in PANELS]
    sheet = Image.new("RGB", (size[0] * 3, size[1] * 2))
    for i, tile in enumerate(tiles):
        sheet.paste(tile, ((i % 3) * size[0], (i // 3) * size[1]))
    sheet.save(OUT / "sample_techniques.png", optimize=True)
    print(f"wrote {OUT / 'sample_techniques.png'}")


if __name__ == "__main__":
    main()
