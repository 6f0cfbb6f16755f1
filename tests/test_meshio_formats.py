"""Meshes and key poses in the formats read through trimesh (PLY, OFF, STL, glTF), written by
hand byte for byte: positions, triangles, UVs, welding, and the errors that name the file; and
the parts (objects, groups, materials) of an OBJ kept for a key pose."""

from __future__ import annotations

import base64
import json
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

from studio.core.files.errors import MeshError
from studio.core.mesh.meshio import load_mesh, load_pose, not_face_vertices, obj_groups
from tests.test_meshio import PARTS_OBJ, _write

pytestmark = pytest.mark.core


# --------------------------------------------------------------------------------------------
# Writers for tiny files
# --------------------------------------------------------------------------------------------


def _ply(path: Path, vertices: list[list[object]], faces: list[list[int]],
         uv: bool = True) -> Path:
    """An ASCII PLY: x y z (and s t when ``uv``) per vertex, one index list per face."""
    header = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}",
              "property float x", "property float y", "property float z"]
    if uv:
        header += ["property float s", "property float t"]
    header += [f"element face {len(faces)}", "property list uchar int vertex_indices",
               "end_header"]
    body = [" ".join(str(c) for c in v) for v in vertices]
    body += [f"{len(f)} " + " ".join(str(i) for i in f) for f in faces]
    path.write_text("\n".join(header + body) + "\n", encoding="ascii")
    return path


def _off(path: Path, vertices: list[list[object]], faces: list[list[int]]) -> Path:
    """An OFF file: positions only, no UVs."""
    lines = ["OFF", f"{len(vertices)} {len(faces)} 0"]
    lines += [" ".join(str(c) for c in v) for v in vertices]
    lines += [f"{len(f)} " + " ".join(str(i) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def _binary_stl(path: Path, triangles: list[list[list[float]]]) -> Path:
    """A binary STL: 80-byte header, count, then normal, three corners and 2 spare bytes each."""
    data = b"made by hand".ljust(80, b" ") + struct.pack("<I", len(triangles))
    for tri in triangles:
        data += struct.pack("<12fH", 0, 0, 0, *[c for corner in tri for c in corner], 0)
    path.write_bytes(data)
    return path


def _ascii_stl(path: Path, triangles: list[list[list[float]]], name: str = "face") -> Path:
    lines = [f"solid {name}"]
    for tri in triangles:
        lines += ["facet normal 0 0 1", "outer loop"]
        lines += [f"vertex {x} {y} {z}" for x, y, z in tri]
        lines += ["endloop", "endfacet"]
    lines.append(f"endsolid {name}")
    path.write_bytes(("\n".join(lines) + "\n").encode("utf-8"))
    return path


def _gltf(path: Path, positions: list[list[float]], uvs: list[list[float]],
          indices: list[int], uv_type: str = "VEC2") -> Path:
    """A .gltf with one textured triangle-list primitive, its buffer inline as a data URI."""
    pos = np.asarray(positions, "<f4")
    tex = np.asarray(uvs, "<f4")
    idx = np.asarray(indices, "<u4")
    blob = pos.tobytes() + tex.tobytes() + idx.tobytes()
    views = [(0, pos.nbytes), (pos.nbytes, tex.nbytes), (pos.nbytes + tex.nbytes, idx.nbytes)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {}}],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(blob).decode("ascii")}],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
             "min": pos.min(axis=0).tolist(), "max": pos.max(axis=0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(tex), "type": uv_type},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
    }
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


# A unit square as two triangles whose render vertices 1 and 4 share a position but not a UV
# (a seam), with x y z s t per vertex.
SQUARE = [
    [0, 0, 0, 0.0, 0.0],
    [1, 0, 0, 0.5, 0.0],
    [1, 1, 0, 0.5, 0.5],
    [0, 1, 0, 0.0, 0.5],
    [1, 0, 0, 0.75, 0.25],
]
SQUARE_FACES = [[0, 1, 2], [0, 2, 3], [4, 2, 0]]


def _raises(path: Path, message: str, call=None) -> MeshError:
    """Loading ``path`` (or ``call()``) raises MeshError whose whole text is '<path>: message'."""
    with pytest.raises(MeshError) as info:
        load_mesh(path) if call is None else call()
    assert info.value.path == path
    assert str(info.value) == f"{path}: {message}"
    return info.value


# --------------------------------------------------------------------------------------------
# Reading meshes
# --------------------------------------------------------------------------------------------


def test_ply_render_vertices_are_the_file_s_and_equal_positions_are_welded(tmp_path: Path):
    """A PLY's vertices become render vertices in file order; equal positions share a weld."""
    path = _ply(tmp_path / "square.ply", SQUARE, SQUARE_FACES)
    mesh = load_mesh(path)
    assert mesh.source == str(path)
    np.testing.assert_array_equal(mesh.rest, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    np.testing.assert_array_equal(mesh.weld, [0, 1, 2, 3, 1])
    np.testing.assert_array_equal(mesh.triangles, SQUARE_FACES)
    np.testing.assert_array_equal(mesh.uvs, [[0, 0], [0.5, 0], [0.5, 0.5], [0, 0.5],
                                             [0.75, 0.25]])


def test_ply_copies_with_the_same_position_and_uv_stay_apart(tmp_path: Path):
    """Two PLY vertices equal in position and UV are kept as the file has them (not merged)."""
    vertices = [[0, 0, 0, 0, 0], [1, 0, 0, 1, 0], [0, 1, 0, 0, 1], [1, 0, 0, 1, 0]]
    mesh = load_mesh(_ply(tmp_path / "dup.ply", vertices, [[0, 1, 2], [0, 3, 2]]))
    assert mesh.n_vertices == 4
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [0, 3, 2]])
    np.testing.assert_array_equal(mesh.weld, [0, 1, 2, 1])


def test_a_single_triangle_ply_is_a_mesh(tmp_path: Path):
    """One triangle is enough for a mesh."""
    path = _ply(tmp_path / "tri.ply", SQUARE[:3], [[0, 1, 2]])
    mesh = load_mesh(path)
    assert mesh.n_triangles == 1 and mesh.n_welded == 3


def test_gltf_uvs_are_flipped_to_a_lower_left_origin(tmp_path: Path):
    """glTF's texture origin is top left: v becomes 1 - v, positions and triangles stay."""
    positions = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    path = _gltf(tmp_path / "quad.gltf", positions,
                 [[0, 0.25], [1, 0.25], [1, 1], [0, 1]], [0, 1, 2, 0, 2, 3])
    mesh = load_mesh(path)
    np.testing.assert_array_equal(mesh.rest, positions)
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [0, 2, 3]])
    np.testing.assert_allclose(mesh.uvs, [[0, 0.75], [1, 0.75], [1, 0], [0, 0]])


def test_gltf_texture_coordinates_with_a_third_component_keep_u_and_v(tmp_path: Path):
    """Extra texture-coordinate components are dropped: only u and v are the mesh's UVs."""
    path = _gltf(tmp_path / "uvw.gltf", [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                 [[0, 0, 9], [1, 0, 9], [0, 1, 9]], [0, 1, 2], uv_type="VEC3")
    mesh = load_mesh(path)
    np.testing.assert_allclose(mesh.uvs, [[0, 1], [1, 1], [0, 0]])


def test_gltf_with_fewer_texture_coordinates_than_vertices_is_refused(tmp_path: Path):
    """UVs that do not cover every vertex are 'no texture coordinates', naming the file."""
    path = _gltf(tmp_path / "short.gltf", [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                 [[0, 0], [1, 0]], [0, 1, 2])
    _raises(path, "the mesh has no texture coordinates (UVs); export it with UVs")


# --------------------------------------------------------------------------------------------
# Errors naming the file
# --------------------------------------------------------------------------------------------


def test_formats_without_uvs_get_uvs_made_and_say_so(tmp_path: Path):
    """OFF and STL carry no UVs: the neutral mesh gets them from xatlas (issue #37), and the
    line a user reads says so."""
    from studio.core.mesh.meshio import made_uvs

    tri = [[[0, 0, 0], [1, 0, 0], [0, 1, 0]]]
    for path in (_off(tmp_path / "tri.off", tri[0], [[0, 1, 2]]),
                 _binary_stl(tmp_path / "tri.stl", tri),
                 _ascii_stl(tmp_path / "text.stl", tri)):
        mesh = load_mesh(path)
        assert made_uvs(mesh) == f"no UVs in {path}: made them with xatlas, 1 charts"
        assert mesh.n_welded == 3 and (mesh.uvs >= 0).all() and (mesh.uvs <= 1).all()


def test_unknown_format_names_what_the_studio_reads(tmp_path: Path):
    """An unknown suffix is refused in words a user knows (OBJ, glTF/GLB, FBX, USD), not
    trimesh's format names; neither archives, point clouds nor compound suffixes among them."""
    path = tmp_path / "face.foo"
    path.write_text("whatever\n")
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert info.value.path == path
    assert info.value.problem == ("unknown mesh format '.foo': the studio reads OBJ, PLY, STL, "
                                  "OFF, glTF/GLB, VRM, FBX and USD")


@pytest.mark.parametrize("name", ["points.xyz", "face.ply.bz2", "face.zip", "face.XYZ"])
def test_archives_and_point_clouds_are_not_mesh_formats(tmp_path: Path, name: str):
    """.xyz point clouds and .zip/.bz2 archives are unknown formats, even holding a good PLY."""
    import bz2
    import zipfile

    ply = _ply(tmp_path / "inner.ply", SQUARE, SQUARE_FACES).read_bytes()
    path = tmp_path / name
    if name.endswith(".zip"):
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("face.ply", ply)
    elif name.endswith(".bz2"):
        path.write_bytes(bz2.compress(ply))
    else:
        path.write_text("0 0 0\n1 0 0\n0 1 0\n")
    with pytest.raises(MeshError, match=r"^.*: unknown mesh format '\.[a-zA-Z0-9]+': the studio "
                                        r"reads OBJ, "):
        load_mesh(path)


def test_empty_and_one_byte_files(tmp_path: Path):
    """A 0-byte file is 'empty'; a 1-byte one is a file trimesh cannot read, with its error."""
    empty = tmp_path / "empty.ply"
    empty.write_bytes(b"")
    _raises(empty, "the file is empty")
    one = tmp_path / "one.ply"
    one.write_bytes(b"x")
    with pytest.raises(MeshError, match=r"^.*one\.ply: cannot read the mesh \(ValueError: "):
        load_mesh(one)


def test_garbage_names_the_exception_kind(tmp_path: Path):
    """What trimesh raises is reported with its exception type and text."""
    path = tmp_path / "garbage.ply"
    path.write_text("garbage\n")
    _raises(path, "cannot read the mesh (ValueError: Not a ply file!)")


def test_a_text_stl_with_non_ascii_bytes_is_refused_before_trimesh(tmp_path: Path):
    """A text STL is checked for ASCII: the é in its name is reported as the byte it is."""
    tri = [[[0, 0, 0], [1, 0, 0], [0, 1, 0]]]
    path = _ascii_stl(tmp_path / "cafe.stl", tri, name="café")
    _raises(path, "a text STL must be ASCII, but byte 10 is 0xc3 (damaged, or another kind of "
                  "file)")


def test_a_ply_starting_like_a_text_stl_is_not_checked_as_stl(tmp_path: Path):
    """Only .stl files get the STL text check: other files go straight to their reader."""
    path = tmp_path / "solid.ply"
    path.write_bytes(b"solid \xff\xfe\n")
    with pytest.raises(MeshError, match=r"cannot read the mesh \(ValueError"):
        load_mesh(path)


def test_a_file_without_vertices_is_empty(tmp_path: Path):
    """Zero vertices: 'the mesh is empty (no vertices)', for meshes and key poses alike."""
    _raises(_ply(tmp_path / "none.ply", [], []), "the mesh is empty (no vertices)")
    neutral = load_mesh(_ply(tmp_path / "n.ply", SQUARE, SQUARE_FACES))
    path = _off(tmp_path / "none.off", [], [])
    _raises(path, "the mesh is empty (no vertices)", lambda: load_pose(path, neutral))


def test_a_file_without_faces(tmp_path: Path):
    """Vertices but no faces: 'the mesh has no faces'."""
    path = _off(tmp_path / "points.off", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [])
    _raises(path, "the mesh has no faces")


def test_a_non_finite_vertex_is_named(tmp_path: Path):
    """The first vertex with NaN or infinity is named, counted from 1."""
    vertices = [v[:] for v in SQUARE]
    vertices[2][1] = "nan"
    vertices[3][0] = "inf"
    path = _ply(tmp_path / "nan.ply", vertices, SQUARE_FACES)
    _raises(path, "vertex 3 has a non-finite coordinate (NaN or infinity)")


@pytest.mark.filterwarnings("ignore:invalid value encountered in cast:RuntimeWarning")  # trimesh
def test_a_non_finite_texture_coordinate_is_named(tmp_path: Path):
    """The first vertex whose UV has NaN is named, counted from 1."""
    vertices = [v[:] for v in SQUARE]
    vertices[1][4] = "nan"
    path = _ply(tmp_path / "nan_uv.ply", vertices, SQUARE_FACES)
    _raises(path, "vertex 2 has a non-finite texture coordinate")


@pytest.mark.parametrize(("bad", "face"), [(3, 2), (-1, 2), (7, 3)])
def test_a_face_using_a_missing_vertex_is_named(tmp_path: Path, bad: int, face: int):
    """A face index past the last vertex (or negative) names the face, counted from 1."""
    faces = [[0, 1, 2], [0, 2, 1], [1, 2, 0]]
    faces[face - 1] = [2, bad, 1]
    path = _ply(tmp_path / "range.ply", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces, uv=False)
    _raises(path, f"face {face} refers to a vertex that does not exist (the mesh has 3)")


def test_the_vertex_budget_names_the_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """A mesh over the vertex budget is refused naming the file and the setting."""
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_MESH_VERTICES", "4")
    path = _ply(tmp_path / "big.ply", SQUARE, SQUARE_FACES)
    error = _raises(path, "the mesh is 5 vertices, more than the limit of 4 vertices (set "
                          "WRINKLE_STUDIO_MAX_MESH_VERTICES to change it)")
    assert error.path == path


def test_without_trimesh_other_formats_say_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """Without trimesh installed, a PLY is refused with that reason, naming the file."""
    path = _ply(tmp_path / "face.ply", SQUARE, SQUARE_FACES)
    monkeypatch.setitem(sys.modules, "trimesh", None)
    _raises(path, "cannot read .ply files: trimesh is not installed")


def test_a_file_that_is_not_a_triangle_mesh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """What trimesh reads as something other than a triangle mesh (a point cloud) is refused."""
    trimesh = pytest.importorskip("trimesh")
    path = _ply(tmp_path / "cloud.ply", SQUARE, SQUARE_FACES)
    monkeypatch.setattr(trimesh, "load", lambda *a, **k: trimesh.PointCloud(np.eye(3)))
    _raises(path, "the file holds no triangle mesh")


def test_unreadable_texture_coordinates_are_a_mesh_error(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch):
    """UVs a reader hands back that are not numbers are refused naming the file."""
    trimesh = pytest.importorskip("trimesh")
    from types import SimpleNamespace

    class Odd(trimesh.Trimesh):
        visual = property(lambda self: SimpleNamespace(uv="n/a"), lambda self, value: None)

    path = _ply(tmp_path / "odd.ply", SQUARE, SQUARE_FACES)
    odd = Odd(vertices=np.eye(3), faces=[[0, 1, 2]], process=False)
    monkeypatch.setattr(trimesh, "load", lambda *a, **k: odd)
    _raises(path, "cannot read the mesh (could not convert string to float: 'n/a')")


# --------------------------------------------------------------------------------------------
# Key poses in other formats
# --------------------------------------------------------------------------------------------


def _tris(vertices: list[list[float]], faces: list[list[int]]) -> list[list[list[float]]]:
    return [[vertices[i] for i in face] for face in faces]


def test_an_stl_pose_fits_a_neutral_mesh_with_one_vertex_per_corner(tmp_path: Path):
    """Binary and text STL poses (three vertices a triangle) load onto a matching neutral mesh:
    welded positions come from the pose, seam copies agreeing."""
    corners = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 0], [1, 1, 0], [0, 1, 0]]
    uvs = [[0, 0], [0.5, 0], [0.5, 0.5], [0, 0], [0.5, 0.5], [0, 0.5]]
    faces = [[0, 1, 2], [3, 4, 5]]
    neutral = load_mesh(_ply(tmp_path / "n.ply", [c + u for c, u in zip(corners, uvs,
                                                                        strict=True)], faces))
    np.testing.assert_array_equal(neutral.weld, [0, 1, 2, 0, 2, 3])
    moved = [[x, y, 0.25 * (x + 2 * y)] for x, y, _ in corners]
    expected = [[0, 0, 0], [1, 0, 0.25], [1, 1, 0.75], [0, 1, 0.5]]
    for path in (_binary_stl(tmp_path / "up.stl", _tris(moved, faces)),
                 _ascii_stl(tmp_path / "up_text.stl", _tris(moved, faces))):
        pose = load_pose(path, neutral)
        assert pose.name == path.stem
        np.testing.assert_array_equal(pose.positions, expected)


def test_a_pose_with_other_triangle_count_is_refused(tmp_path: Path):
    """Same vertices but a triangle fewer: both counts are named, with the file."""
    neutral = load_mesh(_ply(tmp_path / "n.ply", SQUARE, SQUARE_FACES))
    path = _off(tmp_path / "fewer.off", [v[:3] for v in SQUARE], SQUARE_FACES[:2])
    _raises(path, "has 2 triangles, the neutral mesh has 3", lambda: load_pose(path, neutral))


def test_a_pose_with_a_different_later_triangle_names_it(tmp_path: Path):
    """The first differing triangle (here the second) is named with both vertex lists."""
    neutral = load_mesh(_ply(tmp_path / "n.ply", SQUARE, SQUARE_FACES))
    faces = [[0, 1, 2], [0, 3, 2], [4, 2, 0]]
    path = _off(tmp_path / "flip.off", [v[:3] for v in SQUARE], faces)
    _raises(path, "triangle 2 uses vertices (1, 4, 3), the neutral mesh's triangle 2 uses "
                  "(1, 3, 4)", lambda: load_pose(path, neutral))


# --------------------------------------------------------------------------------------------
# OBJ parts kept for key poses
# --------------------------------------------------------------------------------------------

PARTS = PARTS_OBJ  # the artist's head of tests/test_meshio.py: skin quads, an eye


def _raised(text: str) -> str:
    """The same OBJ with every vertex one unit higher in z."""
    return "\n".join(f"v {ln.split()[1]} {ln.split()[2]} 1" if ln.startswith("v ") else ln
                     for ln in text.splitlines()) + "\n"


def test_a_pose_exported_with_only_the_kept_material_fits(tmp_path: Path):
    """Keeping material 'skin': a pose holding only skin faces is cut by name and fits."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin"], kind="material")
    skin_only = PARTS.split("g eyes")[0].replace("v 1 2 0\nv 2 2 0\n", "")
    pose = load_pose(_write(tmp_path / "skin.obj", _raised(skin_only)), neutral)
    np.testing.assert_array_equal(pose.positions, neutral.rest + np.float32([0, 0, 1]))


def test_a_pose_naming_the_kept_part_as_another_kind_is_cut_by_face_number(tmp_path: Path):
    """Keeping material 'skin': a pose where 'skin' is only a group is cut by face number."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin"], kind="material")
    renamed = _raised(PARTS).replace("usemtl skin", "usemtl flesh")
    pose = load_pose(_write(tmp_path / "renamed.obj", renamed), neutral)
    np.testing.assert_array_equal(pose.positions, neutral.rest + np.float32([0, 0, 1]))


def test_a_pose_is_cut_by_the_kind_of_name_the_neutral_mesh_kept(tmp_path: Path):
    """Keeping material 'skin': a pose whose eye faces are in group 'skin' still drops them."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin"], kind="material")
    regrouped = _raised(PARTS).replace("g eyes", "g skin")
    pose = load_pose(_write(tmp_path / "regrouped.obj", regrouped), neutral)
    assert len(pose.positions) == 6
    np.testing.assert_array_equal(pose.positions[:, 2], 1)


def test_a_pose_that_cannot_be_cut_lists_the_missing_names(tmp_path: Path):
    """A pose naming none of the kept parts and with other faces lists every missing name."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin", "eye"],
                        kind="material")
    path = _write(tmp_path / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\ng skin\nf 1 2 3\n")
    _raises(path, "names no part called eye, skin (kept from the neutral mesh) and has 1 faces, "
                  "the neutral file 4: export the key pose with the same objects, groups and "
                  "materials", lambda: load_pose(path, neutral))


def test_a_kept_part_s_mismatch_is_named_in_the_file_s_numbers(tmp_path: Path):
    """Keeping the eye (faces 3-4, v5-v8): a changed eye face is named with the file's face,
    line and v numbers, not the numbers after the cut."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["eyes"])
    assert neutral.n_welded == 4
    changed = PARTS.replace("f 5/7 8/10 7/9", "f 6/7 8/10 7/9")
    path = _write(tmp_path / "changed.obj", changed)
    _raises(path, "face 4 (line 28) uses vertices (6, 8, 7), the neutral mesh's face 4 uses "
                  "(5, 8, 7)", lambda: load_pose(path, neutral))


def test_not_face_parts_of_a_mesh_cut_to_some_parts(tmp_path: Path):
    """Part names still mark not-face vertices on a mesh loaded with only some parts kept."""
    neutral = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin", "eyes"],
                        kind="group")
    np.testing.assert_array_equal(not_face_vertices(neutral, ["eye"]),
                                  [0, 0, 0, 0, 0, 0, 1, 1])
    skin = load_mesh(_write(tmp_path / "head.obj", PARTS), keep=["skin"])
    np.testing.assert_array_equal(not_face_vertices(skin, ["skin"]), [1, 1, 1, 1, 1, 1])


def test_obj_groups_of_a_broken_obj_names_the_file(tmp_path: Path):
    """Listing the parts of an OBJ that cannot be parsed is a MeshError naming the file."""
    path = _write(tmp_path / "broken.obj", "v 0 0 zero\nvt 0 0\nf 1/1 1/1 1/1\n")
    with pytest.raises(MeshError, match="line 1") as info:
        obj_groups(path)
    assert info.value.path == path


def test_not_face_vertices_of_the_whole_file(tmp_path: Path):
    """Skin marked: only v1-v4 are skin alone (v5, v6 touch the eye); a v no face uses is
    never marked."""
    path = _write(tmp_path / "head.obj", PARTS + "v 9 9 9\n")
    mesh = load_mesh(path)
    assert mesh.n_welded == 9
    np.testing.assert_array_equal(not_face_vertices(mesh, ["skin"]),
                                  [1, 1, 1, 1, 0, 0, 0, 0, 0])
    np.testing.assert_array_equal(not_face_vertices(mesh, ["skin", "eye"]),
                                  [1, 1, 1, 1, 1, 1, 1, 1, 0])


def test_not_face_names_are_checked_against_their_kind_and_name_the_file(tmp_path: Path):
    """An unknown part name, or a material asked for as a group, is an error naming the file."""
    path = _write(tmp_path / "head.obj", PARTS)
    mesh = load_mesh(path)
    _raises(path, "no group named 'eye' (the file has: eyes, skin)",
            lambda: not_face_vertices(mesh, ["eye"], kind="group"))
    _raises(path, "no object, group or material named 'teeth' (the file has: eye, eyes, Head, "
                  "skin)", lambda: not_face_vertices(mesh, ["teeth"]))


def test_not_face_parts_need_an_obj(tmp_path: Path):
    """A mesh from a PLY has no parts to mark: the error says so and names the file."""
    path = _ply(tmp_path / "square.ply", SQUARE, SQUARE_FACES)
    mesh = load_mesh(path)
    _raises(path, "only OBJ files have groups or materials to mark as not-face",
            lambda: not_face_vertices(mesh, ["eyes"]))


def test_keeping_unknown_parts_lists_them_all_or_says_the_file_has_none(tmp_path: Path):
    """Every unknown name is listed; a kind the file never names is 'none'; a kind that is not
    one of object, group or material is a programming error."""
    path = _write(tmp_path / "head.obj", PARTS)
    _raises(path, "no group named 'lips', 'teeth' (the file has: eyes, skin)",
            lambda: load_mesh(path, keep=["teeth", "lips"], kind="group"))
    bare = _write(tmp_path / "bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n")
    _raises(bare, "no material named 'skin' (the file has: none)",
            lambda: load_mesh(bare, keep=["skin"], kind="material"))
    with pytest.raises(ValueError, match=r"^kind must be one of \('object', 'group', "
                                         r"'material'\), got 'part'$"):
        load_mesh(path, keep=["skin"], kind="part")
