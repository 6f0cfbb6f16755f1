"""The furrow controls on the command line (issue 45, point 6): ``new --auto`` takes
``--furrow-depth``, ``--furrow-spacing``, ``--furrow-sharpness`` and ``--furrow-onset``, each
for all poses or ``POSE=VALUE`` for one; the set-up synthesises its maps with them and the
project keeps them. A bad value, or a pose the files lack, is one line and exit code 2. Run as a
person runs it, in a subprocess, on a head in millimetres with Z up and UVs off the unit
square."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import save_obj
from studio.core.project.reader import load_project

pytestmark = pytest.mark.core

POSE = "browDown_L"  # squeezes the left half of the sheet across


def sheet(tmp_path: Path) -> list[str]:
    """A skin sheet 160 × 200 mm in the x-z plane (Z up), its UVs in [0.1, 0.9] × [0.3, 0.7],
    and a pose that squeezes its left half to 85 % across: the files of ``new``."""
    n = 25
    x, z = np.meshgrid(np.linspace(-80.0, 80.0, n), np.linspace(-100.0, 100.0, n))
    rest = np.c_[x.ravel(), np.zeros(n * n), z.ravel()].astype(np.float32)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), \
        idx[1:, :-1].ravel()
    uvs = np.c_[0.1 + 0.8 * (x.ravel() + 80) / 160, 0.3 + 0.4 * (z.ravel() + 100) / 200]
    mesh = FaceMesh(rest, np.r_[np.c_[a, c, b], np.c_[a, d, c]], uvs.astype(np.float32),
                    np.arange(n * n))
    pose = rest.copy()
    pose[:, 0] = np.where(rest[:, 0] < 0, rest[:, 0] * 0.85, rest[:, 0])
    save_obj(tmp_path / "neutral.obj", mesh)
    save_obj(tmp_path / "frown.obj", mesh, pose)
    return ["new", "--mesh", str(tmp_path / "neutral.obj"),
            "--pose", f"{POSE}={tmp_path / 'frown.obj'}", "--auto"]


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "studio.cli", *args], capture_output=True,
                          text=True, timeout=600, check=False)


def test_the_flags_reach_the_synthesised_map_and_the_project(tmp_path):
    args = sheet(tmp_path)
    plain, shaped = tmp_path / "plain.wrinkle", tmp_path / "shaped.wrinkle"
    done = cli(*args, "-o", str(plain))
    assert done.returncode == 0, done.stderr
    done = cli(*args, "--furrow-depth", "2.5", "--furrow-onset", f"{POSE}=0.4",
               "--furrow-sharpness", f"{POSE}=1.5", "--furrow-spacing", "1.25",
               "--furrow-depth", "2", "-o", str(shaped))  # the later depth wins
    assert done.returncode == 0, done.stderr
    project = load_project(shaped)
    controls = project.furrows.of(POSE)
    assert (controls.depth, controls.spacing, controls.sharpness, controls.onset) == (
        2.0, 1.25, 1.5, 0.4)
    assert project.furrows.all.onset == 0.0 and project.furrows.controls(POSE).depth == 1.0
    before = load_project(plain)
    (name,) = project.furrows.maps_of(POSE)
    assert before.furrows.maps_of(POSE) == [name]
    assert not np.array_equal(project.textures.wrinkle_maps[name],
                              before.textures.wrinkle_maps[name])  # made with the controls
    # the onset reaches the areas the set-up linked: nothing at 0.4 of the pose
    assert np.array_equal(project.activations({POSE: 0.4}), project.activations({POSE: 0.0}))
    assert not np.array_equal(before.activations({POSE: 0.4}),
                              before.activations({POSE: 0.0}))


@pytest.mark.parametrize(("flag", "value", "says"), [
    ("--furrow-depth", "deep", "'deep' is not a number"),
    ("--furrow-spacing", "0.1", "spacing must be a number from 0.25 to 4 (not 0.1)"),
    ("--furrow-onset", f"{POSE}=1", "onset must be a number from 0 to 0.95 (not 1)"),
    ("--furrow-sharpness", "=2", "'=2' names no pose"),
    ("--furrow-depth", "nan", "depth must be a number from 0 to 4 (not nan)"),
    ("--furrow-onset", "smile=0.3", "the face does not have: 'smile' (key poses: browDown_L)"),
])
def test_a_bad_value_is_one_line_and_exit_2(tmp_path, flag, value, says):
    out = tmp_path / "bad.wrinkle"
    done = cli(*sheet(tmp_path), flag, value, "-o", str(out))
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], done.stderr
    assert "Traceback" not in done.stderr and not out.exists()
