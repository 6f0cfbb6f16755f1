"""glTF scenes, not first meshes: an avatar's face found among ten meshes (eyes first, a skin,
quantized and sparse accessors, JPEG images, a scene at 1.6 m), node transforms by matrix and
TRS, sparse accessors, strips and fans, texture transforms, several meshes merged into one
face with one pose per target name, ``keep``/``not_face`` by glTF names, the refusals of
compressed files and unknown required extensions, and the not-face suggestion by names, small
closed shells and rigid motion. Expected values are worked out by hand from the files built."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from studio.core.files.errors import MeshError
from studio.core.formats.assemble import project_from_files, suggest_not_face
from studio.core.formats.face_parts import Part, is_closed, moves_rigidly, suggest_parts
from studio.core.formats.gltf.codec import load_gltf
from tests.gltf_avatar import MESHES, TARGETS, build_avatar, to_world
from tests.production_head import build_head
from tests.test_gltf_load_core import POSITIONS, SMILE, UVS, Doc, face

pytestmark = pytest.mark.core

ICT_NOT_SKIN = ["M_EyeBlend", "M_EyeLashes", "M_EyeOcclusion", "M_GumsTongue", "M_IrisLeft",
                "M_IrisRight", "M_LacrimalFluid", "M_ScleraLeft", "M_ScleraRight", "M_Teeth"]


@pytest.fixture(scope="module")
def avatar(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_avatar(tmp_path_factory.mktemp("avatar") / "avatar.glb")


def matching_rows(actual: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """The rows of ``actual`` in ``expected``'s order (the reader numbers welded vertices by
    first use, the builder by its own list): matched by sorting both."""
    key = np.round(np.asarray(actual, np.float64), 5)
    want = np.round(np.asarray(expected, np.float64), 5)
    a, e = np.lexsort(key.T[::-1]), np.lexsort(want.T[::-1])
    out = np.empty(len(e), np.int64)
    out[e] = a
    return out


def refused(path: Path, problem: str, **kwargs: object) -> None:
    with pytest.raises(MeshError) as info:
        load_gltf(path, **kwargs)  # type: ignore[arg-type]
    assert str(info.value) == f"{path}: {problem}"


# --- the avatar --------------------------------------------------------------------------------
def test_the_avatar_s_face_is_found_with_eyes_and_teeth_not_face(avatar: Path) -> None:
    report: list[str] = []
    project = load_gltf(avatar, report=report)
    head = build_head("m", up="y")
    skin, eye_l, eye_r, teeth = head.parts
    assert report == [
        "glTF scene: 10 meshes; the face: EyeLeft, EyeRight, Head, Teeth "
        f"({project.mesh.n_welded} vertices, 67 morph targets)",
        "not face: EyeLeft (name), EyeRight (name), Teeth (name)",
        "left out (no morph targets): Hair, Glasses, Body, OutfitTop, OutfitBottom, Shoes",
        "skinned (EyeLeft, EyeRight, Head): the bind pose is used, the joints are not applied"]
    assert project.pose_names == ["neutral", *TARGETS]
    # the eyes (spheres: their seam welded), the head as welded, the teeth, in file order
    sizes = [len(np.unique(p.rest, axis=0)) for p in (eye_l, eye_r)]
    counts = [*sizes, len(skin.rest), len(teeth.rest)]
    assert project.mesh.n_welded == sum(counts)
    flags = project.not_face
    assert flags is not None
    starts = np.cumsum([0, *counts])
    assert flags[:starts[2]].all() and flags[starts[3]:].all()
    assert not flags[starts[2]:starts[3]].any()
    # the skinned head in its bind pose (its node's 5 m translation ignored), metres, Y up
    rest = project.mesh.rest[starts[2]:starts[3]]
    rows = matching_rows(rest, to_world(skin.rest))
    np.testing.assert_allclose(rest[rows], to_world(skin.rest), atol=1e-6)
    # the teeth: int16 positions through a TRS node under a matrix node
    step = np.ptp(to_world(teeth.rest), axis=0).max() / 32000.0
    teeth_rest = project.mesh.rest[starts[3]:]
    np.testing.assert_allclose(teeth_rest[matching_rows(teeth_rest, to_world(teeth.rest))],
                               to_world(teeth.rest), atol=step)
    # a pose: the skin moved as the production head's, the eyes and teeth still
    smile = project.pose("mouthSmileLeft").positions
    np.testing.assert_allclose(smile[starts[2]:starts[3]][rows],
                               to_world(skin.poses["mouthSmile_L"]), atol=1e-6)
    np.testing.assert_array_equal(smile[:starts[2]], project.mesh.rest[:starts[2]])
    look = project.pose("eyeLookUpLeft").positions
    assert not np.allclose(look[:starts[1]], project.mesh.rest[:starts[1]])
    np.testing.assert_array_equal(look[starts[1]:], project.mesh.rest[starts[1]:])


def test_each_material_gets_its_own_cell_with_its_image_or_colour(avatar: Path) -> None:
    """Skin (JPEG 200,150,130) on 1001's full cell; the eyes' JPEG (240) and the teeth's
    base colour (0.3, 0.2, 0.1 → 77, 51, 26) on half-size cells."""
    project = load_gltf(avatar)
    tiles = project.uv_tiles
    assert tiles is not None and tiles.layout.tiles == (1001, 1002, 1003)
    assert project.skin_tiles() == [1001]
    diffuse = project.textures.diffuse.astype(int)
    for tile, colour in ((1001, (200, 150, 130)), (1002, (240, 240, 240)), (1003, (77, 51, 26))):
        assert np.abs(tiles.layout.crop(diffuse, tile) - colour).max() <= 3, tile
    assert project.mesh.uvs.min() >= 0.0 and project.mesh.uvs.max() <= 1.0


def test_keep_and_not_face_take_glTF_names(avatar: Path) -> None:
    report: list[str] = []
    project = load_gltf(avatar, keep=["Head", "Teeth"], not_face=["TeethMaterial"],
                        report=report)
    head = build_head("m", up="y")
    assert project.mesh.n_welded == len(head.parts[0].rest) + len(head.parts[3].rest)
    assert project.not_face is not None and project.not_face.sum() == len(head.parts[3].rest)
    assert report[1:3] == ["not face: Teeth (named)",
                           "left out (not kept): EyeLeft, EyeRight, Hair, Glasses, Body, "
                           "OutfitTop, OutfitBottom, Shoes"]
    assert load_gltf(avatar, keep=["Head"], not_face=[]).not_face is None
    message = ("--keep Face: no mesh, node or material has that name (the file has "
               f"{', '.join(sorted({*MESHES, 'Skin', 'EyeMaterial', 'TeethMaterial', 'Cloth'}))})")
    refused(avatar, message, keep=["Face"])


def test_project_from_files_and_the_cli_take_a_glTF_s_names(avatar: Path, tmp_path: Path,
                                                              capsys: pytest.CaptureFixture
                                                              ) -> None:
    from studio.cli import main

    project = project_from_files(avatar, keep=["Head"])
    assert project.not_face is None and len(project.poses) == 67
    out = tmp_path / "head.wrinkle"
    assert main(["new", "--gltf", str(avatar), "--keep", "Head", "EyeLeft", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "glTF scene: 10 meshes; the face: EyeLeft, Head (" in text
    assert "not face: EyeLeft (name)" in text


# --- nodes, accessors, primitives --------------------------------------------------------------
def placed(tmp_path: Path, node: dict, parent: dict | None = None) -> np.ndarray:
    d, _ = face(["smile", "frown"])
    nodes = [{**node, "mesh": 0}]
    if parent is not None:
        nodes.append({**parent, "children": [0]})
        d.doc["scenes"] = [{"nodes": [1]}]
    d.doc["nodes"] = nodes
    return load_gltf(d.write(tmp_path / "placed.gltf")).mesh.rest


def test_a_node_s_matrix_and_trs_and_its_parent_s_apply(tmp_path: Path) -> None:
    square = POSITIONS[:4].astype(np.float64)
    # TRS: a quarter turn about +Y (x → −z, z → x), scale 2, then up 1.6
    half = np.sqrt(0.5)
    trs = {"rotation": [0.0, half, 0.0, half], "scale": [2.0, 2.0, 2.0],
           "translation": [0.0, 1.6, 0.0]}
    expected = np.column_stack([2 * square[:, 2], 2 * square[:, 1] + 1.6, -2 * square[:, 0]])
    np.testing.assert_allclose(placed(tmp_path, trs), expected, atol=1e-6)
    # a column-major matrix on the parent: shift x by 3 (stored in elements 12–14)
    matrix = np.eye(4)
    matrix[0, 3] = 3.0
    moved = placed(tmp_path, trs, {"matrix": matrix.T.ravel().tolist()})
    np.testing.assert_allclose(moved, expected + np.array([3.0, 0.0, 0.0]), atol=1e-6)


def test_morph_offsets_turn_with_the_node_but_do_not_shift(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    half = np.sqrt(0.5)
    d.doc["nodes"] = [{"mesh": 0, "rotation": [0.0, half, 0.0, half], "translation": [9, 9, 9]}]
    project = load_gltf(d.write(tmp_path / "turned.gltf"))
    offset = project.pose("smile").positions - project.mesh.rest
    np.testing.assert_allclose(offset[3], [0.5, 0.0, 0.0], atol=1e-6)  # +z turned to +x


def test_a_sparse_accessor_overrides_its_base_at_its_indices(tmp_path: Path) -> None:
    d, prim = face(["smile", "frown"])
    base = prim["targets"][0]["POSITION"]
    d.doc["accessors"][base]["sparse"] = {
        "count": 2,
        "indices": {"bufferView": d.view(np.array([0, 2], np.uint16).tobytes()),
                    "componentType": 5123},
        "values": {"bufferView": d.view(np.float32([[1, 0, 0], [0, 2, 0]]).tobytes())}}
    project = load_gltf(d.write(tmp_path / "sparse.gltf"))
    offset = project.pose("smile").positions - project.mesh.rest
    np.testing.assert_allclose(offset, [[1, 0, 0], [0, 0, 0], [0, 2, 0], [0, 0, 0.5]])
    d.doc["accessors"][base]["sparse"]["indices"]["bufferView"] = d.view(
        np.array([2, 0], np.uint16).tobytes())
    refused(d.write(tmp_path / "unordered.gltf"),
            f"accessor {base}'s sparse block's indices are not increasing element numbers "
            "below 5")


@pytest.mark.parametrize(("mode", "order", "expected"), [
    (5, [0, 1, 2, 3], [[0, 1, 2], [2, 1, 3]]),  # a strip: every other triangle turned
    (6, [0, 1, 2, 3], [[0, 1, 2], [0, 2, 3]]),  # a fan round the first vertex
])
def test_strips_and_fans_are_triangles(tmp_path: Path, mode: int, order: list[int],
                                       expected: list[list[int]]) -> None:
    d = Doc()
    d.doc["meshes"] = [{"primitives": [{
        "attributes": {"POSITION": d.data(POSITIONS[:4]), "TEXCOORD_0": d.data(UVS[:4])},
        "indices": d.data(np.array(order, np.uint16)), "mode": mode}]}]
    mesh = load_gltf(d.write(tmp_path / "strip.gltf")).mesh
    np.testing.assert_array_equal(mesh.welded_triangles, expected)


def test_a_texture_transform_moves_the_uvs(tmp_path: Path) -> None:
    """Scale (0.5, 0.5) then offset (0.5, 0): (u, v) → (u/2 + 0.5, v/2), then v flipped."""
    d, prim = face()
    texture = d.texture(np.zeros((2, 2, 3), np.uint8))
    texture["extensions"] = {"KHR_texture_transform": {"offset": [0.5, 0.0],
                                                       "scale": [0.5, 0.5]}}
    d.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": texture}}]
    prim["material"] = 0
    d.doc["extensionsRequired"] = ["KHR_texture_transform"]
    mesh = load_gltf(d.write(tmp_path / "moved.gltf")).mesh
    expected = np.column_stack([UVS[:, 0] / 2 + 0.5, 1.0 - UVS[:, 1] / 2])
    np.testing.assert_allclose(mesh.uvs, expected, atol=1e-6)


def test_meshes_merge_with_one_pose_per_target_name(tmp_path: Path) -> None:
    """Two squares: the first has smile and frown, the second only frown (and is moved 5 in
    x): smile is zero on the second; frown moves both."""
    d, prim = face(["smile", "frown"])
    second = {"attributes": dict(prim["attributes"]), "indices": prim["indices"],
              "targets": [prim["targets"][1]]}
    d.doc["meshes"].append({"name": "brow", "primitives": [second],
                            "extras": {"targetNames": ["frown"]}})
    d.doc["nodes"] = [{"mesh": 0}, {"mesh": 1, "translation": [5, 0, 0]}]
    project = load_gltf(d.write(tmp_path / "two.gltf"))
    assert project.mesh.n_welded == 8 and project.pose_names == ["neutral", "smile", "frown"]
    smile = project.pose("smile").positions - project.mesh.rest
    frown = project.pose("frown").positions - project.mesh.rest
    np.testing.assert_allclose(smile[:4], SMILE[:4])
    assert not smile[4:].any()
    np.testing.assert_allclose(frown[:4], frown[4:])
    assert frown[1, 1] == -0.25


def test_vertices_at_one_place_that_poses_part_stay_two(tmp_path: Path) -> None:
    """Closed lips: render vertices 1 and 4 share a position but the pose moves only 1."""
    d, prim = face(["open"], targets=(SMILE,))
    parted = np.zeros((5, 3), np.float32)
    parted[1] = [0.0, 0.1, 0.0]
    prim["targets"][0]["POSITION"] = d.data(parted)
    project = load_gltf(d.write(tmp_path / "lips.gltf"))
    assert project.mesh.n_welded == 5


# --- refusals ------------------------------------------------------------------------------
@pytest.mark.parametrize(("extension", "command"), [
    ("EXT_meshopt_compression", "gltfpack -noq -i FILE -o OUT.glb"),
    ("KHR_draco_mesh_compression", "npx @gltf-transform/cli copy FILE OUT.glb"),
])
def test_a_compressed_file_is_refused_naming_the_extension_and_the_way_out(
        tmp_path: Path, extension: str, command: str) -> None:
    d, _ = face()
    d.doc["extensionsRequired"] = ["KHR_mesh_quantization", extension]
    d.doc["buffers"] = [{"byteLength": 7211288}]  # what compression leaves: no data to read
    path = tmp_path / "packed.gltf"
    path.write_text(__import__("json").dumps(d.doc))
    refused(path, f"the file is compressed with {extension}, which this reader does not "
                  f"decode; decompress it first: {command}")


def test_an_unknown_required_extension_is_refused_by_name(tmp_path: Path) -> None:
    d, _ = face()
    d.doc["extensionsRequired"] = ["KHR_mesh_quantization", "EXT_made_up", "KHR_texture_basisu"]
    refused(d.write(tmp_path / "odd.gltf"), "the file requires the glTF extensions "
            "EXT_made_up, KHR_texture_basisu, which this reader does not know")


# --- not-face suggestions -------------------------------------------------------------------
def test_the_ict_head_s_ten_non_skin_materials_are_suggested() -> None:
    names = ["M_Face", "M_BackHead", *ICT_NOT_SKIN]
    assert suggest_not_face(names) == ICT_NOT_SKIN
    assert suggest_not_face(["EyeLid_L", "eyebrow", "Wolf3D_Head", "mouth_bag", "EyeLeft",
                             "Wolf3D_Teeth", "TearLine"]) == ["mouth_bag", "EyeLeft",
                                                             "Wolf3D_Teeth", "TearLine"]


def test_a_small_closed_shell_and_a_rigidly_moved_part_are_suggested() -> None:
    head = build_head("m", vertices=600)
    skin, eye, _, teeth = head.parts
    weld = skin.weld
    skin_part = Part(["skin"], skin.rest, weld[skin.triangles],
                     [skin.poses[p] for p in skin.poses])
    positions, inverse = np.unique(eye.rest, axis=0, return_inverse=True)
    shell = inverse.ravel()[eye.triangles]
    assert is_closed(shell) and not is_closed(teeth.triangles)
    ball = Part(["part 2"], positions, shell)
    turned = Part(["part 3"], teeth.rest, teeth.triangles,
                  [teeth.rest @ np.array([[1, 0, 0], [0, 0.8, -0.6], [0, 0.6, 0.8]]).T + 1.0])
    assert moves_rigidly(turned.rest, turned.poses)
    assert not moves_rigidly(skin.rest, [skin.poses["browInnerUp"]])
    assert not moves_rigidly(skin.rest, [skin.rest])  # never moved: no sign either way
    assert suggest_parts([skin_part, ball, turned]) == {1: "small closed shell",
                                                        2: "moved rigidly"}


def test_when_everything_looks_not_face_the_largest_stays_face(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    d.doc["meshes"][0]["name"] = "EyeLeft"
    project = load_gltf(d.write(tmp_path / "eye.gltf"))
    assert project.not_face is None


def test_the_cli_help_names_glTF_parts() -> None:
    from studio.cli import build_parser

    text = build_parser()._subparsers._group_actions[0].choices["new"].format_help()
    assert re.search(r"glTF\s+meshes,\s+nodes\s+or\s+materials", text)
