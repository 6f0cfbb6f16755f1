"""The synthesised furrows' shape, measured on default renders the way issue 38 defines it.

Front view (the face framed, yaw 0), 800 × 800, each pose at full weight with a technique and
with none: the luminance difference d, its gradients gx, gy over the pixels where |d| > 3, and

- **Gy/Gx** = Σgy² / Σgx²: above 1 the lines run across (horizontal), below 1 up and down;
- **coherence** = √((Σgx² − Σgy²)² + 4(Σgx·gy)²) / (Σgx² + Σgy²): 1 for one direction
  everywhere, about 0.3 for crumpled skin;
- **between the brows**: the share of a frown's changed pixels inside the glabella's box, as
  wide as the gap between the inner ends of the brows (landmarks 21 and 22) and from the bridge
  of the nose (landmark 28) up to one and a half gaps above the brows;
- **temple side**: the share of a left squint's changed pixels beyond the outer corner of the
  left eye (landmark 45), toward the temple: its crow's feet;
- **on the fold**: the share of a left smile's changed pixels near its nasolabial fold (from
  the wing of the nose, landmark 35, down past the mouth corner, 54), and **under the eye**
  (below the left eye's lower lid, 46 and 47): where an artist paints a smile; and the fold's
  **slant**, how far (degrees) the long axis of the change there turns from the line nose
  wing → mouth corner;
- **marionette**: the share of a left mouth frown's changed pixels in the box below the left
  mouth corner (54), down to the chin's height (8) and out to the jaw line.

On the bundled sample (the ICT-FaceKit head, 17 wrinkling poses on four maps), on the head the
tests build in production conventions (millimetres, Z up, UDIM tiles, separate eyes and teeth)
and on a coarse copy of it (561 vertices). Before issue 38 a brow lowerer on the sample drew
near-vertical lines fanning over the whole forehead up to the scalp with horizontal folds above
the inner brow (Gy/Gx 1.2, coherence 0.31, 13 % of its change between the brows); on the
production head it drew horizontal lines (Gy/Gx 2.5, coherence 0.47). Before issues 37/38's
second round its lines fanned out past the inner ends of the brows and technique 2's frown
showed the squint's crow's feet at the outer eye corners (the frown's motion there falls in the
squint's wrinkle vectors): 63 % (t1) and 50 % (t2) of the frown's change between the brows.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.sample.ict_head import landmark_vertices
from studio.core.setup.face_frame import aim
from studio.core.setup.sample_setup import sample_project
from tests import production_head

SIZE = 800
CHANGED = 3.0  # luminance levels: where the figures are taken
FROWN = ("browDown_L", "browDown_R")
SURPRISE = ("browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R")


@dataclass
class Figures:
    ratio: float  # Gy/Gx
    coherence: float
    between_brows: float  # share of the changed pixels in the glabella's box (nan: no box)
    temple_side: float = float("nan")  # … and beyond the left eye's outer corner
    fold: float = float("nan")  # … near the left nasolabial fold
    under_eye: float = float("nan")  # … under the left eye's lower lid
    slant: float = float("nan")  # degrees between the change near the fold and its line
    marionette: float = float("nan")  # … below the left mouth corner


def luminance(image: np.ndarray) -> np.ndarray:
    return image[..., :3].astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def furrow_figures(posed: np.ndarray, plain: np.ndarray, box: np.ndarray | None = None,
                   temple: np.ndarray | None = None, places: Places | None = None) -> Figures:
    """The issue's figures of what a technique changes (``posed`` against ``plain``)."""
    d = luminance(posed) - luminance(plain)
    gy, gx = np.gradient(d)
    on = np.abs(d) > CHANGED
    xx, yy, xy = (gx[on] ** 2).sum(), (gy[on] ** 2).sum(), (gx[on] * gy[on]).sum()
    total = max(xx + yy, 1e-12)

    def share(where: np.ndarray | None) -> float:
        return float((on & where).sum() / max(on.sum(), 1)) if where is not None else float("nan")

    figures = Figures(float(yy / max(xx, 1e-12)),
                      float(np.sqrt((xx - yy) ** 2 + 4.0 * xy * xy) / total), share(box),
                      share(temple))
    if places is not None:
        figures.fold, figures.under_eye, figures.marionette = (
            share(places.fold), share(places.under_eye), share(places.marionette))
        figures.slant = line_slant(d, on & places.fold, places.fold_direction)
    return figures


def line_slant(d: np.ndarray, where: np.ndarray, direction: np.ndarray) -> float:
    """Degrees between the long axis of a change over ``where`` (the principal axis of its
    pixels, weighted by |d|: a fold is a long, narrow mark) and ``direction``."""
    yy, xx = np.nonzero(where)
    if xx.size < 3:
        return float("nan")
    w = np.abs(d[yy, xx])
    points = np.c_[xx, yy] - np.average(np.c_[xx, yy], axis=0, weights=w)
    cov = (points * w[:, None]).T @ points
    axis = np.linalg.eigh(cov)[1][:, -1]
    turn = np.degrees(abs(np.arctan2(axis[1], axis[0]) - np.arctan2(direction[1], direction[0])))
    turn %= 180.0
    return float(min(turn, 180.0 - turn))


@dataclass
class Places:
    """Where an artist paints a left smile's fold and bunching and a left mouth frown's line,
    from the landmarks' pixels."""

    fold: np.ndarray  # (SIZE, SIZE) bool
    fold_direction: np.ndarray  # (2,) pixels: nose wing → mouth corner
    under_eye: np.ndarray
    marionette: np.ndarray

    @classmethod
    def of(cls, pixels: np.ndarray) -> Places:
        """The fold's band: along the line from the nose wing to the mouth corner (35 → 54,
        from a third of its length above the wing to 40 % past the corner), from a sixth of
        its length inside it to 60 % outside, where the cheek folds over the corner. Under
        the eye: from the lower lid (46, 47) down a lid's width, between the eye's corners
        (42, 45). The marionette box: from the mouth corner (54) down to the chin's height
        (8), from half the corner's distance to the midline (51) inside it to as far out."""
        yy, xx = np.mgrid[0:SIZE, 0:SIZE].astype(np.float64)
        wing, corner = pixels[35], pixels[54]
        axis = corner - wing
        length = float(np.hypot(*axis))
        u = ((xx - wing[0]) * axis[0] + (yy - wing[1]) * axis[1]) / length ** 2
        v = ((xx - wing[0]) * axis[1] - (yy - wing[1]) * axis[0]) / length  # >0: outward
        fold = (u >= -0.3) & (u <= 1.4) & (v >= -length / 6.0) & (v <= 0.6 * length)
        lid = max(pixels[46, 1], pixels[47, 1])
        width = abs(pixels[45, 0] - pixels[42, 0])
        under = ((xx >= pixels[42, 0]) & (xx <= pixels[45, 0] + 0.25 * width)
                 & (yy >= lid) & (yy <= lid + 0.6 * width))
        half = abs(corner[0] - pixels[51, 0]) * 0.5
        marionette = ((xx >= corner[0] - half) & (xx <= corner[0] + half)
                      & (yy >= corner[1] - 0.1 * half) & (yy <= pixels[8, 1]))
        return cls(fold, axis / length, under, marionette)


def glabella_box(pixels: np.ndarray) -> np.ndarray:
    """(SIZE, SIZE) bool: the box between the brows from the landmarks' pixels (68, 2)."""
    left, right = sorted((pixels[21, 0], pixels[22, 0]))
    gap = right - left
    top = min(pixels[21, 1], pixels[22, 1]) - 1.5 * gap
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    return (xx >= left) & (xx <= right) & (yy >= top) & (yy <= pixels[28, 1])


def temple_side(pixels: np.ndarray) -> np.ndarray:
    """(SIZE, SIZE) bool: the image beyond the character's left eye's outer corner (landmark
    45; less a tenth of the eye's width, 42 to 45), toward the temple, above the tip of the
    nose (30): where a left squint's crow's feet lie."""
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    return (xx >= pixels[45, 0] - 0.1 * abs(pixels[45, 0] - pixels[42, 0])) & (
        yy <= pixels[30, 1])


def front_figures(project: Project, poses: dict[str, tuple[str, ...]],
                  techniques: tuple[str, ...] = ("t2",), marks: np.ndarray | None = None
                  ) -> dict[tuple[str, str], Figures]:
    """{(expression, technique): figures} from front-view renders of these expressions;
    ``marks``: the 68 landmarks' vertices, for the figures that need them."""
    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    out = {}
    with OffscreenStudio(project, SIZE, SIZE) as studio:
        aim(studio.camera, project, "face")
        studio.camera.yaw = 0.0
        box = temple = places = None
        if marks is not None:
            pixels = studio.camera.project(project.mesh.rest[marks], SIZE, SIZE)[0]
            box, temple = glabella_box(pixels), temple_side(pixels)
        for name, pose_names in poses.items():
            weights = dict.fromkeys(pose_names, 1.0)
            if marks is not None:  # the mouth and cheek move far: their places, posed
                posed_marks = project.mesh.rest[marks] + sum(
                    project.pose(p).positions[marks] - project.mesh.rest[marks]
                    for p in pose_names)
                places = Places.of(studio.camera.project(posed_marks, SIZE, SIZE)[0])
            plain = studio.render(RenderSettings(technique="none"), weights)
            for technique in techniques:
                posed = studio.render(RenderSettings(technique=technique), weights)
                out[name, technique] = furrow_figures(posed, plain, box, temple, places)
    return out


@pytest.fixture(scope="module")
def sample() -> dict[tuple[str, str], Figures]:
    project = sample_project()
    poses = {"browInnerUp_L": ("browInnerUp_L",), "surprise": SURPRISE,
             "browDown_L": ("browDown_L",), "browDown_R": ("browDown_R",), "frown": FROWN,
             "mouthSmile_L": ("mouthSmile_L",), "eyeSquint_L": ("eyeSquint_L",),
             "mouthFrown_L": ("mouthFrown_L",),
             "frown expression": (*FROWN, "mouthFrown_L", "mouthFrown_R")}
    return front_figures(project, poses, ("t2", "t1"), landmark_vertices())


def test_the_sample_s_brow_raise_draws_long_lines_across_the_forehead(sample) -> None:
    """Measured 6.5 and 0.73 (t2), 9.4 and 0.81 (t1)."""
    for technique in ("t2", "t1"):
        f = sample["browInnerUp_L", technique]
        assert f.ratio >= 3.0 and f.coherence >= 0.7, (technique, f)


def test_the_sample_s_brow_lowerer_draws_vertical_lines(sample) -> None:
    """Glabellar lines, up and down and alike, with a faint one across the root of the
    nose: measured Gy/Gx 0.11–0.19, coherence 0.68–0.80 for the left brow and for both (a
    frown), t1 and t2, as two lines between the brows (0.62 and 0.24 while the line across
    the root of the nose was as deep as 0.4 of them; 0.12–0.17 and 0.71–0.79 as three lines,
    0.07–0.10 and 0.82–0.87 when they reached further up); 0.5–1.3 and 0.21–0.52 before
    issue 38."""
    for pose in ("browDown_L", "browDown_R", "frown"):
        for technique in ("t2", "t1"):
            f = sample[pose, technique]
            assert f.ratio <= 0.33 and f.coherence >= 0.6, (pose, technique, f)


def test_a_frown_s_lines_lie_between_the_brows(sample) -> None:
    """Both brows lowered: the frown's change lies in the glabella's box — 100 % of it with
    either technique (two vertical lines no further out than the inner ends of the brows, a
    faint one across the root of the nose; technique 2's vectors keep the frown's motion out
    of the squint's crow's feet at the eye corners and the brow raise's forehead lines); 90 %
    with three lines up to 1.5 above the tip of the nose, 85 % when they reached further up
    the forehead toward the hairline. 63 % and
    50 % before, when the lines fanned out past the inner brows and technique 2 showed the
    crow's feet; 23 % and 9 % before issue 38, when they covered the forehead."""
    assert sample["frown", "t1"].between_brows >= 0.75, sample["frown", "t1"]
    assert sample["frown", "t2"].between_brows >= 0.75, sample["frown", "t2"]


def test_a_brow_raise_leaves_a_squint_s_lines_under_the_eye_alone(sample) -> None:
    """A brow raise squeezes the skin between the inner eye and the nose, and its motion there
    fell in the cones of the squint's and the cheek raise's lines under the eye: technique 2
    showed them as small scratches, 3.4 % of its change under the left eye. Other poses'
    compression no longer keeps a pose's cones wide on the lines anatomy placed for it, unless
    they have placed lines of their own (``auto_setup.narrow_cones``): 0.3 %."""
    assert sample["browInnerUp_L", "t2"].under_eye <= 0.01, sample["browInnerUp_L", "t2"]


def test_a_whole_frown_leaves_the_temple_alone(sample) -> None:
    """The sample's frown expression (both brow lowerers and both mouth frowns at once): none
    of its change beyond the outer corner of the left eye. A brow lowerer with a mouth frown
    moves the temple's skin the way a squint does where neither alone does, and technique 2
    showed the squint's crow's feet there (4.2 % of the frown's change: a mark by the eye)
    until the set-up narrowed the squint's cones for two poses at once as for one
    (``auto_setup.narrow_cones``); measured 0 % now."""
    for technique in ("t2", "t1"):
        f = sample["frown expression", technique]
        assert f.temple_side <= 0.002, (technique, f)


def test_the_sample_s_smile_stays_orderly(sample) -> None:
    """Measured coherence 0.77 (t2)."""
    assert sample["mouthSmile_L", "t2"].coherence >= 0.55, sample["mouthSmile_L", "t2"]


def test_a_squint_draws_crow_s_feet_beside_the_outer_corner_of_the_eye(sample) -> None:
    """A squint's lines fan out from the outer corner of the eye over the temple side, where it
    squeezes the skin, none on the eye nor back toward the nose, and two shallower ones follow
    the lower lid under the eye, which the squint pushes up: measured 69 / 70 % of its change
    beyond the corner (t2 / t1, ``temple_side``) and 27 % under the eye (100 % beyond the
    corner with the fan alone, which left an avatar maker's lid squint at 0.7 % of the render).
    46 % (t2) and 32 % (t1) beyond the corner before issue 38's second round, when furrows
    across its compression crossed under the eye."""
    for technique in ("t2", "t1"):
        f = sample["eyeSquint_L", technique]
        assert f.temple_side >= 0.5 and f.temple_side + f.under_eye >= 0.85, (technique, f)


def test_a_smile_draws_one_nasolabial_fold_and_bunches_the_cheek_under_the_eye(sample) -> None:
    """A left smile: one deep fold from the wing of the nose down past the mouth corner, along
    that line, and two short lines where the cheek bunches under the eye — where an artist
    paints a smile — not parallel lines over the whole cheek. Measured 37 / 39 % of its
    change on the fold (t2 / t1) and 17 / 18 % under the eye, the fold's long axis 9° off the
    line nose wing → mouth corner since issue 45's soft fold at skin's tilt (41 / 43 % and
    20 / 21 %, 3° as a deep trench the reviewers scored 0; 46 and 28 % with a fold half as
    wide and deeper); 13 % on the fold and 3 % under the eye (t2) before."""
    for technique in ("t2", "t1"):
        f = sample["mouthSmile_L", technique]
        assert f.fold >= 0.3 and f.fold + f.under_eye >= 0.45, (technique, f)
        assert f.slant <= 25.0, (technique, f)


def test_a_mouth_frown_draws_a_short_marionette_line_only(sample) -> None:
    """A left mouth frown (the sample's frown expression pulls both corners down): at most a
    short line down from the mouth corner, what an artist paints, not lines radiating around
    the mouth. Measured 85 % of its change in the box below the corner (t2 and t1; 94 % when
    it was twice as deep and half as wide); 36 % (t2) before, for the lines around the
    mouth."""
    for technique in ("t2", "t1"):
        f = sample["mouthFrown_L", technique]
        assert f.marionette >= 0.8, (technique, f)


def production_project(folder: Path, vertices: int) -> Project:
    """``new --auto`` on the production-conventions head (millimetres, Z up, UDIM tiles)."""
    head = production_head.build_head("mm", vertices=vertices)
    files = head.write_set(folder / "mm")
    args = ["new", "--mesh", str(files["neutral"]), "--not-face", "eye_L", "eye_R", "teeth",
            "--auto", "-o", str(folder / "mm.wrinkle")]
    for pose in production_head.POSES:
        args += ["--pose", f"{pose}={files[pose]}"]
    with redirect_stdout(io.StringIO()):
        assert main(args) == 0
    return load_project(folder / "mm.wrinkle")


@pytest.mark.parametrize("vertices", [2172, 561])
def test_a_head_in_other_conventions_and_a_coarse_one_frown_and_raise_alike(
        tmp_path, vertices: int) -> None:
    """The production-conventions head at the thesis's 2172 vertices and coarse at 561:
    the brow lowerer's line vertical (measured Gy/Gx 0.45 and 0.15, coherence 0.39 and 0.83
    with t2: since issue 45 one soft line on its own side, bent where it follows the squeeze,
    at 2172 vertices; 0.12 and 0.07, 0.80 and 0.89 as two stamped slots; 2.5 and 0.47
    before them, horizontal), the brow raise's across (10.6, 0.89), the smile orderly
    (coherence 0.71 and 0.83). Its brows sit lower in its face box than the ICT head's: its
    lines begin where its brow lowerer squeezes the skin, too short a band for a line across
    the root of the nose."""
    project = production_project(tmp_path, vertices)
    found = front_figures(project, {p: (p,) for p in ("browInnerUp", "browDown_L",
                                                       "mouthSmile_L")}, ("t2", "t1"))
    for technique in ("t2", "t1"):
        frown, raise_, smile = (found[p, technique] for p in ("browDown_L", "browInnerUp",
                                                                "mouthSmile_L"))
        assert frown.ratio <= 0.5 and frown.coherence >= 0.35, (technique, frown)
        assert raise_.ratio >= 3.0 and raise_.coherence >= 0.7, (technique, raise_)
        assert smile.coherence >= 0.55, (technique, smile)
