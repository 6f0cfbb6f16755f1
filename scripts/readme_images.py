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
from studio.core.project.model import Project
from studio.core.project.sample import make_sample, sample_landmarks
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

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


def contact_sheet(tiles: list[Image.Image], columns: int, name: str) -> None:
    """Tiles of one size in rows of ``columns``, saved as docs/images/NAME.png."""
    w, h = tiles[0].size
    sheet = Image.new("RGB", (w * columns, h * -(-len(tiles) // columns)))
    for i, tile in enumerate(tiles):
        sheet.paste(tile, ((i % columns) * w, (i // columns) * h))
    sheet.save(OUT / f"{name}.png", optimize=True)
    print(f"wrote {OUT / f'{name}.png'}")


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
    contact_sheet(tiles, len(tiles), "silhouette")


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
    contact_sheet(tiles, 3, "sample_techniques")


def blend_modes(project: Project) -> None:
    """The thesis's blend of two shaded colours beside the faster-on-a-GPU blend of normals
    (light once), on the surprised forehead with technique 2, and their difference."""
    size = (420, 300)
    with OffscreenStudio(project, *size) as studio:
        camera = studio.camera
        camera.frame(*project.mesh.bounds())
        camera.target = sample_landmarks(project)["forehead"]
        camera.distance *= 0.4
        weights = project.single_pose_weights("surprise")
        colour, normal = (studio.render(RenderSettings(technique="t2", blend=b), weights)
                          for b in ("colour", "normal"))
    difference = np.abs(colour.astype(int) - normal.astype(int))
    gain = max(1, 255 // max(int(difference.max()), 1))  # the largest difference shows white
    tiles = [labelled(colour, "colour blend (the thesis, default)"),
             labelled(normal, "normal blend (light once)"),
             labelled(np.clip(difference * gain, 0, 255).astype(np.uint8),
                      f"difference × {gain} (largest: {difference.max()} of 255)")]
    contact_sheet(tiles, 3, "blend_modes")


IMAGES = {"sample_techniques": sample_techniques, "silhouette": silhouette,
          "blend_modes": blend_modes}


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
