"""Stock Blender (the ``bpy`` package, 4.5 LTS) imports every kind of glTF export: the poses as
shape keys at the project's positions, the UVs, the skin material with its maps, the studio's
custom attributes and the timeline as an action keyed with its weights.

Blender's importer (4.2 to 5.1, glTF-Blender-IO #2658) failed on every export while its custom
``_`` attributes mixed VEC3 and SCALAR types; they are all VEC3 now. bpy runs in a subprocess
(scripts/blender_gltf.py): importing it loads all of Blender, and a crash there must not end
the test run. Without bpy the test fails and says how to install it, as the validator's does.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.timeline import Timeline, sequence_all_poses
from studio.core.formats.export import export_folder
from studio.core.formats.gltf.codec import _Gltf, save_gltf, vertex_attributes
from studio.core.project.model import Project
from studio.core.sample.synthetic import make_test_face
from tests.test_export_folder_core import tiny_project

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "blender_gltf.py"


def blender(*args: str | Path) -> list[dict]:
    """scripts/blender_gltf.py's JSON lines (the first: bpy's version)."""
    if importlib.util.find_spec("bpy") is None:
        pytest.fail("bpy is not installed: run 'bash scripts/setup.sh test' (the test extra "
                    "installs Blender's bpy package)")
    done = subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    mark = "BLENDER_GLTF_REPORT "  # scripts/blender_gltf.py's MARK
    return [json.loads(line[len(mark):]) for line in done.stdout.splitlines()
            if line.startswith(mark)]


def full_face() -> Project:
    """The test face with every per-vertex attribute: not-face vertices, painted cones, a
    timeline."""
    face = make_test_face(561, texture_size=64, mask_size=32)
    face.timeline = sequence_all_poses([p.name for p in face.poses])
    face.not_face = np.zeros(face.mesh.n_welded, bool)
    face.not_face[:40] = True
    area = face.wdv.areas[1]
    area.cone_angles_deg = np.linspace(0.0, 40.0, face.mesh.n_welded).astype(np.float32)
    return face


def bare_face() -> Project:
    """No influence areas, no WDV areas, no keys."""
    face = make_test_face(561, texture_size=64, mask_size=32)
    face.timeline = Timeline()
    face.influence.areas.clear()
    face.wdv.areas.clear()
    return face


@pytest.fixture(scope="module")
def exports(tmp_path_factory) -> list[tuple[Project, Path]]:
    """Each kind of export: the full test face, the bare one (in the thesis's frame), a face
    on two UDIM tiles with painted cones, and the engine folder's face.glb."""
    folder = tmp_path_factory.mktemp("blender")
    full, bare, udim = full_face(), bare_face(), tiny_project(udim=True)
    save_gltf(full, folder / "full.glb")
    save_gltf(bare, folder / "bare.glb", tangent_frame="thesis")
    save_gltf(udim, folder / "udim.glb")
    export_folder(full, folder / "engine")
    return [(full, folder / "full.glb"), (bare, folder / "bare.glb"),
            (udim, folder / "udim.glb"), (full, folder / "engine" / "face.glb")]


def check_import(project: Project, report: dict, positions: bool = True) -> None:
    """One file as Blender imported it, against the project it was written from."""
    assert report["ok"], report.get("trace", report)
    (mesh,) = report["meshes"]
    face = project.mesh
    assert mesh["vertices"] == face.n_vertices
    assert [k["name"] for k in mesh["shape_keys"]] == (
        ["Basis", *(p.name for p in project.poses)] if project.poses else [])
    if positions:
        size = float(np.ptp(face.rest, axis=0).max())
        expected = [face.rest, *(p.positions for p in project.poses)] if project.poses else []
        for key, want in zip(mesh["shape_keys"], expected, strict=True):
            np.testing.assert_allclose(key["co"], want[face.weld], atol=1e-6 * size,
                                       err_msg=key["name"])
        loops = np.array(mesh["loop_vertices"])
        np.testing.assert_allclose(mesh["loop_uvs"], face.uvs[loops], atol=1e-6)
    assert mesh["uv_layers"] == ["UVMap", "UVMap.001"]  # the second: the studio's welding
    assert mesh["materials"] == [{"name": "skin", "images": ["diffuse", "normal_neutral"]}]
    assert mesh["attributes"] == sorted(vertex_attributes(project))
    assert report["actions"] == (["timeline"] if project.timeline.has_keys else [])
    if positions and project.timeline.has_keys:  # the timeline's weights, key for key
        g = _Gltf(Path(report["file"]))
        timeline = project.timeline
        times = g.accessor(g.doc["animations"][0]["samplers"][0]["input"]).ravel()
        frames = times * timeline.fps + timeline.start
        assert list(report["keyed"]) == [p.name for p in project.poses]
        for name, values in report["keyed"].items():
            want = timeline.track(name).values_at(frames)
            np.testing.assert_allclose(values, want, atol=1e-6, err_msg=name)
            assert np.ptp(want) > 0.5  # the pose moves


def test_blender_imports_every_kind_of_export(exports):
    version, *reports = blender("--keys", *(path for _, path in exports))
    assert version["bpy"].startswith("4.5")
    assert len(reports) == len(exports)
    for (project, path), report in zip(exports, reports, strict=True):
        assert report["file"] == str(path)
        check_import(project, report)


def test_blender_imports_the_sample_head(tmp_path):
    """The sample as the studio opens on it: 53 poses, 18 WDV areas (37 custom attributes:
    a direction and a cone per area, and the weld) and 18 masks on the ICT head's 28 911
    render vertices."""
    from studio.core.setup.sample_setup import sample_project

    project = sample_project()
    save_gltf(project, tmp_path / "sample.glb")
    _, report = blender(tmp_path / "sample.glb")
    check_import(project, report, positions=False)
    (mesh,) = report["meshes"]
    assert mesh["vertices"] == 28911 and len(mesh["shape_keys"]) == 54
    assert len(mesh["attributes"]) == 2 * len(project.wdv.areas) + 1 == 37
