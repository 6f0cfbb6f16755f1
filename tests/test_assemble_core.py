"""A new project from loose files (``project_from_files``): a mesh, key-pose meshes, texture
maps, or a glTF that brings its own; UDIM texture sets (``find_tile_set``, ``load_texture``);
which weights show one key pose (``Project.single_pose_weights``); and the tile record of such a
face in a saved project file (read back as written, damage named).

What a user sees: the poses under the names they gave, the parts they kept or marked as not
face (eyes never wrinkle; their tile gets a half-size cell in the atlas), the texture files
they named placed in the atlas with the right fill, and one message naming the file for each
mismatch. Every expectation is worked out by hand from an 8-vertex OBJ on two UDIM tiles.
"""

from __future__ import annotations

import base64
import io
import json
import os
import re
import struct
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import ImageError, MeshError, ProjectError, StudioError
from studio.core.files.images import write_png
from studio.core.formats.assemble import FLAT_NORMAL, project_from_files
from studio.core.formats.gltf.codec import save_gltf
from studio.core.formats.texture_sets import find_tile_set, load_texture
from studio.core.mesh.meshio import load_mesh, not_face_vertices
from studio.core.mesh.uv_tiles import SINGLE, plan_layout
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.wrinkles.textures import SKIN, FaceTextures
from tests.bad_inputs import rewrite_project

pytestmark = pytest.mark.core

# Skin: three triangles on tile 1001 (T1 alone owns v1; T2's corners are all shared with T1 or
# T3). Eye: one triangle on tile 1002 sharing nothing. The names cross kinds on purpose: the
# material "eye" is on a skin face and the material "skin" on the eye.
POSITIONS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 2, 0), (3, 0, 0), (4, 0, 0), (3, 1, 0)]
HEAD_FACES = """vt 0.1 0.1
vt 0.9 0.1
vt 0.1 0.5
vt 0.9 0.5
vt 0.1 0.9
vt 1.1 0.1
vt 1.9 0.1
vt 1.1 0.9
g skin
usemtl eye
f 1/1 2/2 3/3
usemtl lips
f 2/2 4/4 3/3
usemtl face
f 3/3 4/4 5/5
g eye
usemtl skin
f 6/6 7/7 8/8
"""
EYE = [False] * 5 + [True] * 3


@pytest.fixture(autouse=True)
def no_fsync(monkeypatch: pytest.MonkeyPatch) -> None:
    """Files written here need no fsync (durability is not under test; each costs ~10 ms)."""
    monkeypatch.setattr(os, "fsync", lambda _fd: None)


def moved(dz: float) -> np.ndarray:
    """The positions with every z raised by ``dz``, as the key-pose files have them."""
    return np.array(POSITIONS, np.float64) + np.array([0.0, 0.0, dz])


def obj_text(offset: float = 0.0) -> str:
    lines = [f"v {x} {y} {z + offset}" for x, y, z in POSITIONS]
    return "\n".join(lines) + "\n" + HEAD_FACES


@pytest.fixture
def head(tmp_path: Path) -> Path:
    """head.obj with two key poses beside it (files named apart from the poses' names)."""
    (tmp_path / "head.obj").write_text(obj_text())
    (tmp_path / "head_a.obj").write_text(obj_text(0.5))
    (tmp_path / "head_b.obj").write_text(obj_text(-0.25))
    return tmp_path / "head.obj"


def tile(value: int) -> np.ndarray:
    """A uniform 2 × 2 RGB tile."""
    return np.full((2, 2, 3), value, np.uint8)


# --- an OBJ and its key poses -------------------------------------------------------------


def test_poses_take_the_names_given_in_order(head: Path) -> None:
    poses = {"smile": head.parent / "head_a.obj", "frown": head.parent / "head_b.obj"}
    project = project_from_files(head, poses)
    assert project.name == "head"
    assert project.pose_names == ["neutral", "smile", "frown"]
    np.testing.assert_allclose(project.pose("smile").positions, moved(0.5))
    np.testing.assert_allclose(project.pose("frown").positions, moved(-0.25))
    assert project_from_files(head, name="Custom").name == "Custom"


def test_a_face_on_two_tiles_without_maps(head: Path) -> None:
    """Both tiles hold skin: full-size cells side by side in the top half of the atlas; no
    maps given: plain skin colour and flat normals; nothing marked as not face."""
    project = project_from_files(head)
    assert project.mesh.n_welded == 8
    assert project.not_face is None
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.tiles == (1001, 1002)
    assert project.uv_tiles.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.5))
    textures = project.textures
    assert (textures.diffuse == SKIN).all()
    assert (textures.normal_neutral == FLAT_NORMAL).all()
    assert (textures.normal_wrinkled == FLAT_NORMAL).all()


def test_a_pose_named_neutral_is_refused_naming_its_file(head: Path) -> None:
    pose = head.parent / "head_a.obj"
    message = f"{pose}: two key poses are named 'neutral'"
    with pytest.raises(MeshError, match=f"^{re.escape(message)}$"):
        project_from_files(head, {"neutral": pose})


def test_not_face_flags_the_eye_and_shrinks_its_tile(head: Path) -> None:
    """Group "eye" only (not the material of that name): v6-v8. Tile 1002 then holds no skin
    and gets a half-size cell beside 1001's."""
    project = project_from_files(head, not_face=["eye"], part_kind="group")
    assert project.not_face is not None
    assert project.not_face.tolist() == EYE
    assert project.skin_weights().tolist() == [1.0] * 5 + [0.0] * 3
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.25))
    assert project.skin_tiles() == [1001]


def test_not_face_of_any_kind_also_takes_a_material_of_that_name(head: Path) -> None:
    """Without a kind, "eye" is the eye group and the material on T1, which alone owns v1."""
    project = project_from_files(head, not_face=["eye"])
    assert project.not_face is not None
    assert project.not_face.tolist() == [True, *EYE[1:]]


def test_a_part_whose_corners_all_touch_skin_leaves_every_vertex_skin(head: Path) -> None:
    """The material "lips" is T2 only, whose corners all belong to other skin faces too: no
    vertex is flagged, so the project records no not-face flags at all."""
    project = project_from_files(head, not_face=["lips"], part_kind="material")
    assert project.not_face is None
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.5))


def test_marking_every_part_as_not_face_is_refused_naming_them_sorted(head: Path) -> None:
    message = f"{head}: marking eye, skin as not face leaves no skin to wrinkle"
    with pytest.raises(MeshError, match=f"^{re.escape(message)}$"):
        project_from_files(head, not_face=["skin", "eye"], part_kind="group")


def test_keep_of_a_kind_drops_the_other_parts(head: Path) -> None:
    """Group "skin" keeps v1-v5 (one tile: no UV tiles); without a kind, the material "skin"
    on the eye keeps it too."""
    kept = project_from_files(head, keep=["skin"], part_kind="group")
    assert kept.mesh.n_welded == 5 and kept.mesh.n_triangles == 3
    assert kept.uv_tiles is None
    np.testing.assert_allclose(kept.mesh.rest, POSITIONS[:5])
    assert project_from_files(head, keep=["skin"]).mesh.n_welded == 8


# --- a glTF ---------------------------------------------------------------------------------


@pytest.fixture
def foreign_glb(head: Path) -> Path:
    """head.obj as a glTF from another tool: UDIM UVs (no studio tile record), the eye marked
    as not face, one morph target "smile", its own 2 × 2 maps (diffuse 40, normals 50, 60)."""
    mesh = load_mesh(head)
    flags = not_face_vertices(mesh, ["eye"], "group")
    textures = FaceTextures(tile(40), tile(50), tile(60))
    smile = KeyPose("smile", np.array(POSITIONS, np.float32) + np.float32(0.5))
    path = head.parent / "foreign.glb"
    save_gltf(Project("Foreign", mesh, [smile], textures, not_face=flags), path)
    return path


def test_the_studios_own_glb_has_no_parts_to_choose(foreign_glb: Path) -> None:
    message = (f"{foreign_glb}: this file was written by Wrinkle Studio: its face is one mesh, "
               "with no parts to keep or mark")
    with pytest.raises(MeshError, match=f"^{re.escape(message)}$"):
        project_from_files(foreign_glb, keep=["skin"])
    with pytest.raises(MeshError, match=f"^{re.escape(message)}$"):
        project_from_files(foreign_glb, not_face=["eye"])


def test_a_foreign_gltf_is_packed_with_its_own_maps_in_tile_1001(foreign_glb: Path) -> None:
    """Its not-face eye gives tile 1002 a half-size cell; each own map fills 1001's 2 × 2
    cell of a 4 × 4 atlas, the rest skin colour (diffuse) or flat (normals)."""
    project = project_from_files(foreign_glb)
    assert project.name == "Foreign"
    assert project.pose_names == ["neutral", "smile"]
    assert project.not_face is not None and project.not_face.tolist() == EYE
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.cells == ((0.0, 0.0, 0.5), (0.5, 0.0, 0.25))
    for image, value, fill in (
        (project.textures.diffuse, 40, SKIN),
        (project.textures.normal_neutral, 50, FLAT_NORMAL),
        (project.textures.normal_wrinkled, 60, FLAT_NORMAL),
    ):
        assert image.shape == (4, 4, 3)
        assert (image[:2, :2] == value).all()
        assert (image[2:] == fill).all() and (image[:2, 2:] == fill).all()


def test_files_given_with_a_gltf_add_poses_and_replace_its_maps(foreign_glb: Path) -> None:
    """A pose file adds a pose; the named maps replace the glTF's: each lands in its tile's
    cell (1001: top-left 2 × 2, 1002: the 1 × 1 at column 2), the rest of the atlas skin
    colour in the diffuse map and flat in the normal maps; ``name`` renames the project."""
    folder = foreign_glb.parent
    write_png(folder / "skin.png", tile(70))
    write_png(folder / "nrm.1002.png", tile(80))
    write_png(folder / "wr.1001.png", tile(90))
    project = project_from_files(
        foreign_glb,
        {"frown": folder / "head_b.obj"},
        folder / "skin.png",
        folder / "nrm.1002.png",
        folder / "wr.1001.png",
        name="Mine",
    )
    assert project.name == "Mine"
    assert project.pose_names == ["neutral", "smile", "frown"]
    np.testing.assert_allclose(project.pose("frown").positions, moved(-0.25))
    diffuse, neutral, wrinkled = (
        project.textures.diffuse,
        project.textures.normal_neutral,
        project.textures.normal_wrinkled,
    )
    for image in (diffuse, neutral, wrinkled):
        assert image.shape == (4, 4, 3)
    assert (diffuse[:2, :2] == 70).all()
    assert (diffuse[:2, 2:] == SKIN).all() and (diffuse[2:] == SKIN).all()
    assert (neutral[0, 2] == 80).all()
    assert (neutral[:2, :2] == FLAT_NORMAL).all() and (neutral[2:] == FLAT_NORMAL).all()
    assert (neutral[1, 2:] == FLAT_NORMAL).all() and (neutral[0, 3] == FLAT_NORMAL).all()
    assert (wrinkled[:2, :2] == 90).all()
    assert (wrinkled[:2, 2:] == FLAT_NORMAL).all() and (wrinkled[2:] == FLAT_NORMAL).all()


def test_a_pose_file_named_like_a_gltf_pose_is_refused(foreign_glb: Path) -> None:
    pose = foreign_glb.parent / "head_a.obj"
    for name in ("smile", "neutral"):
        message = f"{pose}: two key poses are named '{name}'"
        with pytest.raises(MeshError, match=f"^{re.escape(message)}$"):
            project_from_files(foreign_glb, {name: pose})


def test_the_studios_own_gltf_keeps_its_tile_layout(head: Path) -> None:
    """A glb the studio wrote records each vertex's tile: read back as it was, not re-packed."""
    project = project_from_files(head, not_face=["eye"], part_kind="group")
    save_gltf(project, head.parent / "own.glb")
    back = project_from_files(head.parent / "own.glb")
    assert back.uv_tiles is not None and project.uv_tiles is not None
    assert back.uv_tiles.layout == project.uv_tiles.layout
    assert np.array_equal(back.uv_tiles.vertex_tile, project.uv_tiles.vertex_tile)


def glb_to_gltf(glb: Path, gltf: Path) -> None:
    """The same document as a .gltf: JSON with the binary chunk as a base64 data URI."""
    data = glb.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20 : 20 + json_length])
    bin_start = 20 + json_length
    bin_length = struct.unpack_from("<I", data, bin_start)[0]
    binary = data[bin_start + 8 : bin_start + 8 + bin_length]
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
        binary
    ).decode("ascii")
    gltf.write_text(json.dumps(doc))


def test_a_gltf_text_file_is_read_as_a_gltf(foreign_glb: Path) -> None:
    """.gltf is a glTF like .glb: its morph target comes in as a key pose."""
    path = foreign_glb.with_suffix(".gltf")
    glb_to_gltf(foreign_glb, path)
    project = project_from_files(path)
    assert project.pose_names == ["neutral", "smile"]
    assert project.not_face is not None and project.not_face.tolist() == EYE


# --- UDIM texture sets ----------------------------------------------------------------------


def test_a_tile_set_is_found_among_other_files(tmp_path: Path) -> None:
    """Only NAME.<four digits from 1>.png files count: not other words, five digits, tile
    2001, or a folder named like a tile."""
    for name, value in (
        ("skin.1001.png", 1),
        ("skin.1002.png", 2),
        ("skin.back.png", 3),
        ("skin.1bcd.png", 4),
        ("skin.abcd.png", 5),
        ("skin.10011.png", 6),
        ("skin.2001.png", 7),
        ("skin.1001.jpg", 8),
    ):
        write_png(tmp_path / name, tile(value))
    (tmp_path / "skin.1003.png").mkdir()
    found = find_tile_set(tmp_path / "skin.1002.png")
    assert found.files == {1001: tmp_path / "skin.1001.png", 1002: tmp_path / "skin.1002.png"}
    assert found.pattern == str(tmp_path / "skin.<UDIM>.png")
    token = find_tile_set(tmp_path / "skin.<udim>.png")
    assert token.files == found.files and token.pattern == str(tmp_path / "skin.<udim>.png")
    plain = find_tile_set(tmp_path / "skin.back.png")
    assert plain.files == {1001: tmp_path / "skin.back.png"}
    assert plain.pattern == str(tmp_path / "skin.back.png")


def test_a_tile_file_not_there_yet_is_its_own_set(tmp_path: Path) -> None:
    found = find_tile_set(tmp_path / "skin_1005.png")
    assert found.files == {1005: tmp_path / "skin_1005.png"}
    assert found.pattern == str(tmp_path / "skin_<UDIM>.png")


def test_a_udim_pattern_without_files_is_refused_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "none.<UDIM>.png"
    message = f"{path}: no files match the UDIM pattern (none.1001.png, …)"
    with pytest.raises(ImageError, match=f"^{re.escape(message)}$"):
        find_tile_set(path)


def test_an_untiled_face_takes_tile_1001_else_the_lowest_tile(tmp_path: Path) -> None:
    """With no layout (or the single-tile one) the texture is one file: tile 1001's where the
    set has it (even beside 1000), else its lowest tile."""
    for number in (1000, 1001):
        write_png(tmp_path / f"a.{number}.png", tile(number - 990))
    for number in (1002, 1003):
        write_png(tmp_path / f"b.{number}.png", tile(number - 990))
    fill = np.zeros(3, np.uint8)
    for layout in (None, SINGLE):
        assert np.array_equal(load_texture(tmp_path / "a.1000.png", layout, fill), tile(11))
        assert np.array_equal(load_texture(tmp_path / "b.1003.png", layout, fill), tile(12))
    tiled = load_texture(tmp_path / "b.1003.png", plan_layout([1002, 1003]), fill)
    assert tiled.shape == (4, 4, 3)
    assert (tiled[:2, :2] == 12).all() and (tiled[:2, 2:] == 13).all() and not tiled[2:].any()


# --- one pose's weights ---------------------------------------------------------------------


def test_single_pose_weights_show_one_pose(head: Path) -> None:
    project = project_from_files(head, {"smile": head.parent / "head_a.obj"})
    assert project.single_pose_weights("smile") == {"smile": 1.0}
    assert project.single_pose_weights("smile", 0.25) == {"smile": 0.25}
    assert project.single_pose_weights("neutral") == {}
    with pytest.raises(StudioError, match=r"^unknown pose 'grin' \(poses: neutral, smile\)$"):
        project.single_pose_weights("grin")


# --- the UDIM record of a saved project -----------------------------------------------------


def npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


@pytest.fixture
def saved_udim(head: Path) -> tuple[Path, Project]:
    project = project_from_files(head, not_face=["eye"], part_kind="group")
    save_project(project, head.parent / "head.wrinkle")
    return head.parent / "head.wrinkle", project


def test_a_saved_face_on_two_tiles_comes_back_with_its_tiles(
    saved_udim: tuple[Path, Project],
) -> None:
    path, project = saved_udim
    back = load_project(path)
    assert back.uv_tiles is not None and project.uv_tiles is not None
    assert back.uv_tiles.layout == project.uv_tiles.layout
    assert np.array_equal(back.uv_tiles.vertex_tile, project.uv_tiles.vertex_tile)


@pytest.mark.parametrize(
    ("change", "members", "ending"),
    [
        (
            lambda doc: doc.__setitem__("uv_tiles", [1]),
            None,
            "project.json: uv_tiles must be a JSON object",
        ),
        (
            lambda doc: doc["uv_tiles"].pop("vertex_tile"),
            None,
            "project.json lacks uv_tiles.vertex_tile",
        ),
        (
            lambda doc: doc["uv_tiles"].__setitem__("cells", [[0.7, 0, 0.5], [0, 0, 0.5]]),
            None,
            "project.json: the UV tile layout has a cell outside the square",
        ),
        (
            None,
            {"mesh/vertex_tile.npy": npy(np.zeros(3, np.int16))},
            "'mesh/vertex_tile.npy' (the vertices' UV tiles) has shape (3,), expected (8,)",
        ),
        (
            None,
            {"mesh/vertex_tile.npy": npy(np.full(8, 7, np.int16))},
            "mesh/vertex_tile.npy: a vertex names a UV tile the layout does not have",
        ),
    ],
    ids=["not-an-object", "no-vertex-tiles", "cell-outside", "wrong-count", "unknown-tile"],
)
def test_a_damaged_tile_record_is_refused_naming_the_problem(
    saved_udim: tuple[Path, Project],
    change: Callable[[dict], object] | None,
    members: dict[str, bytes] | None,
    ending: str,
) -> None:
    path, _ = saved_udim
    damaged = path.with_name("damaged.wrinkle")
    rewrite_project(path, damaged, change, members)
    # the whole message: the problem is worded once, naming the member it is in
    with pytest.raises(ProjectError, match=f"^{re.escape(str(damaged))}: {re.escape(ending)}$"):
        load_project(damaged)
