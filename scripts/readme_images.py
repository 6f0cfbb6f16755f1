"""Renders the README's pictures of the bundled sample: the ICT-FaceKit head, set up.

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
from studio.core.sample.ict_head import landmark_vertices
from studio.core.sample.synthetic import make_test_face, sample_landmarks
from studio.core.setup.sample_setup import EXPRESSIONS, sample_project
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

OUT = Path(__file__).resolve().parent.parent / "docs" / "images"
EXPRESSION = dict(EXPRESSIONS)
PANELS = [  # label, technique, expression
    ("surprise · no wrinkles", "none", "surprise"),
    ("surprise · technique 2", "t2", "surprise"),
    ("surprise · technique 1", "t1", "surprise"),
    ("squint · automatic (strain)", "strain", "squint"),
    ("frown · technique 2", "t2", "frown"),
    ("smile · technique 2", "t2", "smile"),
    ("squint and sneer · technique 2", "t2", "squint"),
    ("kiss · technique 2", "t2", "kiss"),
]
CLOSE_UPS = [  # the four poses the issue measured, each where it wrinkles
    ("browInnerUp_L", (19, 20, 21, 24)), ("browDown_L", (21, 22, 23, 27)),
    ("mouthSmile_L", (31, 35, 48, 54)), ("eyeSquint_L", (42, 45, 46, 47)),
]


def expression(name: str) -> dict[str, float]:
    return dict.fromkeys(EXPRESSION[name], 1.0)


def landmarks(project: Project) -> np.ndarray:
    """(68, 3) the head's landmark points (iBUG 300-W order) at rest."""
    return project.mesh.rest[landmark_vertices()]


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


def silhouette(_: Project) -> None:
    """Wrinkles in silhouette (issue 10), on the procedural test face (its brow map was
    painted with relief in mind): the surprised forehead in profile, technique 2, with relief
    off and with displacement (tessellation)."""
    project = make_test_face()
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
                 for label, relief in (("test face · surprise · t2 · relief off", "off"),
                                       ("displaced (tessellation)", "displace"))]
    contact_sheet(tiles, len(tiles), "silhouette")


def sample_techniques(project: Project) -> None:
    """Both techniques and the automatic mode on whole expressions of the real head."""
    size = (420, 460)
    with OffscreenStudio(project, *size) as studio:
        studio.camera.yaw = 15.0
        tiles = [labelled(studio.render(RenderSettings(technique=t), expression(e)), label)
                 for label, t, e in PANELS]
    contact_sheet(tiles, 4, "sample_techniques")


def close_ups(project: Project) -> None:
    """Each of the four poses the issue measured, close up where it wrinkles: no wrinkles,
    technique 1 and technique 2."""
    size = (340, 300)
    marks = landmarks(project)
    tiles = []
    with OffscreenStudio(project, *size) as studio:
        camera = studio.camera
        camera.yaw, camera.pitch = 15.0, 0.0
        distance = camera.distance
        for pose, around in CLOSE_UPS:
            camera.target = marks[list(around)].mean(axis=0)
            camera.distance = 0.45 * distance
            for technique in ("none", "t1", "t2"):
                image = studio.render(RenderSettings(technique=technique), {pose: 1.0})
                tiles.append(labelled(image, f"{pose} · {technique}"))
    contact_sheet(tiles, 6, "real_head_poses")


def anatomy_lines(marks: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """Where skin creases on a face, by anatomy (a schematic in model space): forehead lines
    across the brow raise, vertical frown lines between the brows, crow's feet fanning from
    the eye corners, the nasolabial folds and marionette lines, a pucker's lines on the upper
    lip. Polylines of 3-D points."""
    up = marks[27] - marks[30]  # nose bridge over nose tip: the face's up, its length a unit
    out = marks[45] - marks[42]  # along the left eye, toward its outer corner
    lines = []
    brows = marks[17:27]
    for k in (0.7, 1.05, 1.4):  # forehead lines above the brows
        lines.append(("forehead", brows[1:-1] + k * up))
    for inner, step in ((marks[21], 0.18), (marks[22], -0.18)):  # glabella
        x = inner + step * out
        lines.append(("glabella", np.array([x + 0.45 * up, x - 0.05 * up])))
    for corner, side in ((marks[45], 1.0), (marks[36], -1.0)):  # crow's feet
        for tilt in (-0.35, 0.0, 0.35):
            lines.append(("crow's feet", np.array(
                [corner + side * 0.15 * out, corner + side * 0.65 * out + tilt * up])))
    for wing, corner in ((marks[35], marks[54]), (marks[31], marks[48])):  # folds
        bow = (corner - marks[51]) * 0.35
        lines.append(("nasolabial", np.array([wing + 0.1 * (wing - marks[33]),
                                              0.5 * (wing + corner) + bow, corner + bow * 0.8])))
        lines.append(("marionette", np.array([corner + bow * 0.5, corner - 0.6 * up + bow])))
    lip = marks[51] - marks[33]  # from the base of the nose down to the upper lip's top
    for k in (-0.22, -0.1, 0.1, 0.22):  # lip lines, standing on the upper lip's border
        foot = marks[51] + k * 2.0 * (marks[54] - marks[51])
        lines.append(("lip", np.array([foot - 0.05 * lip, foot - 0.4 * lip])))
    return lines


def wrinkle_lines(project: Project) -> None:
    """Anatomy's wrinkle lines beside the synthesised maps: the head with every wrinkled map
    revealed where it holds furrows, next to where skin creases on a face."""
    size = (460, 520)
    lines = anatomy_lines(landmarks(project))
    revealed = project_with_every_map(project)
    with OffscreenStudio(project, *size) as studio:
        studio.camera.yaw = 0.0
        plain = Image.fromarray(studio.render(RenderSettings(technique="none"), {}))
        camera = studio.camera
        draw = ImageDraw.Draw(plain)
        for _, points in lines:
            xy, _ = camera.project(smooth(points), *size)
            draw.line([tuple(p) for p in xy], fill=(140, 40, 40), width=3)
    with OffscreenStudio(revealed, *size) as studio:
        studio.camera.yaw = 0.0
        maps = studio.render(RenderSettings(technique="none"), {})
    tiles = [labelled(np.asarray(plain), "where skin creases (anatomy, schematic)"),
             labelled(maps, "the synthesised wrinkled maps, all furrows shown")]
    contact_sheet(tiles, 2, "wrinkle_lines")


def smooth(points: np.ndarray, steps: int = 12) -> np.ndarray:
    """A polyline's corners rounded (Chaikin), so drawn creases curve."""
    for _ in range(steps // 4):
        a, b = points[:-1], points[1:]
        points = np.r_[points[:1], np.c_[0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b].reshape(
            -1, 3), points[-1:]]
    return points


def project_with_every_map(project: Project) -> Project:
    """A copy whose neutral map is, per texel, the wrinkled map furthest from flat there: the
    plain shading then shows every synthesised furrow at once."""
    import copy

    from studio.core.files.images import to_unit_float

    shown = copy.deepcopy(project)
    textures = shown.textures
    maps = [to_unit_float(m) * 2.0 - 1.0 for m in textures.wrinkle_maps.values()]
    tilt = np.stack([np.hypot(m[..., 0], m[..., 1]) for m in maps])
    pick = np.argmax(tilt, axis=0)
    best = np.take_along_axis(np.stack(maps), pick[None, ..., None], axis=0)[0]
    dtype = next(iter(textures.wrinkle_maps.values())).dtype
    top = np.iinfo(dtype).max
    textures.normal_neutral = np.clip(np.rint((best * 0.5 + 0.5) * top), 0, top).astype(dtype)
    return shown


def blend_modes(project: Project) -> None:
    """The thesis's blend of two shaded colours beside the faster-on-a-GPU blend of normals
    (light once), on the surprised forehead with technique 2, and their difference."""
    size = (420, 300)
    with OffscreenStudio(project, *size) as studio:
        camera = studio.camera
        camera.frame(*project.mesh.bounds())
        marks = landmarks(project)
        camera.target = marks[[19, 24]].mean(axis=0) + 0.8 * (marks[27] - marks[30])
        camera.distance *= 0.4
        weights = expression("surprise")
        colour, normal = (studio.render(RenderSettings(technique="t2", blend=b), weights)
                          for b in ("colour", "normal"))
    difference = np.abs(colour.astype(int) - normal.astype(int))
    gain = max(1, 255 // max(int(difference.max()), 1))  # the largest difference shows white
    tiles = [labelled(colour, "colour blend (the thesis, default)"),
             labelled(normal, "normal blend (light once)"),
             labelled(np.clip(difference * gain, 0, 255).astype(np.uint8),
                      f"difference × {gain} (largest: {difference.max()} of 255)")]
    contact_sheet(tiles, 3, "blend_modes")


def studio_window(project: Project) -> None:
    """The studio as it opens on the sample, 1440 × 900, the timeline at the surprise's peak
    and the brow raise shown by technique 2 (run under a display, e.g. xvfb-run)."""
    import os
    import tempfile

    # a first start's window (Getting started in front), not the layout this user last left
    os.environ.setdefault("XDG_CONFIG_HOME", tempfile.mkdtemp(prefix="readme-"))
    os.environ.setdefault("XDG_DATA_HOME", tempfile.mkdtemp(prefix="readme-"))
    from PySide6.QtWidgets import QApplication

    from studio.app import configure_opengl
    from studio.widgets.main_window import MainWindow

    configure_opengl()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    window = MainWindow(project)
    window.resize(1440, 900)
    window.show()
    rise, hold = 12, 18  # the surprise's keys: frames 0 → 12, held to 30
    window.doc.show_frame(rise + hold // 2)
    for _ in range(200):  # until the viewport has drawn that frame, refined
        app.processEvents()
        if window.viewport.frames_rendered > 2:
            break
    for _ in range(20):
        app.processEvents()
    out = OUT / "studio.png"
    window.grab().save(str(out))
    window.doc.undo_stack.setClean()
    window.close()
    print(f"wrote {out}")


IMAGES = {"sample_techniques": sample_techniques, "real_head_poses": close_ups,
          "wrinkle_lines": wrinkle_lines, "silhouette": silhouette, "blend_modes": blend_modes,
          "studio": studio_window}


def main(names: list[str]) -> None:
    unknown = sorted(set(names) - set(IMAGES))
    if unknown:
        raise SystemExit(f"unknown image {', '.join(unknown)} (choose from {', '.join(IMAGES)})")
    OUT.mkdir(parents=True, exist_ok=True)
    project = sample_project()
    for name in names or IMAGES:
        IMAGES[name](project)


if __name__ == "__main__":
    main(sys.argv[1:])
