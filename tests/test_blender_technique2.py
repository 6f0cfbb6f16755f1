"""Technique 2 in stock Blender (bpy 4.5 LTS): the plain glTF export carries the Blender script,
and run on it the script makes the wrinkle direction vectors drive the material (a Geometry
Nodes modifier weighs the motion from Blender's ``rest_position`` against each area's vectors
and cone, read by Named Attribute nodes, per vertex), so that a brow raise wrinkles the
forehead in a Cycles render where the studio's technique 2 shows it, and nowhere it does not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.formats.blender_material import SCRIPT, held_term, onset_term
from studio.core.formats.gltf.codec import save_gltf
from studio.core.project.model import Project
from studio.core.wrinkles.response import onset_weight
from studio.core.wrinkles.wdv import visibility
from tests.test_blender_material import blender_render, changed, rendered
from tests.test_blender_round_trip import JUDGED, set_up_head

SIZE = 128


@pytest.mark.core
@pytest.mark.parametrize("onset", [0.0, 0.3, 0.75])
def test_the_held_back_weight_and_the_onset_weight_add_up_to_the_pose_s_weight(onset):
    for x in np.linspace(0.0, 1.0, 21):
        scope = {"__builtins__": {}, "min": min, "max": max}
        seen = eval(onset_term(onset).format(x=repr(float(x))), scope)
        held = eval(held_term(onset).format(x=repr(float(x))), scope)
        assert seen == pytest.approx(float(onset_weight(x, onset)), abs=1e-12)
        assert seen + held == pytest.approx(x, abs=1e-12)


def studio_region(project: Project, pose: str, frame: list[float]) -> np.ndarray:
    """The pixels of a SIZE² front picture of ``frame`` (as the render script reports it)
    that the studio's technique 2 wrinkles with ``pose`` at 1: the vertices the numpy
    reference of its shader sees, on the skin."""
    rest = project.mesh.rest.astype(np.float64)
    target = next(p for p in project.poses if p.name == pose).positions
    slots = project.wdv.pack_slots(len(rest), project.textures.map_index)
    seen = visibility(target - rest, slots, project.wdv.expression_factor,
                      project.wdv.scale_free).max(1) > 0.05
    if project.not_face is not None:
        seen &= ~project.not_face
    # glTF's x and y are Blender's x and z; the picture looks along +Y
    cx, cz, width = frame
    cols = ((rest[seen, 0] - cx) / width * SIZE + SIZE / 2).astype(int)
    rows = ((cz - rest[seen, 1]) / width * SIZE + SIZE / 2).astype(int)
    region = np.zeros((SIZE, SIZE), bool)
    inside = (rows >= 0) & (rows < SIZE) & (cols >= 0) & (cols < SIZE)
    region[rows[inside], cols[inside]] = True
    return grown(region, 2)


def grown(region: np.ndarray, steps: int) -> np.ndarray:
    """``region`` widened by ``steps`` pixels (vertices project to points, not areas)."""
    padded = np.pad(region, steps)
    out = np.zeros_like(region)
    for dy in range(2 * steps + 1):
        for dx in range(2 * steps + 1):
            out |= padded[dy:dy + region.shape[0], dx:dx + region.shape[1]]
    return out


def render_technique_2(project: Project, tmp_path: Path, weight: float = 1.0
                       ) -> tuple[dict, Path]:
    """The project's plain glTF export rendered in Blender with technique 2, JUDGED at
    ``weight`` (pose1_*) and at 0 (pose0_*), wrinkles on and off; the render's report."""
    folder = tmp_path / "plain"
    folder.mkdir()
    save_gltf(project, folder / "face.glb")  # the plain export, not the folder
    assert (folder / SCRIPT).is_file()
    out = tmp_path / "render"
    report = blender_render(folder, out, "--technique", "2", "--size", str(SIZE),
                            "--samples", "4", "--weight", repr(weight))
    assert report["activations"]["technique 2"] == 1.0
    return report, out


def test_a_brow_raise_wrinkles_the_forehead_in_blender_where_the_studio_s_technique_2_does(
        tmp_path):
    project = set_up_head()
    report, out = render_technique_2(project, tmp_path)
    wrinkles = changed(rendered(out, "pose1_on"), rendered(out, "pose1_off"))
    assert not changed(rendered(out, "pose0_on"), rendered(out, "pose0_off")).any()
    assert wrinkles.mean() >= 0.005, wrinkles.mean()
    rows, cols = np.nonzero(wrinkles)
    # on the forehead above the eyes, on the face's left (the picture's right)
    assert rows.mean() < 0.42 * SIZE and cols.mean() > 0.5 * SIZE, (rows.mean(), cols.mean())
    region = studio_region(project, JUDGED, report["frame"])
    inside = wrinkles[region].sum() / wrinkles.sum()
    assert inside >= 0.9, inside  # nowhere the studio's technique 2 shows nothing


def test_a_brow_raise_short_of_its_onset_shows_no_technique_2_wrinkles_in_blender(tmp_path):
    """An onset of 0.75 holds the brow raise's lines back until 0.75 of its weight: at 0.5 the
    face has moved, the studio's technique 2 measures no motion, and Blender's neither."""
    project = set_up_head()
    project.furrows = project.furrows.with_values({JUDGED: {"onset": 0.75}})
    _, out = render_technique_2(project, tmp_path, weight=0.5)
    assert not changed(rendered(out, "pose1_on"), rendered(out, "pose1_off")).any()
