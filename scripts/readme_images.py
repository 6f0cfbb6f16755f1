"""Renders the README's pictures of the sample face.

Run ``python scripts/readme_images.py`` for all of them, or name some:
``python scripts/readme_images.py silhouette``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from studio.bench.report import _font
from studio.core.project import Project
from studio.core.sample import make_sample, sample_landmarks
from studio.render.offscreen import OffscreenStudio
from studio.render.renderer import RenderSettings

OUT = Path(__file__).resolve().parent.parent / "docs" / "images"
PANELS = [
    ("surprise · no wrinkles", "none", "surprise", "shaded"),
    ("surprise · technique 2 · brow map", "t2", "surprise", "shaded"),
    ("surprise · technique 1 · brow map", "t1", "surprise", "shaded"),
    ("squeeze · technique 2 · eyes & cheeks map", "t2", "squeeze", "shaded"),
    ("frown · technique 2 · brow map", "t2", "frown", "shaded"),
    ("surprise · automatic (strain), no authoring", "strain", "surprise", "shaded"),
]


def labelled(image: np.ndarray, text: str) -> Image.Image:
    img = Image.fromarray(image)
    draw = ImageDraw.Draw(img)
    draw.font = _font()  # a TrueType font: Pillow's bitmap default drops spaces
    draw.rectangle((0, 0, img.width, 22), fill=(20, 20, 24))
    draw.text((8, 5), text, fill=(230, 230, 230))
    return img


def silhouette(project: Project) -> None:
    """Wrinkles in silhouette (issue 10): the surprised forehead in profile, technique 2, with
    relief off and with displacement (tessellation)."""
    size = (440, 440)
    with OffscreenStudio(project, *size) as studio:
        camera = studio.camera
        camera.yaw, camera.pitch = 90.0, 0.0
        camera.frame(*project.mesh.bounds())
        marks = sample_landmarks(project)
        camera.target = marks["forehead"] - [0.0, 0.05, 0.22]  # the outline left of centre
        camera.distance *= 0.28
        weights = project.single_pose_weights("surprise")
        tiles = [labelled(studio.render(RenderSettings(technique="t2", relief=relief), weights),
                          label)
                 for label, relief in (("surprise · t2 · relief off", "off"),
                                       ("surprise · t2 · displaced (tessellation)", "displace"))]
    sheet = Image.new("RGB", (size[0] * len(tiles), size[1]))
    for i, tile in enumerate(tiles):
        sheet.paste(tile, (i * size[0], 0))
    sheet.save(OUT / "silhouette.png", optimize=True)
    print(f"wrote {OUT / 'silhouette.png'}")


def sample_techniques(project: Project) -> None:
    """Both techniques on the surprise, squeeze and frown poses (each area revealing one of the
    sample's two wrinkled maps), and the automatic mode."""
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


IMAGES = {"sample_techniques": sample_techniques, "silhouette": silhouette}


def main(names: list[str]) -> None:
    unknown = sorted(set(names) - set(IMAGES))
    if unknown:
        raise SystemExit(f"unknown image {', '.join(unknown)} (choose from {', '.join(IMAGES)})")
    OUT.mkdir(parents=True, exist_ok=True)
    project = make_sample()
    for name in names or IMAGES:
        IMAGES[name](project)


if __name__ == "__main__":
    main(sys.argv[1:])
