"""OBJ text written by hand, read by the studio's own parser: comments, blank lines, ignored
records, polygons, relative (negative) indices, the ``v``, ``v/vt``, ``v/vt/vn`` and ``v//vn``
corner forms, part names with spaces or bytes that are not UTF-8; every way such a file can be
wrong, each refused with the exact message, the file and the line; key poses that differ from
their neutral mesh in the way a modelling tool would make them differ (polygons re-cut, parts
kept, welded copies pulled apart by more than the tolerance); and ``save_obj``'s exact output.

Why: an artist's OBJ is the studio's main input. A message that names the wrong face or line,
or loses the file name, sends the user searching their scene for the wrong thing, and a pose
accepted with torn seams (or refused for rounding noise) spoils every map baked from it."""

from __future__ import annotations

import errno
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import (
    ObjGroup,
    _read_obj,
    load_mesh,
    load_pose,
    obj_groups,
    save_obj,
)

pytestmark = pytest.mark.core


def _obj(folder: Path, text: str | bytes, name: str = "face.obj") -> Path:
    path = folder / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


def _refused(path: Path, call: Callable[[], object], problem: str) -> None:
    """``call`` raises a MeshError naming ``path`` whose problem is exactly ``problem``."""
    with pytest.raises(MeshError) as caught:
        call()
    assert caught.value.path == path
    assert caught.value.problem == problem


SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
UV4 = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"


# --- reading what a modelling tool writes ---------------------------------------------------------


def test_comments_blank_lines_and_ignored_records_between_the_data(tmp_path: Path) -> None:
    """A quad in ``v/vt/vn`` and a triangle in relative ``v/vt`` indices, with blank lines,
    tabs, ``mtllib``, ``vn`` and ``s`` among them: 5 render vertices, the quad fanned."""
    text = (
        "# hand made\n\nmtllib face.mtl\n"
        + SQUARE
        + "\n"
        + UV4
        + "vn 0 0 1\n\ns off\n"
        + "f 1/1/1\t2/2/1 3/3/1 4/4/1\n\n"
        + "v 2 0.5 0\n"
        + "f -4/-3 -1/-2 -3/-2\n"  # v2/vt2, v5/vt3, v3/vt3
    )
    mesh = load_mesh(_obj(tmp_path, text))
    np.testing.assert_array_equal(
        mesh.rest, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0.5, 0]]
    )
    # render vertices: the distinct (v, vt) pairs in (v, vt) order
    np.testing.assert_array_equal(mesh.weld, [0, 1, 2, 3, 4])
    np.testing.assert_array_equal(mesh.uvs, [[0, 0], [1, 0], [1, 1], [0, 1], [1, 1]])
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [0, 2, 3], [1, 4, 2]])


def test_a_uv_seam_splits_one_position_into_two_render_vertices(tmp_path: Path) -> None:
    text = SQUARE + UV4 + "vt 0.5 0.5\nf 1/1 2/2 3/3\nf 1/5 3/3 4/4\n"
    mesh = load_mesh(_obj(tmp_path, text))
    np.testing.assert_array_equal(mesh.weld, [0, 0, 1, 2, 3])
    np.testing.assert_array_equal(mesh.uvs, [[0, 0], [0.5, 0.5], [1, 0], [1, 1], [0, 1]])
    np.testing.assert_array_equal(mesh.triangles, [[0, 2, 3], [1, 3, 4]])


def test_a_key_pose_written_v_slash_slash_vn_fits_its_neutral_mesh(tmp_path: Path) -> None:
    """Poses need no UVs: ``v//vn`` corners (no texture index) give the positions."""
    neutral = load_mesh(_obj(tmp_path, SQUARE + UV4 + "f 1/1 2/2 3/3 4/4\n"))
    pose_text = SQUARE.replace("1 1 0", "1 1 0.25") + "vn 0 0 1\nf 1//1 2//1 3//1 4//1\n"
    pose = load_pose(_obj(tmp_path, pose_text, "smile.obj"), neutral)
    assert pose.name == "smile"
    np.testing.assert_array_equal(pose.positions[2], [1, 1, 0.25])


def test_part_names_keep_their_spaces_and_bytes_that_are_not_utf8_are_replaced(
    tmp_path: Path,
) -> None:
    """``g left eye`` is one group "left eye"; a Latin-1 é becomes U+FFFD instead of an error."""
    text = (
        SQUARE + UV4 + "g left eye\nf 1/1 2/2 3/3\ng caf\xe9 au lait\nf 1/1 3/3 4/4\n"
        "f 1/1 2/2 4/4\n"
    ).encode("latin-1")
    path = _obj(tmp_path, text)
    assert obj_groups(path) == [
        ObjGroup("group", "left eye", 1),
        ObjGroup("group", "caf\ufffd au lait", 2),
    ]
    assert load_mesh(path, keep=["left eye"]).n_triangles == 1


def test_a_nul_byte_after_the_first_4_kib_is_text(tmp_path: Path) -> None:
    """Only the file's start is sniffed for binary data: a stray NUL in a late comment (the
    file's byte 4097) is tolerated."""
    head = (SQUARE + UV4 + "f 1/1 2/2 3/3\n").encode()
    text = head + b"#" * (4096 - len(head)) + b"\x00\n"
    assert text.index(b"\x00") == 4096
    assert load_mesh(_obj(tmp_path, text)).n_triangles == 1


# --- files that are not meshes ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        (b"", "the file is empty"),
        (b"  \n\t\n", "the file is empty"),
        (b"v 0 0 0\x00\x01\x02", "not an OBJ mesh (the file is binary)"),
        (b"# nothing here\nf 1 2 3\n", "not an OBJ mesh: no vertices ('v' lines) found"),
        (SQUARE.encode(), "the mesh has no faces ('f' lines)"),
    ],
)
def test_files_that_are_not_meshes(tmp_path: Path, text: bytes, problem: str) -> None:
    path = _obj(tmp_path, text)
    _refused(path, lambda: load_mesh(path), problem)


def test_a_file_over_the_size_budget_is_refused_while_reading(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The budget is checked on the open file too (a file that grew after it was checked)."""
    path = _obj(tmp_path, SQUARE)
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FILE_BYTES", "10")
    _refused(
        path,
        lambda: _read_obj(path),
        "the mesh file is 32 bytes, more than the limit of 10 bytes "
        "(set WRINKLE_STUDIO_MAX_FILE_BYTES to raise it)",
    )


def test_a_mesh_over_the_vertex_budget_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _obj(tmp_path, SQUARE + UV4 + "f 1/1 2/2 3/3\n")
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_MESH_VERTICES", "3")
    _refused(
        path,
        lambda: load_mesh(path),
        "the mesh is 4 vertices, more than the limit of 3 vertices "
        "(set WRINKLE_STUDIO_MAX_MESH_VERTICES to change it)",
    )


# --- lines that are wrong -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("v 0 0\n", "line 1: a vertex needs three coordinates"),
        (SQUARE + "vt 0.5\n", "line 5: a texture coordinate needs two numbers (u v)"),
        (SQUARE + "f 1 2\n", "line 5: face 1 has 2 vertices; a face needs at least 3"),
        (
            "v 0 0 0\nv 1 x 2\nv 0 1 0\nf 1 2 3\n",
            "line 2: cannot read the vertex coordinates '1 x 2'",
        ),
        (
            SQUARE + "vt 0 0\nvt a 0.5\nf 1/1 2/2 3/1\n",
            "line 6: cannot read the texture coordinates 'a 0.5'",
        ),
        (
            "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n",
            "vertex 2 (line 2) has a non-finite coordinate (NaN or infinity)",
        ),
        (
            SQUARE + "vt 0 0\nvt nan 1\nf 1/1 2/2 3/1\n",
            "texture coordinate 2 (line 6) is not finite (NaN or infinity)",
        ),
        (SQUARE + UV4 + "f 1/1 2/2 x\n", "line 9: cannot read the face corner 'x'"),
        (SQUARE + UV4 + "f 1/1 2/2 3/b\n", "line 9: cannot read the face corner '3/b'"),
    ],
)
def test_a_wrong_line_is_named_with_its_number(tmp_path: Path, text: str, problem: str) -> None:
    path = _obj(tmp_path, text)
    _refused(path, lambda: load_mesh(path), problem)


@pytest.mark.parametrize(
    ("faces", "problem"),
    [
        ("f 1 2 5\n", "face 1 (line 5) refers to vertex 5, but the file has 4"),
        ("f 0 1 2\n", "face 1 (line 5) refers to vertex 0, but the file has 4"),
        ("f 1 2 3\nf 9 1 2\n", "face 2 (line 6) refers to vertex 9, but the file has 4"),
        ("f 1 2 3\nf 1 3 4\nf 2 3 4 7\n", "face 3 (line 7) refers to vertex 7, but the file has 4"),
        ("f -1 -2 -5\n", "face 1 (line 5) refers to vertex -5, but only 4 come before it"),
    ],
)
def test_a_face_using_a_vertex_that_does_not_exist_is_named(
    tmp_path: Path, faces: str, problem: str
) -> None:
    path = _obj(tmp_path, SQUARE + faces)
    _refused(path, lambda: load_mesh(path), problem)


def test_a_relative_index_counts_only_the_vertices_before_its_face(tmp_path: Path) -> None:
    """``-4`` on line 4 means nothing yet: only 3 ``v`` come before it there."""
    path = _obj(tmp_path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\nv 5 5 5\n")
    _refused(
        path,
        lambda: load_mesh(path),
        "face 1 (line 4) refers to vertex -4, but only 3 come before it",
    )


def test_a_texture_index_out_of_range_is_named(tmp_path: Path) -> None:
    path = _obj(tmp_path, SQUARE + "vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/4\n")
    _refused(
        path,
        lambda: load_mesh(path),
        "face 1 (line 8) refers to texture coordinate 4, but the file has 3",
    )


@pytest.mark.parametrize(
    ("uvs", "faces", "problem"),
    [
        ("vt 0 0\n", "f 1/1 2/1 3/1\nf 1 3 4\n", "face 2 (line 7) has no texture coordinates"),
        (
            "vt 0 0\nvt 1 1\n",
            "f 1/1 2/2 3/1\nf 1//1 3//1 4//1\n",
            "face 2 (line 8) has no texture coordinates",
        ),
    ],
)
def test_faces_without_texture_coordinates_are_refused_for_a_neutral_mesh(
    tmp_path: Path, uvs: str, faces: str, problem: str
) -> None:
    path = _obj(tmp_path, SQUARE + uvs + faces)
    _refused(path, lambda: load_mesh(path), problem)


# --- key poses against their neutral mesh ------------------------------------------------------

FIVE = SQUARE + "v 2 0 0\n"


def test_a_pose_that_cannot_be_parsed_names_the_pose(tmp_path: Path) -> None:
    neutral = load_mesh(_obj(tmp_path, SQUARE + UV4 + "f 1/1 2/2 3/3\n"))
    pose = _obj(tmp_path, SQUARE + "f 1 2 9\n", "pose.obj")
    _refused(
        pose,
        lambda: load_pose(pose, neutral),
        "face 1 (line 5) refers to vertex 9, but the file has 4",
    )


@pytest.mark.parametrize(
    ("neutral_text", "pose_text", "problem"),
    [
        (  # a triangle then a quad, cut as a quad then a triangle: the first face differs
            FIVE + "vt 0 0\nf 1/1 2/1 3/1\nf 3/1 2/1 5/1 4/1\n",
            FIVE + "f 1 2 3 4\nf 3 2 5\n",
            "face 1 (line 6) uses vertices (1, 2, 3, 4), the neutral mesh's face 1 uses (1, 2, 3)",
        ),
        (  # more corners in the first face
            SQUARE + "vt 0 0\nf 1/1 2/1 3/1\nf 1/1 3/1 4/1\n",
            SQUARE + "f 1 2 3 4\nf 1 3 4\n",
            "face 1 (line 5) uses vertices (1, 2, 3, 4), the neutral mesh's face 1 uses (1, 2, 3)",
        ),
        (  # only a later face differs
            FIVE + "vt 0 0\nf 1/1 2/1 3/1\nf 2/1 5/1 3/1\n",
            FIVE + "f 1 2 3\nf 2 5 4\n",
            "face 2 (line 7) uses vertices (2, 5, 4), the neutral mesh's face 2 uses (2, 5, 3)",
        ),
    ],
)
def test_a_pose_whose_polygons_differ_names_the_first_face_that_does(
    tmp_path: Path, neutral_text: str, pose_text: str, problem: str
) -> None:
    neutral = load_mesh(_obj(tmp_path, neutral_text))
    pose = _obj(tmp_path, pose_text, "pose.obj")
    _refused(pose, lambda: load_pose(pose, neutral), problem)


def test_a_pose_against_a_mesh_not_read_from_obj_compares_triangles(tmp_path: Path) -> None:
    """A neutral mesh restored from a project has no OBJ polygons: triangles are compared."""
    neutral = FaceMesh(
        rest=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        triangles=[[0, 1, 2], [0, 2, 3]],
        uvs=np.zeros((4, 2)),
        weld=[0, 1, 2, 3],
    )
    pose = _obj(tmp_path, SQUARE + "f 1 2 3\nf 1 4 3\n", "pose.obj")
    _refused(
        pose,
        lambda: load_pose(pose, neutral),
        "triangle 2 uses vertices (1, 4, 3), the neutral mesh's triangle 2 uses (1, 3, 4)",
    )
    fits = load_pose(_obj(tmp_path, SQUARE + "f 1 2 3 4\n", "quad.obj"), neutral, "fits")
    assert fits.name == "fits"


PARTS = (
    "v 5 5 5\nv 6 5 5\nv 5 6 5\n"  # v1-3: the eye
    + "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"  # v4-7: the skin
    + "vt 0 0\n"
    + "g eye\nf 1/1 2/1 3/1\n"
    + "g skin\nf 4/1 5/1 6/1\nf 4/1 6/1 7/1\n"
)


def test_a_pose_of_the_kept_parts_with_another_vertex_count_says_so(tmp_path: Path) -> None:
    neutral = load_mesh(_obj(tmp_path, PARTS), keep=["skin"])
    extra = PARTS.replace("g skin\n", "v 9 9 9\ng skin\n") + "f 4/1 7/1 8/1\n"
    pose = _obj(tmp_path, extra, "pose.obj")
    _refused(
        pose,
        lambda: load_pose(pose, neutral),
        "has 5 vertices in the parts kept, the neutral mesh has 4",
    )


def test_a_pose_of_the_kept_parts_with_another_face_count_says_so(tmp_path: Path) -> None:
    neutral = load_mesh(_obj(tmp_path, PARTS), keep=["skin"])
    pose = _obj(tmp_path, PARTS + "f 5/1 7/1 6/1\n", "pose.obj")
    _refused(
        pose,
        lambda: load_pose(pose, neutral),
        "has 3 faces in the parts kept, the neutral mesh has 2",
    )


def test_a_pose_of_the_whole_file_with_another_vertex_count_says_so(tmp_path: Path) -> None:
    neutral = load_mesh(_obj(tmp_path, PARTS))
    pose = _obj(tmp_path, "v 0 0 0\n" + PARTS, "pose.obj")
    _refused(pose, lambda: load_pose(pose, neutral), "has 8 vertices, the neutral mesh has 7")


def test_a_changed_face_in_the_kept_parts_is_named_in_the_files_numbers(tmp_path: Path) -> None:
    """The skin's second face is the file's face 3 on line 13, over the file's v 4, 6, 7."""
    neutral = load_mesh(_obj(tmp_path, PARTS), keep=["skin"])
    pose = _obj(tmp_path, PARTS.replace("f 4/1 6/1 7/1", "f 4/1 7/1 6/1"), "pose.obj")
    _refused(
        pose,
        lambda: load_pose(pose, neutral),
        "face 3 (line 13) uses vertices (4, 7, 6), the neutral mesh's face 3 uses (4, 6, 7)",
    )


# --- key poses in other formats: welded copies must stay together ------------------------------


def _seam_mesh(scale: float, offset: float = 0.0) -> FaceMesh:
    """Two triangles over 4 positions; render vertices 2 and 4 (from 1) are one position."""
    rest = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float64) * scale
    rest[:, 0] += offset
    return FaceMesh(
        rest=rest,
        triangles=[[0, 1, 2], [3, 4, 2]],
        uvs=[[0, 0], [1, 0], [0, 1], [0.5, 0.5], [1, 1]],
        weld=[0, 1, 2, 1, 3],
    )


def _ply_pose(folder: Path, mesh: FaceMesh, moved: float, name: str = "pose.ply") -> Path:
    """The mesh's render vertices as an ASCII PLY, the second copy of position 2 moved in x."""
    vertices = mesh.rest[mesh.weld].astype(np.float64)
    vertices[3, 0] += moved
    lines = [
        "ply",
        "format ascii 1.0",
        "element vertex 5",
        "property double x",
        "property double y",
        "property double z",
        "element face 2",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    lines += [" ".join(repr(float(c)) for c in v) for v in vertices]
    lines += ["3 0 1 2", "3 3 4 2"]
    path = folder / name
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def test_welded_copies_a_millionth_of_the_size_apart_are_torn(tmp_path: Path) -> None:
    """The tolerance is a millionth of the mesh's largest extent along an axis: 1 here, though
    the mesh sits 100 units from the origin."""
    mesh = _seam_mesh(1.0, offset=100.0)
    path = _ply_pose(tmp_path, mesh, 2e-5)
    _refused(
        path,
        lambda: load_pose(path, mesh),
        "vertices 2 and 4 are one point in the neutral mesh but apart in this pose",
    )


def test_welded_copies_of_a_tiny_mesh_are_compared_at_its_own_scale(tmp_path: Path) -> None:
    mesh = _seam_mesh(1e-3)
    path = _ply_pose(tmp_path, mesh, 1e-7)
    _refused(
        path,
        lambda: load_pose(path, mesh),
        "vertices 2 and 4 are one point in the neutral mesh but apart in this pose",
    )


def test_welded_copies_within_the_tolerance_of_a_large_mesh_are_one_point(tmp_path: Path) -> None:
    """On a mesh 100 units across, 5e-5 apart is rounding noise; the first copy's position is
    the pose's."""
    mesh = _seam_mesh(100.0)
    pose = load_pose(_ply_pose(tmp_path, mesh, 5e-5), mesh)
    assert pose.name == "pose"
    np.testing.assert_array_equal(pose.positions, mesh.rest)


# --- writing OBJ ---------------------------------------------------------------------------------


def test_save_obj_writes_welded_v_then_render_vt_then_v_vt_faces(tmp_path: Path) -> None:
    mesh = _seam_mesh(1.0)
    mesh.rest[3] = [1, 1, 0.1]
    path = tmp_path / "out.obj"
    save_obj(path, mesh)
    assert path.read_bytes() == (
        b"# Wrinkle Studio mesh\n"
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.100000001\n"
        b"vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\nvt 1 1\n"
        b"f 1/1 2/2 3/3\nf 2/4 4/5 3/3\n"
    )
    # read back: the same welded positions, and every triangle's corners in the same place
    # with the same UVs (render vertices may come back in another order)
    back = load_mesh(path)
    np.testing.assert_array_equal(back.rest, mesh.rest)
    np.testing.assert_array_equal(back.weld[back.triangles], mesh.weld[mesh.triangles])
    np.testing.assert_array_equal(back.uvs[back.triangles], mesh.uvs[mesh.triangles])


def test_save_obj_of_a_pose_or_an_array_reads_back_as_that_pose(tmp_path: Path) -> None:
    mesh = load_mesh(_obj(tmp_path, SQUARE + UV4 + "f 1/1 2/2 3/3 4/4\n"))
    raised = mesh.rest + np.float32([0, 0, 2])
    save_obj(tmp_path / "a.obj", mesh, KeyPose("up", raised))
    save_obj(tmp_path / "b.obj", mesh, raised.tolist())
    for name in ("a.obj", "b.obj"):
        pose = load_pose(tmp_path / name, mesh)
        np.testing.assert_array_equal(pose.positions, raised)


def test_save_obj_refuses_positions_of_another_shape(tmp_path: Path) -> None:
    mesh = _seam_mesh(1.0)
    path = tmp_path / "out.obj"
    _refused(
        path,
        lambda: save_obj(path, mesh, np.zeros((2, 3))),
        "cannot save positions of shape (2, 3) on a mesh of 4 vertices",
    )
    assert not path.exists()


def test_save_obj_into_a_folder_or_a_missing_folder_names_the_path(tmp_path: Path) -> None:
    mesh = _seam_mesh(1.0)
    _refused(
        tmp_path,
        lambda: save_obj(tmp_path, mesh),
        f"cannot write the file ({os.strerror(errno.EISDIR)})",
    )
    missing = tmp_path / "nowhere" / "out.obj"
    _refused(
        missing,
        lambda: save_obj(missing, mesh),
        f"cannot write the file ({os.strerror(errno.ENOENT)})",
    )


def test_corners_of_mixed_forms_are_each_read_as_written(tmp_path: Path) -> None:
    """A face mixing ``v``, ``v/vt`` and ``v/vt/vn`` can have as many slashes in all as a face
    of ``v/vt`` corners: it must still be read corner by corner, not as pairs."""
    tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
    path = _obj(tmp_path, tri + "f 1/1 2/2/1 3\n")
    _refused(path, lambda: load_mesh(path), "face 1 (line 7) has no texture coordinates")
    six = "".join(f"v {i} {i % 2} 0\n" for i in range(6)) + "vt 0 0\nvt 1 0\nvt 0 1\n"
    path = _obj(tmp_path, six + "vn 0 0 1\nf 4/1/1 5/2/1 6/3/1\nf 1/1 2/2 3/3\n", "six.obj")
    mesh = load_mesh(path)
    assert len(mesh.triangles) == 2
    assert np.allclose(mesh.rest[mesh.weld[mesh.triangles[0]]][:, 0], [3, 4, 5])
