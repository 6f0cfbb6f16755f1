"""Faces without texture coordinates in the formats that never or seldom carry them: a binary
STL (every corner repeated in every triangle), a PLY without ``s t`` and a GLB whose primitive
has POSITION and morph targets but no TEXCOORD_0. The head is the production-convention one
(tests/production_head.py: metres, Z up, eyes and teeth beside the skin). ``new`` makes UVs
with xatlas and says so, the key poses keep the files' positions (read through the neutral
file's own vertices, not the render vertices xatlas made), the saved project keeps the made
UVs, its glTF export writes them, and a pose of another topology is one line naming it.

The OBJ equivalent is tests/test_no_uv_face.py.
"""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import load_mesh, load_pose, made_uvs
from studio.core.project.reader import load_project
from studio.core.wrinkles.mask_ops import uv_coverage
from tests.gltf_avatar import GlbDoc, arkit_name, to_world
from tests.production_head import ProductionHead, build_head
from tests.test_meshio_formats import _binary_stl, _ply

pytestmark = pytest.mark.core

POSES = ("browInnerUp", "mouthSmile_L")
MADE = r"no UVs in {}: made them with xatlas, \d+ charts"


def welded_head(head: ProductionHead, pose: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The whole head (skin, eyes, teeth) in world metres: positions (the skin's welded, the
    eyes' with their seams' repeated vertices) and triangles over them."""
    positions, triangles, base = [], [], 0
    for part in head.parts:
        points = part.poses.get(pose, part.rest) if pose else part.rest
        weld = part.weld if part.weld is not None else np.arange(len(part.rest))
        positions.append(head.to_world(points))
        triangles.append(weld[part.triangles] + base)
        base += len(points)
    return np.concatenate(positions), np.concatenate(triangles)


def write_stl(path: Path, positions: np.ndarray, triangles: np.ndarray) -> Path:
    return _binary_stl(path, positions[triangles].tolist())


def write_ply(path: Path, positions: np.ndarray, triangles: np.ndarray) -> Path:
    return _ply(path, positions.tolist(), triangles.tolist(), uv=False)


WRITERS = {"stl": write_stl, "ply": write_ply}


@pytest.fixture(scope="module")
def head() -> ProductionHead:
    return build_head("m", vertices=1220)


def write_set(head: ProductionHead, folder: Path, suffix: str) -> dict[str, Path]:
    """neutral.<suffix> and one file per pose, as a user would pass them to ``new``."""
    folder.mkdir(parents=True, exist_ok=True)
    write = WRITERS[suffix]
    files = {"neutral": write(folder / f"neutral.{suffix}", *welded_head(head))}
    for pose in POSES:
        files[pose] = write(folder / f"{pose}.{suffix}", *welded_head(head, pose))
    return files


def new(args: list[str]) -> tuple[int, str]:
    out = io.StringIO()
    with redirect_stdout(out):
        code = main(["new", *args])
    return code, out.getvalue()


def assert_charts(mesh: FaceMesh) -> None:
    """UVs in the unit square, every triangle with area on the surface with area in UV space,
    and the charts side by side: their areas add up to no more than the texels they cover
    (charts laid over each other would cover less than their sum)."""
    assert mesh.uvs.min() >= 0.0 and mesh.uvs.max() <= 1.0
    uv = mesh.uvs[mesh.triangles].astype(np.float64)
    area = np.abs(np.cross(uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0])) / 2
    p = mesh.rest[mesh.welded_triangles].astype(np.float64)
    surface = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert (area[surface > 1e-6 * surface.max()] > 0).all()
    size = 1024
    covered = uv_coverage(mesh, size).sum() / size**2
    assert area.sum() > 0.3  # the charts fill the square, not a corner of it
    assert area.sum() <= covered * 1.02, (area.sum(), covered)


def assert_poses_fit(mesh: FaceMesh, poses: dict[str, np.ndarray], head: ProductionHead
                     ) -> None:
    """Each pose's welded positions are the file's: xatlas keeps the triangles in order, so a
    triangle's corners in the pose are the file's corners of that triangle."""
    neutral, triangles = welded_head(head)
    assert mesh.n_triangles == len(triangles)
    np.testing.assert_allclose(mesh.rest[mesh.welded_triangles], neutral[triangles], atol=1e-5)
    for name in POSES:
        moved, _ = welded_head(head, name)
        np.testing.assert_allclose(poses[name][mesh.welded_triangles], moved[triangles],
                                   atol=1e-5)
        assert np.abs(poses[name] - mesh.rest).max() > 1e-3  # the pose moves the face


@pytest.mark.parametrize("suffix", ["stl", "ply"])
def test_new_makes_uvs_for_a_mesh_file_without_any_and_its_poses_fit(head, tmp_path, suffix):
    files = write_set(head, tmp_path / suffix, suffix)
    args = ["--mesh", str(files["neutral"]), "-o", str(tmp_path / "face.wrinkle")]
    for pose in POSES:
        args += ["--pose", f"{pose}={files[pose]}"]
    code, out = new(args)
    assert code == 0, out
    assert re.search(MADE.format(re.escape(str(files["neutral"]))), out), out

    mesh = load_mesh(files["neutral"])
    assert re.fullmatch(MADE.format(re.escape(str(files["neutral"]))), made_uvs(mesh) or "")
    assert mesh.n_welded < len(welded_head(head)[0])  # the seams' repeated vertices welded
    assert_charts(mesh)
    assert_poses_fit(mesh, {p: load_pose(files[p], mesh).positions for p in POSES}, head)

    project = load_project(tmp_path / "face.wrinkle")
    assert np.array_equal(project.mesh.uvs, mesh.uvs)
    assert np.array_equal(project.mesh.triangles, mesh.triangles)
    assert_poses_fit(project.mesh, {p.name: p.positions for p in project.poses}, head)


@pytest.mark.parametrize("suffix", ["stl", "ply"])
def test_a_pose_of_another_topology_is_one_line_naming_it(head, tmp_path, suffix, capsys):
    files = write_set(head, tmp_path / suffix, suffix)
    positions, triangles = welded_head(head, POSES[0])
    skin = head.parts[0]
    wrong = WRITERS[suffix](tmp_path / f"skin_only.{suffix}", positions[:len(skin.rest)],
                            triangles[:len(skin.triangles)])
    mesh = load_mesh(files["neutral"])
    with pytest.raises(MeshError, match=r"skin_only\.\w+: has \d+ vertices, the neutral mesh "
                                        r"has \d+"):
        load_pose(wrong, mesh)
    capsys.readouterr()
    code, _ = new(["--mesh", str(files["neutral"]), "--pose", f"smile={wrong}",
                   "-o", str(tmp_path / "face.wrinkle")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and str(wrong) in err and "vertices" in err, err
    assert "Traceback" not in err


def test_a_pose_of_the_same_file_topology_fits_a_project_reopened(head, tmp_path):
    """The neutral file's topology is kept beside the mesh only while it is loaded; reopened
    from the project, a pose file of that topology still fits, face corner by face corner."""
    files = write_set(head, tmp_path / "stl", "stl")
    code, out = new(["--mesh", str(files["neutral"]), "-o", str(tmp_path / "face.wrinkle")])
    assert code == 0, out
    project = load_project(tmp_path / "face.wrinkle")
    pose = load_pose(files[POSES[0]], project.mesh)
    assert_poses_fit(project.mesh, {POSES[0]: pose.positions,
                                    POSES[1]: load_pose(files[POSES[1]], project.mesh).positions},
                     head)


# --------------------------------------------------------------------------------------------
# glTF without TEXCOORD_0
# --------------------------------------------------------------------------------------------


def write_glb(head: ProductionHead, path: Path, eye_uvs: bool = False) -> Path:
    """A .glb of the skin (render vertices, seams repeated, Y up, metres) and the left eye,
    each with POSITION, indices and two morph targets, and no TEXCOORD_0 (the eye has one
    when ``eye_uvs``)."""
    skin, eye = head.parts[0], head.parts[1]
    d = GlbDoc()
    meshes = []
    for name, part in (("Head", skin), ("EyeLeft", eye)):
        weld = part.weld if part.weld is not None else np.arange(len(part.rest))
        world = to_world(part.rest)
        attributes = {"POSITION": d.data(world[weld].astype(np.float32))}
        if eye_uvs and name == "EyeLeft":
            attributes["TEXCOORD_0"] = d.data(part.uvs.astype(np.float32))
        targets = [{"POSITION": d.data((to_world(part.poses[p]) - world)[weld]
                                       .astype(np.float32))} for p in POSES]
        meshes.append({"name": name, "primitives": [{
            "attributes": attributes, "targets": targets,
            "indices": d.data(part.triangles.astype(np.uint32).ravel())}],
            "extras": {"targetNames": [arkit_name(p) for p in POSES]}})
    d.doc["meshes"] = meshes
    d.doc["nodes"] = [{"name": m["name"], "mesh": i} for i, m in enumerate(meshes)]
    d.doc["scenes"] = [{"nodes": [0, 1]}]
    return d.write_glb(path)


def test_new_makes_uvs_for_a_glb_without_texcoords_and_its_morph_targets_fit(head, tmp_path):
    path = write_glb(head, tmp_path / "bare.glb")
    code, out = new(["--gltf", str(path), "-o", str(tmp_path / "face.wrinkle")])
    assert code == 0, out
    assert re.search(MADE.format(re.escape(str(path))), out), out

    project = load_project(tmp_path / "face.wrinkle")
    mesh = project.mesh
    assert_charts(mesh)
    # the file's render vertices (each skin seam vertex repeated) welded: skin and eye
    skin, eye = head.parts[0], head.parts[1]
    assert mesh.n_welded == len(skin.rest) + len(np.unique(eye.rest, axis=0))
    corners = np.concatenate([to_world(skin.rest)[skin.weld][skin.triangles],
                              to_world(eye.rest)[eye.triangles]])
    np.testing.assert_allclose(mesh.rest[mesh.welded_triangles], corners, atol=1e-5)
    for pose in POSES:
        moved = np.concatenate([to_world(skin.poses[pose])[skin.weld][skin.triangles],
                                to_world(eye.poses[pose])[eye.triangles]])
        positions = project.pose(arkit_name(pose)).positions
        np.testing.assert_allclose(positions[mesh.welded_triangles], moved, atol=1e-5)
        assert np.abs(positions - mesh.rest).max() > 1e-3


def test_the_made_uvs_travel_in_the_glb_export(head, tmp_path):
    """``wrinkle-studio export --gltf`` writes the made UVs as TEXCOORD_0, and the export
    opens again with them."""
    from studio.core.formats.gltf.codec import load_gltf

    files = write_set(head, tmp_path / "stl", "stl")
    code, out = new(["--mesh", str(files["neutral"]), "--pose", f"smile={files[POSES[1]]}",
                     "-o", str(tmp_path / "face.wrinkle")])
    assert code == 0, out
    project = load_project(tmp_path / "face.wrinkle")
    assert main(["export", str(tmp_path / "face.wrinkle"), "--gltf",
                 str(tmp_path / "face.glb")]) == 0
    back = load_gltf(tmp_path / "face.glb")
    np.testing.assert_allclose(back.mesh.uvs, project.mesh.uvs, atol=1e-6)
    np.testing.assert_allclose(back.pose("smile").positions, project.pose("smile").positions,
                               atol=1e-6)


def test_a_face_that_mixes_meshes_with_and_without_uvs_is_one_line_naming_them(head, tmp_path,
                                                                              capsys):
    path = write_glb(head, tmp_path / "mixed.glb", eye_uvs=True)
    capsys.readouterr()
    code, _ = new(["--gltf", str(path), "-o", str(tmp_path / "face.wrinkle")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and str(path) in err, err
    assert "without texture coordinates (TEXCOORD_0): Head, and with them: EyeLeft" in err
    # leaving the eye out, the face has no UVs at all: made
    code, out = new(["--gltf", str(path), "--keep", "Head", "-o",
                     str(tmp_path / "face.wrinkle")])
    assert code == 0, out
    assert re.search(MADE.format(re.escape(str(path))), out), out
