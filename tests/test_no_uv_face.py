"""A face without texture coordinates, as the issue's (a low-resolution head in metres, ARKit
shapes): the production-convention head (tests/production_head.py) at about 1,220 vertices,
written as OBJs with every ``vt`` stripped. ``new --auto`` makes UVs with xatlas and says so,
keeps them in the project, and a default render shows each compressing pose's wrinkles with
both techniques."""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.mesh.meshio import (
    load_mesh,
    load_pose,
    made_uvs,
    not_face_vertices,
    save_obj,
)
from studio.core.project.reader import load_project
from studio.core.wrinkles.mask_ops import auto_mask, rasterise_uv, uv_coverage
from tests.production_head import POSES, build_head
from tests.test_blender_round_trip import changed_shares
from tests.visibility import least

JUDGED = ("browInnerUp", "browDown_L", "mouthSmile_L")  # brow raise, frown, smile
NOT_FACE = ["eye_L", "eye_R", "teeth"]


def strip_uvs(path: Path) -> Path:
    """The same OBJ with no ``vt`` and faces of vertex numbers only."""
    lines = [line for line in path.read_text().splitlines() if not line.startswith("vt ")]
    lines = [re.sub(r"(\d+)/\d+", r"\1", line) if line.startswith("f ") else line
             for line in lines]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("no_uv")
    files = {name: strip_uvs(path)
             for name, path in build_head("m", vertices=1220).write_set(folder / "m").items()}
    args = ["new", "--mesh", str(files["neutral"]), "--not-face", *NOT_FACE, "--auto",
            "-o", str(folder / "face.wrinkle")]
    for pose in POSES:
        args += ["--pose", f"{pose}={files[pose]}"]
    out = io.StringIO()
    with redirect_stdout(out):
        assert main(args) == 0
    return files, load_project(folder / "face.wrinkle"), out.getvalue()


@pytest.mark.core
def test_uvs_are_made_for_an_obj_without_any_and_poses_still_fit(tmp_path):
    files = {name: strip_uvs(path)
             for name, path in build_head("m", vertices=1220).write_set(tmp_path,
                                                                        POSES[:1]).items()}
    assert "vt " not in files["neutral"].read_text()
    mesh = load_mesh(files["neutral"])
    note = made_uvs(mesh)
    assert note is not None and re.fullmatch(
        rf"no UVs in {re.escape(str(files['neutral']))}: made them with xatlas, \d+ charts", note)
    assert mesh.uvs.min() >= 0.0 and mesh.uvs.max() <= 1.0
    # every triangle with area on the face has area in UV space: none folded to a line
    uv = mesh.uvs[mesh.triangles].astype(np.float64)
    area = np.abs(np.cross(uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]))
    p = mesh.rest[mesh.welded_triangles].astype(np.float64)
    surface = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert (area[surface > 1e-6 * surface.max()] > 0).all()
    pose = load_pose(files[POSES[0]], mesh)  # the file's v order is kept
    assert pose.positions.shape == mesh.rest.shape


def test_new_says_it_made_the_uvs_and_keeps_them(imported):
    files, project, out = imported
    assert f"no UVs in {files['neutral']}: made them with xatlas" in out
    made = load_mesh(files["neutral"])
    assert project.mesh.n_welded == made.n_welded
    assert np.allclose(np.sort(project.mesh.uvs, axis=0), np.sort(made.uvs, axis=0))


def test_the_made_uvs_travel_in_the_exports(imported, tmp_path):
    """A glTF export and an OBJ of the face carry the UVs the studio made."""
    from studio.core.formats.gltf.codec import load_gltf, save_gltf

    _, project, _ = imported
    save_gltf(project, tmp_path / "face.glb")
    back = load_gltf(tmp_path / "face.glb")
    assert np.allclose(back.mesh.uvs, project.mesh.uvs, atol=1e-6)
    save_obj(tmp_path / "face.obj", project.mesh)
    again = load_mesh(tmp_path / "face.obj")
    assert made_uvs(again) is None  # it has UVs now: the studio's
    assert np.allclose(np.sort(again.uvs, axis=0), np.sort(project.mesh.uvs, axis=0), atol=1e-5)


def test_a_default_render_shows_brow_raise_frown_and_smile(imported):
    _, project, _ = imported
    for pose in JUDGED:
        shares = changed_shares(project, pose)
        print(pose, shares)
        # the frown: two short lines between the brows (issue 38), 0.93 / 0.92 % (t1 / t2)
        assert min(shares["t1"], shares["t2"]) >= least(pose), (pose, shares)



def test_the_coarse_face_s_furrows_are_long_lines_not_crosshatched_creases(imported):
    """Issue 38 on the issue's low-resolution head (1,220 vertices, UVs made by xatlas), front
    view, t1 and t2 against none (tests/test_furrow_figures.py): the brow raise's lines across
    the forehead, the frown's up and down between the brows, the smile's one direction (its
    nasolabial fold: coherence 0.50 / 0.49 when it drew crosshatched short creases; 0.71 /
    0.75 now)."""
    from tests.test_furrow_figures import front_figures

    _, project, _ = imported
    figures = front_figures(project, {pose: (pose,) for pose in JUDGED}, ("t2", "t1"))
    for technique in ("t2", "t1"):
        raise_, frown, smile = (figures[pose, technique] for pose in JUDGED)
        assert raise_.ratio >= 3.0 and raise_.coherence >= 0.65, (technique, raise_)
        assert frown.ratio <= 0.33 and frown.coherence >= 0.6, (technique, frown)
        assert smile.coherence >= 0.55, (technique, smile)

def curvature_on_edges(mask: np.ndarray, mesh) -> float:
    """How much more the mask bends on its UV triangles' edges than inside them: the mean
    |Laplacian| on texels an edge crosses over that on the others, inside the charts (away
    from their borders) where the mask is on. A value interpolated across each triangle is
    linear there and bends only on the edges (about 1.4 here, what shows as triangle-stepped
    outlines); a field smooth on the surface bends wherever it does (about 1)."""
    size = mask.shape[0]
    inner = uv_coverage(mesh, size)
    for _ in range(6):
        inner[1:-1, 1:-1] &= (inner[:-2, 1:-1] & inner[2:, 1:-1] & inner[1:-1, :-2]
                              & inner[1:-1, 2:])
    on_edge = np.zeros((size, size), bool)
    uv = mesh.uvs[mesh.triangles]
    for t in range(3):
        a, b = uv[:, t], uv[:, (t + 1) % 3]
        for f in np.linspace(0.0, 1.0, 60):
            q = a + (b - a) * f
            on_edge[np.clip(((1 - q[:, 1]) * size).astype(int), 0, size - 1),
                    np.clip((q[:, 0] * size).astype(int), 0, size - 1)] = True
    lap = np.abs(4 * mask[1:-1, 1:-1] - mask[:-2, 1:-1] - mask[2:, 1:-1] - mask[1:-1, :-2]
                 - mask[1:-1, 2:])
    judged = inner[1:-1, 1:-1] & (mask[1:-1, 1:-1] > 0.02)
    edge = on_edge[1:-1, 1:-1]
    return float(lap[judged & edge].mean() / lap[judged & ~edge].mean())


@pytest.mark.core
@pytest.mark.parametrize("pose", ["browDown_L", "mouthSmile_L"])
def test_auto_masks_on_the_low_resolution_face_do_not_follow_its_triangles(tmp_path, pose):
    """The Areas panel's Auto mask on the 1,220-vertex face (its UV triangles some 20 texels
    across at 1024): smooth across the triangles, not stepped along their edges."""
    files = {name: strip_uvs(path) for name, path in
             build_head("m", vertices=1220).write_set(tmp_path, (pose,)).items()}
    mesh = load_mesh(files["neutral"])
    mask = auto_mask(mesh, load_pose(files[pose], mesh).positions, 1024)
    assert mask.max() > 0.9
    assert curvature_on_edges(mask, mesh) < 1.15


@pytest.mark.core
def test_the_smoothed_auto_mask_leaves_the_eyes_under_the_lids_alone(tmp_path):
    """The squint compresses the lower lid, a few millimetres from the eyeball: weighed on
    the surface, the lid's value must not reach the eye's own texels (away from its chart's
    border, where the mask's blur may)."""
    files = {name: strip_uvs(path) for name, path in
             build_head("m", vertices=1220).write_set(tmp_path, ("eyeSquint_L",)).items()}
    mesh = load_mesh(files["neutral"])
    eyes = not_face_vertices(mesh, NOT_FACE[:2])
    _, on_eye = rasterise_uv(mesh.uvs, mesh.triangles[eyes[mesh.welded_triangles].all(axis=1)],
                             np.zeros(mesh.n_vertices, np.float32), 1024)
    for _ in range(8):
        on_eye[1:-1, 1:-1] &= (on_eye[:-2, 1:-1] & on_eye[2:, 1:-1] & on_eye[1:-1, :-2]
                               & on_eye[1:-1, 2:])
    mask = auto_mask(mesh, load_pose(files["eyeSquint_L"], mesh).positions, 1024)
    assert mask.max() > 0.9 and on_eye.any()
    assert mask[on_eye].max() == 0.0
