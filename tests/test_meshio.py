"""Mesh and key-pose loading: OBJ parsing, seam splitting, pose checks, errors, trimesh formats."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import load_mesh, load_pose, save_obj

pytestmark = pytest.mark.core

# A quad (v/vt/vn), a pentagon (v/vt) whose first and last corners reuse v2 and v3 with other
# texture coordinates (a UV seam), and a triangle written with negative (relative) indices.
NEUTRAL_OBJ = """\
# exported by hand
mtllib face.mtl
o Face
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 2 1 0
v 3 0.5 0 1.0
vt 0 0
vt 0.5 0
vt 0.5 1
vt 0 1
vt 0.6 0
vt 0.6 1
vt 0.8 0
vt 0.8 1
vt 1 0.5 0
vn 0 0 1
g skin
usemtl skin
s 1
f 1/1/1 2/2/1 3/3/1 4/4/1
f 2/5 5/7 7/9 6/8 3/6
v 0.5 2 0
vt 0.25 1.5
f -5/-7 -6/-8 -1/-1
"""

# Expected, 0-based: render vertices are the distinct (v, vt) pairs in (v, vt) order.
PAIRS = [(1, 1), (2, 2), (2, 5), (3, 3), (3, 6), (4, 4), (5, 7), (6, 8), (7, 9), (8, 10)]
VT = {
    1: (0, 0), 2: (0.5, 0), 3: (0.5, 1), 4: (0, 1), 5: (0.6, 0), 6: (0.6, 1),
    7: (0.8, 0), 8: (0.8, 1), 9: (1, 0.5), 10: (0.25, 1.5),
}  # fmt: skip
# Fan triangulation as (v, vt) corners: quad → 2 triangles, pentagon → 3, triangle → 1.
TRIANGLES = [
    [(1, 1), (2, 2), (3, 3)],
    [(1, 1), (3, 3), (4, 4)],
    [(2, 5), (5, 7), (7, 9)],
    [(2, 5), (7, 9), (6, 8)],
    [(2, 5), (6, 8), (3, 6)],
    [(4, 4), (3, 3), (8, 10)],
]
POSITIONS = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0], [3, 0.5, 0],
             [0.5, 2, 0]]  # fmt: skip


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def neutral(tmp_path: Path) -> FaceMesh:
    return load_mesh(_write(tmp_path / "neutral.obj", NEUTRAL_OBJ))


# --------------------------------------------------------------------------------------------
# OBJ parsing
# --------------------------------------------------------------------------------------------


def test_obj_polygons_seam_and_negative_indices(neutral: FaceMesh):
    np.testing.assert_array_equal(neutral.rest, np.array(POSITIONS, np.float32))
    assert neutral.n_welded == 8
    assert neutral.n_vertices == len(PAIRS) == 10
    np.testing.assert_array_equal(neutral.weld, [v - 1 for v, _ in PAIRS])
    np.testing.assert_allclose(neutral.uvs, [VT[t] for _, t in PAIRS])
    expected = [[PAIRS.index(corner) for corner in tri] for tri in TRIANGLES]
    np.testing.assert_array_equal(neutral.triangles, expected)
    np.testing.assert_array_equal(
        neutral.welded_triangles, [[v - 1 for v, _ in tri] for tri in TRIANGLES]
    )
    # v2 and v3 are split at the seam: two render vertices each, same welded position.
    assert list(neutral.weld).count(1) == 2 and list(neutral.weld).count(2) == 2
    assert neutral.source.endswith("neutral.obj")


def test_obj_vertex_only_faces_without_uvs_get_uvs_made(tmp_path: Path):
    """No UVs at all: xatlas makes them (tests/test_no_uv_face.py), and says so."""
    from studio.core.mesh.meshio import made_uvs

    for name, faces in [("plain.obj", "f 1 2 3"), ("normals.obj", "f 1//1 2//1 3//1")]:
        path = _write(tmp_path / name, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n" + faces + "\n")
        mesh = load_mesh(path)
        assert mesh.n_welded == 3 and name in made_uvs(mesh)


def test_obj_face_partly_without_uvs_names_the_face(tmp_path: Path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
    text += "f 1/1 2/2 3/3\nf 2 4 3\n"
    with pytest.raises(MeshError, match=r"face 2 \(line 9\) has no texture coordinates"):
        load_mesh(_write(tmp_path / "partial.obj", text))


def test_save_obj_round_trip(neutral: FaceMesh, tmp_path: Path):
    out = tmp_path / "copy.obj"
    save_obj(out, neutral)
    again = load_mesh(out)
    np.testing.assert_array_equal(again.rest, neutral.rest)
    np.testing.assert_array_equal(again.weld, neutral.weld)
    np.testing.assert_array_equal(again.triangles, neutral.triangles)
    np.testing.assert_array_equal(again.uvs, neutral.uvs)


# --------------------------------------------------------------------------------------------
# Key poses
# --------------------------------------------------------------------------------------------


def test_pose_obj_loads_positions_in_file_order(neutral: FaceMesh, tmp_path: Path):
    moved = NEUTRAL_OBJ.replace("v 3 0.5 0 1.0", "v 3 0.75 0.25").replace("v 0 0 0", "v 0 0 -1")
    pose = load_pose(_write(tmp_path / "smile.obj", moved), neutral)
    assert isinstance(pose, KeyPose) and pose.name == "smile"
    expected = np.array(POSITIONS, np.float32)
    expected[0] = [0, 0, -1]
    expected[6] = [3, 0.75, 0.25]
    np.testing.assert_array_equal(pose.positions, expected)
    assert load_pose(tmp_path / "smile.obj", neutral, name="grin").name == "grin"


def test_pose_obj_needs_no_uvs(neutral: FaceMesh, tmp_path: Path):
    lines = [ln for ln in NEUTRAL_OBJ.splitlines() if not ln.startswith("vt")]
    text = "\n".join(lines)
    text = text.replace("f 1/1/1 2/2/1 3/3/1 4/4/1", "f 1 2 3 4")
    text = text.replace("f 2/5 5/7 7/9 6/8 3/6", "f 2 5 7 6 3")
    text = text.replace("f -5/-7 -6/-8 -1/-1", "f -5 -6 -1")
    pose = load_pose(_write(tmp_path / "bare.obj", text), neutral)
    np.testing.assert_array_equal(pose.positions, np.array(POSITIONS, np.float32))


def test_pose_with_fewer_vertices_names_file_and_counts(neutral: FaceMesh, tmp_path: Path):
    text = NEUTRAL_OBJ.replace("v 3 0.5 0 1.0\n", "").replace("7/9", "6/9")
    path = _write(tmp_path / "short_pose.obj", text)
    with pytest.raises(MeshError, match="has 7 vertices, the neutral mesh has 8") as info:
        load_pose(path, neutral)
    assert "short_pose.obj" in str(info.value)


def test_pose_with_changed_face_names_the_first_mismatch(neutral: FaceMesh, tmp_path: Path):
    text = NEUTRAL_OBJ.replace("f -5/-7 -6/-8 -1/-1", "f 4/4 3/3 7/10")
    path = _write(tmp_path / "bad_face.obj", text)
    with pytest.raises(MeshError) as info:
        load_pose(path, neutral)
    message = str(info.value)
    assert "bad_face.obj" in message
    assert "face 3 (line 28) uses vertices (4, 3, 7)" in message
    assert "the neutral mesh's face 3 uses (4, 3, 8)" in message


def test_pose_with_the_same_triangles_but_other_polygons(neutral: FaceMesh, tmp_path: Path):
    # The quad written as the two triangles it becomes: the same topology, accepted.
    same = NEUTRAL_OBJ.replace("f 1/1/1 2/2/1 3/3/1 4/4/1", "f 1/1 2/2 3/3\nf 1/1 3/3 4/4")
    pose = load_pose(_write(tmp_path / "same.obj", same), neutral)
    np.testing.assert_array_equal(pose.positions, neutral.rest)
    # Split along the other diagonal: different triangles, reported as a face-count mismatch.
    other = NEUTRAL_OBJ.replace("f 1/1/1 2/2/1 3/3/1 4/4/1", "f 1/1 2/2 4/4\nf 2/2 3/3 4/4")
    with pytest.raises(MeshError, match="has 4 faces, the neutral mesh has 3"):
        load_pose(_write(tmp_path / "other.obj", other), neutral)


def test_pose_against_a_mesh_not_read_from_obj_compares_triangles(tmp_path: Path):
    mesh = FaceMesh(
        rest=np.array(POSITIONS, np.float32)[:4],
        triangles=np.array([[0, 1, 2], [0, 2, 3]]),
        uvs=np.zeros((4, 2)),
        weld=np.arange(4),
    )
    good = "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 2 3 4\n"
    pose = load_pose(_write(tmp_path / "up.obj", good), mesh)
    np.testing.assert_array_equal(pose.positions[:, 2], 1)
    bad = "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 2 4\nf 2 3 4\n"
    with pytest.raises(MeshError, match=r"triangle 1 uses vertices \(1, 2, 4\)"):
        load_pose(_write(tmp_path / "other.obj", bad), mesh)


# --------------------------------------------------------------------------------------------
# Errors: always MeshError, always naming the file
# --------------------------------------------------------------------------------------------

TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"

BAD_FILES = {
    "nan.obj": (TRI.replace("v 1 0 0", "v 1 nan 0") + "f 1/1 2/2 3/3\n",
                r"vertex 2 \(line 2\) has a non-finite coordinate"),
    "inf.obj": (TRI.replace("v 0 1 0", "v 0 1 inf") + "f 1/1 2/2 3/3\n",
                "vertex 3 .*non-finite"),
    "range.obj": (TRI + "f 1/1 2/2 9/3\n",
                  r"face 1 \(line 7\) refers to vertex 9, but the file has 3"),
    "neg_range.obj": (TRI + "f 1/1 2/2 -4/3\n", "refers to vertex -4, but only 3 come before"),
    "vt_range.obj": (TRI + "f 1/1 2/2 3/7\n", "refers to texture coordinate 7"),
    "zero.obj": (TRI + "f 0/1 2/2 3/3\n", "refers to vertex 0"),
    "two.obj": (TRI + "f 1/1 2/2\n", "face 1 has 2 vertices; a face needs at least 3"),
    "empty.obj": ("", "empty"),
    "blank.obj": ("\n  \n\n", "empty"),
    "garbage.obj": ("this is not a mesh\njust words\n", "no vertices"),
    "no_faces.obj": (TRI, "no faces"),
    "letters.obj": (TRI.replace("v 1 0 0", "v 1 zero 0") + "f 1/1 2/2 3/3\n",
                    r"line 2: cannot read the vertex coordinates"),
    "short_v.obj": (TRI.replace("v 1 0 0", "v 1 0") + "f 1/1 2/2 3/3\n", "three coordinates"),
    "bad_corner.obj": (TRI + "f 1/1 2/x 3/3\n", "line 7: cannot read the face corner '2/x'"),
    "huge.obj": (TRI + "f 1/1 2/2 99999999999999999999/3\n", "line 7: cannot read the face corner"),
    "unknown.foo": (TRI + "f 1/1 2/2 3/3\n", "unknown mesh format"),
    "garbage.ply": ("this is not a ply file\n", "cannot read the mesh"),
    "empty.ply": ("", "empty"),
}  # fmt: skip


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_files_raise_mesh_error_naming_the_file(name: str, tmp_path: Path):
    text, pattern = BAD_FILES[name]
    path = _write(tmp_path / name, text)
    with pytest.raises(MeshError, match=pattern) as info:
        load_mesh(path)
    assert name in str(info.value)
    assert info.value.path == path


def test_binary_garbage(tmp_path: Path):
    for name in ("noise.obj", "noise.glb", "noise.ply"):
        path = tmp_path / name
        path.write_bytes(bytes(range(256)) * 8)
        with pytest.raises(MeshError) as info:
            load_mesh(path)
        assert name in str(info.value)


def test_missing_file_and_directory(tmp_path: Path, neutral: FaceMesh):
    with pytest.raises(MeshError, match="not found") as info:
        load_mesh(tmp_path / "nowhere.obj")
    assert "nowhere.obj" in str(info.value)
    with pytest.raises(MeshError, match="not found"):
        load_pose(tmp_path / "nowhere.obj", neutral)
    with pytest.raises(MeshError, match="not a file"):
        load_mesh(tmp_path)


# --------------------------------------------------------------------------------------------
# Formats read through trimesh
# --------------------------------------------------------------------------------------------


def _as_trimesh(mesh: FaceMesh, positions: np.ndarray | None = None):
    trimesh = pytest.importorskip("trimesh")
    welded = mesh.rest if positions is None else positions
    return trimesh.Trimesh(
        vertices=welded[mesh.weld],
        faces=mesh.triangles,
        visual=trimesh.visual.TextureVisuals(uv=mesh.uvs),
        process=False,
    )


@pytest.mark.parametrize("suffix", [".ply", ".glb"])
def test_trimesh_formats_round_trip(neutral: FaceMesh, tmp_path: Path, suffix: str):
    path = tmp_path / f"face{suffix}"
    _as_trimesh(neutral).export(path)
    mesh = load_mesh(path)
    assert mesh.n_vertices == neutral.n_vertices
    assert mesh.n_welded == neutral.n_welded  # seam copies welded again by position
    np.testing.assert_array_equal(mesh.triangles, neutral.triangles)
    np.testing.assert_allclose(mesh.rest[mesh.weld], neutral.rest[neutral.weld], atol=1e-6)
    np.testing.assert_allclose(mesh.uvs, neutral.uvs, atol=1e-6)
    # Seam copies share a welded position, in first-occurrence order.
    np.testing.assert_array_equal(mesh.weld, [0, 1, 1, 2, 2, 3, 4, 5, 6, 7])

    moved = neutral.rest.copy()
    moved[:, 2] += np.arange(8, dtype=np.float32)
    pose_path = tmp_path / f"raise{suffix}"
    _as_trimesh(neutral, moved).export(pose_path)
    pose = load_pose(pose_path, mesh)
    assert pose.name == "raise"
    np.testing.assert_allclose(pose.positions, moved, atol=1e-6)


def test_trimesh_pose_mismatches(neutral: FaceMesh, tmp_path: Path):
    trimesh = pytest.importorskip("trimesh")
    path = tmp_path / "face.ply"
    _as_trimesh(neutral).export(path)
    mesh = load_mesh(path)

    fewer = trimesh.Trimesh(neutral.rest[:4], [[0, 1, 2], [0, 2, 3]], process=False)
    fewer.export(tmp_path / "fewer.ply")
    with pytest.raises(MeshError, match="has 4 vertices, the neutral mesh has 10") as info:
        load_pose(tmp_path / "fewer.ply", mesh)
    assert "fewer.ply" in str(info.value)

    other = _as_trimesh(neutral)
    other.faces = other.faces[:, [0, 2, 1]]
    other.export(tmp_path / "flipped.ply")
    with pytest.raises(MeshError, match=r"triangle 1 uses vertices \(1, 4, 2\)"):
        load_pose(tmp_path / "flipped.ply", mesh)

    torn = _as_trimesh(neutral)
    vertices = np.array(torn.vertices)
    vertices[2] += 0.5  # a seam copy drifts away from its twin
    torn.vertices = vertices
    torn.export(tmp_path / "torn.ply")
    with pytest.raises(MeshError, match="vertices 2 and 3 are one point"):
        load_pose(tmp_path / "torn.ply", mesh)


def test_trimesh_mesh_without_uvs(tmp_path: Path):
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box().export(tmp_path / "box.ply")
    from studio.core.mesh.meshio import made_uvs

    mesh = load_mesh(tmp_path / "box.ply")  # UVs made by xatlas (issue #37), and said
    assert made_uvs(mesh) == f"no UVs in {tmp_path / 'box.ply'}: made them with xatlas, 6 charts"
    assert mesh.n_welded == 8


def test_save_obj_of_a_pose_reads_back(neutral: FaceMesh, tmp_path: Path):
    moved = neutral.rest * np.float32(1.5) + np.float32(0.1)
    save_obj(tmp_path / "pose.obj", neutral, KeyPose("wide", moved))
    pose = load_pose(tmp_path / "pose.obj", neutral)
    np.testing.assert_array_equal(pose.positions, moved)
    with pytest.raises(MeshError, match="cannot save"):
        save_obj(tmp_path / "x.obj", neutral, moved[:3])
    with pytest.raises(MeshError, match="cannot write"):
        save_obj(tmp_path / "missing_dir" / "x.obj", neutral)


def test_large_obj_loads(tmp_path: Path):
    # 100 × 100 grid written with v/vt/vn corners: exercises the bulk-conversion path.
    n = 100
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    idx = np.arange(n * n).reshape(n, n) + 1
    quads = np.stack(
        [idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()], 1
    )
    lines = [f"v {a} {b} 0" for a, b in zip(x.ravel(), y.ravel(), strict=True)]
    lines += [f"vt {a / n} {b / n}" for a, b in zip(x.ravel(), y.ravel(), strict=True)]
    lines += ["f " + " ".join(f"{i}/{i}/1" for i in q) for q in quads]
    mesh = load_mesh(_write(tmp_path / "grid.obj", "vn 0 0 1\n" + "\n".join(lines) + "\n"))
    assert mesh.n_welded == mesh.n_vertices == n * n
    assert mesh.n_triangles == 2 * (n - 1) ** 2
    np.testing.assert_array_equal(mesh.weld, np.arange(n * n))
    np.testing.assert_array_equal(mesh.triangles[0], [0, 1, n + 1])


# --------------------------------------------------------------------------------------------
# Objects, groups and materials: keeping parts, and marking parts as not face
# --------------------------------------------------------------------------------------------

# A face (two quads, material "skin", a UV seam along v2–v5) and an eye (a triangle, group
# "eyes", material "eye") sharing vertex 5 with the skin, as one OBJ. Quads, two materials, a
# seam: what an artist's export looks like.
PARTS_OBJ = """\
mtllib head.mtl
o Head
v 0 0 0
v 1 0 0
v 2 0 0
v 0 1 0
v 1 1 0
v 2 1 0
v 1 2 0
v 2 2 0
vt 0 0
vt 0.5 0
vt 0 0.5
vt 0.5 0.5
vt 0.6 0
vt 1 0
vt 0.6 0.5
vt 1 0.5
vt 0.5 1
vt 1 1
g skin
usemtl skin
f 1/1 2/2 5/4 4/3
f 2/5 3/6 6/8 5/7
g eyes
usemtl eye
f 5/7 6/8 8/10
f 5/7 8/10 7/9
"""


def _parts(tmp_path: Path, text: str = PARTS_OBJ, name: str = "head.obj") -> Path:
    return _write(tmp_path / name, text)


def _moved(text: str, dz: float = 1.0) -> str:
    """The same OBJ with every vertex raised by ``dz`` (a key pose)."""
    lines = []
    for line in text.splitlines():
        if line.startswith("v "):
            x, y, z = (float(c) for c in line.split()[1:])
            line = f"v {x} {y} {z + dz}"
        lines.append(line)
    return "\n".join(lines) + "\n"


def test_obj_groups_lists_objects_groups_and_materials_with_face_counts(tmp_path: Path):
    from studio.core.mesh.meshio import ObjGroup, obj_groups

    assert obj_groups(_parts(tmp_path)) == [
        ObjGroup("object", "Head", 4),
        ObjGroup("group", "skin", 2),
        ObjGroup("group", "eyes", 2),
        ObjGroup("material", "skin", 2),
        ObjGroup("material", "eye", 2),
    ]
    # Faces before any g/usemtl are OBJ's "default" group and "(no material)".
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nusemtl red\nf 1/1 3/1 2/1\n"
    names = [(g.name, g.faces) for g in obj_groups(_write(tmp_path / "two.obj", text))]
    assert names == [("(no material)", 1), ("red", 1)]


def test_keeping_some_parts_drops_their_faces_and_unused_vertices(tmp_path: Path):
    path = _parts(tmp_path)
    whole = load_mesh(path)
    assert whole.n_welded == 8 and whole.n_triangles == 6
    for keep, kind in ((["skin"], None), (["skin"], "material"), (["skin"], "group")):
        mesh = load_mesh(path, keep=keep, kind=kind)
        # v7 and v8 belong to the eye only; v5 and v6 are shared with the skin and stay.
        np.testing.assert_array_equal(mesh.rest[:, :2], [[0, 0], [1, 0], [2, 0], [0, 1],
                                                         [1, 1], [2, 1]])
        assert mesh.n_triangles == 4
        assert mesh.weld.max() == 5 and len(np.unique(mesh.weld)) == 6
    # The seam survives the cut: v2 and v5 still have two UVs each.
    mesh = load_mesh(path, keep=["skin"])
    assert list(mesh.weld).count(1) == 2 and list(mesh.weld).count(4) == 2
    eye = load_mesh(path, keep=["eyes"])
    assert eye.n_welded == 4 and eye.n_triangles == 2
    # Any of a face's names will do: the skin group or the eye material is everything.
    assert load_mesh(path, keep=["skin", "eye"]).n_triangles == 6
    assert load_mesh(path, keep=["Head"]).n_triangles == 6


def test_key_poses_are_cut_like_the_neutral_mesh(tmp_path: Path):
    path = _parts(tmp_path)
    mesh = load_mesh(path, keep=["skin"])
    # A pose of the whole file: cut by name to the skin.
    pose = load_pose(_parts(tmp_path, _moved(PARTS_OBJ), "up.obj"), mesh)
    np.testing.assert_array_equal(pose.positions, mesh.rest + np.float32([0, 0, 1]))
    # A pose exported without the eye at all (fewer v): fits the cut neutral mesh.
    skin_only = PARTS_OBJ.split("g eyes")[0].replace("v 1 2 0\nv 2 2 0\n", "")
    pose = load_pose(_parts(tmp_path, _moved(skin_only, 2.0), "skin_only.obj"), mesh)
    np.testing.assert_array_equal(pose.positions[:, 2], 2.0)
    # A pose that names no parts (but has the same faces): cut by face number.
    bare = "\n".join(ln for ln in _moved(PARTS_OBJ, 3.0).splitlines()
                     if ln.split()[:1] not in (["g"], ["o"], ["usemtl"]))
    pose = load_pose(_parts(tmp_path, bare, "bare.obj"), mesh)
    np.testing.assert_array_equal(pose.positions[:, 2], 3.0)


def test_a_pose_whose_kept_part_differs_names_the_file_and_face(tmp_path: Path):
    mesh = load_mesh(_parts(tmp_path), keep=["skin"])
    changed = PARTS_OBJ.replace("f 2/5 3/6 6/8 5/7", "f 2/5 3/6 6/8 4/7")
    with pytest.raises(MeshError) as info:
        load_pose(_parts(tmp_path, changed, "changed.obj"), mesh)
    message = str(info.value)
    assert "changed.obj" in message
    assert "face 2 (line 24) uses vertices (2, 3, 6, 4)" in message
    assert "the neutral mesh's face 2 uses (2, 3, 6, 5)" in message
    # Fewer faces and no part names: the cut cannot be made.
    other = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    with pytest.raises(MeshError, match="no part called skin") as info:
        load_pose(_parts(tmp_path, other, "tri.obj"), mesh)
    assert "tri.obj" in str(info.value)


def test_unknown_or_empty_choices_are_clear_errors(tmp_path: Path):
    path = _parts(tmp_path)
    with pytest.raises(MeshError) as info:
        load_mesh(path, keep=["skin", "teeth"])
    message = str(info.value)
    assert "head.obj" in message and "'teeth'" in message
    assert "the file has: eye, eyes, Head, skin" in message
    with pytest.raises(MeshError, match=r"no material named 'eyes' \(the file has: eye, skin\)"):
        load_mesh(path, keep=["eyes"], kind="material")
    with pytest.raises(MeshError, match="no parts are kept") as info:
        load_mesh(path, keep=[])
    assert "head.obj" in str(info.value)
    # A part with no faces cannot be kept: "g" with nothing after it names no part.
    with pytest.raises(MeshError, match="no object, group or material named 'empty'"):
        load_mesh(_write(tmp_path / "e.obj", TRI + "f 1/1 2/2 3/3\ng empty\n"), keep=["empty"])


def test_not_face_vertices_are_those_only_not_face_parts_touch(tmp_path: Path):
    from studio.core.mesh.meshio import not_face_vertices

    mesh = load_mesh(_parts(tmp_path))
    # v5, v6 touch skin and eye faces: skin. v7, v8: eye only.
    np.testing.assert_array_equal(not_face_vertices(mesh, ["eyes"]),
                                  [0, 0, 0, 0, 0, 0, 1, 1])
    np.testing.assert_array_equal(not_face_vertices(mesh, ["eye"]),
                                  not_face_vertices(mesh, ["eyes"]))
    with pytest.raises(MeshError, match="'teeth'"):
        not_face_vertices(mesh, ["teeth"])
    with pytest.raises(MeshError, match="only OBJ"):
        not_face_vertices(FaceMesh(np.eye(3), [[0, 1, 2]], np.zeros((3, 2)), np.arange(3)),
                          ["eyes"])
