"""Contact sheets for judging the wrinkles' look blind (``../shared/LOOK.md``).

One sheet per pose of the bundled sample: close-ups where the pose wrinkles, technique none,
1 and 2, under the default light (top row) and one hard raking light (bottom row),
nearest-neighbour enlarged so steps and seams show; and the furrow-tilt figures of every
synthesised map (``studio.core.wrinkles.normal_tilt``). The sheets carry no label that says
which build made them: a reviewer compares them unlabelled.

``python scripts/look_review.py OUT_DIR [POSE …]``, or ``--production OUT_DIR`` for the head
the tests build in production conventions (millimetres, Z up, UDIM tiles; set up by ``new
--auto``), its face framed whole.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image

from studio.core.sample.ict_head import landmark_vertices
from studio.core.setup.face_frame import aim
from studio.core.setup.sample_setup import sample_project
from studio.core.wrinkles.normal_tilt import furrow_tilt
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

# pose → the iBUG-68 landmarks it wrinkles around (brows 17–26, nose 27–35, eyes 36–47,
# mouth 48–67)
POSES = {
    "browInnerUp_L": (19, 20, 21, 22, 23, 24), "browOuterUp_L": (17, 18, 19, 20, 21),
    "browDown_L": (20, 21, 22, 23, 27), "eyeSquint_L": (42, 45, 46, 47),
    "cheekSquint_L": (45, 46, 47, 54), "noseSneer_L": (27, 31, 35, 42),
    "mouthSmile_L": (31, 35, 48, 54), "mouthFrown_L": (48, 54, 57, 8),
    "mouthShrugLower": (48, 54, 57, 8), "mouthPucker": (33, 48, 54, 57),
}
TILE = (300, 260)
ENLARGE = 2
LIGHTS = {"default": RenderSettings().light_dir, "raking": (0.95, 0.25, 0.18)}


def sheet(studio: OffscreenStudio, pose: str) -> Image.Image:
    """Techniques none, 1 and 2 across, the default and the raking light down, enlarged."""
    rows = [np.concatenate([studio.render(RenderSettings(technique=t, light_dir=light),
                                          {pose: 1.0}) for t in ("none", "t1", "t2")], axis=1)
            for light in LIGHTS.values()]
    image = Image.fromarray(np.concatenate(rows, axis=0))
    return image.resize((image.width * ENLARGE, image.height * ENLARGE), Image.NEAREST)


def pose_sheet(studio: OffscreenStudio, marks: np.ndarray, pose: str) -> Image.Image:
    studio.camera.target = marks[list(POSES[pose])].mean(axis=0)
    return sheet(studio, pose)


def production(out: Path) -> None:
    """Sheets of the production-conventions head's compressing poses, the face framed."""
    import io
    import tempfile
    from contextlib import redirect_stdout

    from studio.cli import main as cli
    from studio.core.project.reader import load_project
    from tests.production_head import COMPRESSING
    from tests.test_production_head import import_head

    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as folder:
        _, args = import_head(Path(folder), "mm")
        with redirect_stdout(io.StringIO()):
            cli(args)
        project = load_project(Path(folder) / "mm.wrinkle")
    with OffscreenStudio(project, *TILE) as studio:
        aim(studio.camera, project, "face")
        studio.camera.yaw = 15.0
        studio.camera.distance *= 0.6  # the face, not the whole head
        for pose in COMPRESSING:
            sheet(studio, pose).save(out / f"production_{pose}.png")
            print(f"wrote {out / f'production_{pose}.png'}")


def main(out: Path, poses: list[str]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    project = sample_project()
    marks = project.mesh.rest[landmark_vertices()]
    with OffscreenStudio(project, *TILE) as studio:
        distance = studio.camera.distance
        studio.camera.yaw, studio.camera.pitch = 15.0, 0.0
        for pose in poses or list(POSES):
            studio.camera.distance = 0.42 * distance
            pose_sheet(studio, marks, pose).save(out / f"{pose}.png")
            print(f"wrote {out / f'{pose}.png'}")
    neutral = project.textures.normal_neutral
    for name, image in project.textures.wrinkle_maps.items():
        p90, p99, top = furrow_tilt(image, neutral)
        print(f"{name}: furrow tilt p90 {p90:.1f}°, p99 {p99:.1f}°, max {top:.1f}°")


if __name__ == "__main__":
    if sys.argv[1] == "--production":
        production(Path(sys.argv[2]))
    else:
        main(Path(sys.argv[1]), sys.argv[2:])
