"""Reading glTF files into projects, on small files built by hand: the triangle primitive and
its indices, seam vertices welded (by position, or exactly as the studio's ``_WELD`` says),
morph targets as named key poses, the material's textures, the studio's own extras (masks,
wrinkled maps, WDV areas, not-face flags, UDIM tiles, settings) and their defaults, weights
animations as timelines (LINEAR, STEP, CUBICSPLINE; times to frames; the range) and
``load_weight_animation``; and that each damaged file gets one error naming the file and the
exact problem. Every value is worked out by hand from the file written, so a reader that
misreads a default, a key or an index fails here, quickly and without GL."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.timeline import Timeline
from studio.core.files.errors import MeshError
from studio.core.files.png import encode_png
from studio.core.formats.gltf.animation import sample_frames, timeline_from_animation
from studio.core.formats.gltf.codec import load_gltf, load_weight_animation

pytestmark = pytest.mark.core

TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}
COMPONENT = {
    np.dtype(np.float32): 5126,
    np.dtype(np.uint8): 5121,
    np.dtype(np.uint16): 5123,
    np.dtype(np.uint32): 5125,
}

# a square of two triangles; render vertex 4 is a seam copy of vertex 1 (same place, other UV)
POSITIONS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]], np.float32)
UVS = np.array([[0.0, 0.0], [0.5, 0.25], [0.0, 0.75], [1.0, 1.0], [0.5, 0.5]], np.float32)
INDICES = np.array([0, 1, 2, 4, 3, 2], np.uint16)
SMILE = np.zeros((5, 3), np.float32)
SMILE[3] = [0.0, 0.0, 0.5]
FROWN = np.zeros((5, 3), np.float32)
FROWN[[1, 4]] = [0.0, -0.25, 0.0]


class Doc:
    """A glTF document under construction, its binary data in one data-URI buffer."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.doc: dict = {"asset": {"version": "2.0"}, "accessors": [], "bufferViews": []}

    def view(self, data: bytes) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        self.doc["bufferViews"].append(
            {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        )
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def data(self, array: np.ndarray, kind: str | None = None) -> int:
        """An accessor holding ``array`` (rows of 1-4 components)."""
        array = np.ascontiguousarray(array)
        width = 1 if array.ndim == 1 else array.shape[1]
        self.doc["accessors"].append(
            {
                "bufferView": self.view(array.tobytes()),
                "componentType": COMPONENT[array.dtype],
                "count": len(array),
                "type": kind or TYPES[width],
            }
        )
        return len(self.doc["accessors"]) - 1

    def image(self, array: np.ndarray) -> int:
        images = self.doc.setdefault("images", [])
        images.append({"bufferView": self.view(encode_png(array)), "mimeType": "image/png"})
        return len(images) - 1

    def texture(self, array: np.ndarray) -> dict:
        textures = self.doc.setdefault("textures", [])
        textures.append({"source": self.image(array)})
        return {"index": len(textures) - 1}

    def write(self, path: Path) -> Path:
        uri = "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": uri}]
        path.write_text(json.dumps(self.doc))
        return path


def face(
    names: list[str] | None = None,
    targets: tuple[np.ndarray, ...] = (SMILE, FROWN),
    node: bool = True,
) -> tuple[Doc, dict]:
    """The square with morph targets named ``names`` on the mesh; returns it and the
    primitive (to change before writing)."""
    d = Doc()
    prim = {
        "attributes": {"POSITION": d.data(POSITIONS), "TEXCOORD_0": d.data(UVS)},
        "indices": d.data(INDICES),
    }
    if targets:
        prim["targets"] = [{"POSITION": d.data(t)} for t in targets]
    mesh: dict = {"name": "head", "primitives": [prim]}
    if names is not None:
        mesh["extras"] = {"targetNames": names}
    d.doc["meshes"] = [mesh]
    if node:
        d.doc["nodes"] = [{"mesh": 0}]
    return d, prim


def animate(
    d: Doc,
    times: list[float],
    weights: list[float],
    interpolation: str | None = None,
    node: int = 0,
    extras: dict | None = None,
) -> dict:
    """A weights animation on ``node``; returns the animation (to change before writing)."""
    sampler: dict = {
        "input": d.data(np.array(times, np.float32)),
        "output": d.data(np.array(weights, np.float32)),
    }
    if interpolation is not None:
        sampler["interpolation"] = interpolation
    animation: dict = {
        "samplers": [sampler],
        "channels": [{"sampler": 0, "target": {"node": node, "path": "weights"}}],
    }
    if extras is not None:
        animation["extras"] = extras
    d.doc.setdefault("animations", []).append(animation)
    return animation


def refused(path: Path, problem: str, loader=load_gltf) -> None:
    """Loading ``path`` fails with exactly ``problem``, naming the file."""
    with pytest.raises(MeshError) as info:
        loader(path)
    assert str(info.value) == f"{path}: {problem}"


# --- the mesh ------------------------------------------------------------------------------
def test_the_square_loads_welded_with_flipped_v_named_poses_and_defaults(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    path = d.write(tmp_path / "face.gltf")
    project = load_gltf(path)
    mesh = project.mesh
    assert project.name == "face"  # no studio extras: the file's stem
    assert mesh.source == str(path)
    np.testing.assert_array_equal(mesh.weld, [0, 1, 2, 3, 1])
    np.testing.assert_array_equal(mesh.rest, POSITIONS[:4])
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [4, 3, 2]])
    np.testing.assert_array_equal(mesh.uvs, [[0, 1], [0.5, 0.75], [0, 0.25], [1, 0], [0.5, 0.5]])
    assert [p.name for p in project.poses] == ["smile", "frown"]
    np.testing.assert_array_equal(project.poses[0].positions, (POSITIONS + SMILE)[:4])
    np.testing.assert_array_equal(project.poses[1].positions, (POSITIONS + FROWN)[:4])
    # nothing of the studio's: its defaults, no timeline from a file without an animation
    assert project.influence.areas == [] and project.influence.links == {}
    assert project.influence.curves == {}
    assert project.wdv.areas == [] and project.wdv.expression_factor == 1.0
    assert project.wdv.scale_free is True
    assert project.not_face is None and project.uv_tiles is None
    assert project.timeline.to_dict() == Timeline().to_dict()
    assert project.view == {}
    assert project.textures.normal_wrinkled.shape == (4, 4, 3)


def test_triangles_without_indices_are_each_three_vertices(tmp_path: Path) -> None:
    d = Doc()
    corners = POSITIONS[[0, 1, 2, 1, 3, 2]]
    uvs = np.arange(12, dtype=np.float32).reshape(6, 2) / 16
    d.doc["meshes"] = [
        {"primitives": [{"attributes": {"POSITION": d.data(corners), "TEXCOORD_0": d.data(uvs)}}]}
    ]
    mesh = load_gltf(d.write(tmp_path / "soup.gltf")).mesh
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [3, 4, 5]])
    np.testing.assert_array_equal(mesh.weld, [0, 1, 2, 1, 3, 2])
    np.testing.assert_array_equal(mesh.rest, POSITIONS[:4])


def test_vertices_without_indices_must_come_in_threes(tmp_path: Path) -> None:
    d = Doc()
    d.doc["meshes"] = [
        {
            "primitives": [
                {"attributes": {"POSITION": d.data(POSITIONS[:4]), "TEXCOORD_0": d.data(UVS[:4])}}
            ]
        }
    ]
    refused(d.write(tmp_path / "four.gltf"), "4 vertices without indices are not triangles")


def test_the_first_triangle_primitive_with_uvs_is_the_face(tmp_path: Path) -> None:
    d, prim = face()
    points = {
        "attributes": {"POSITION": d.data(POSITIONS[:3] + 5), "TEXCOORD_0": d.data(UVS[:3])},
        "mode": 0,
    }
    no_uvs = {"attributes": {"POSITION": d.data(POSITIONS[:3] + 7)}}
    d.doc["meshes"] = [{"primitives": [points]}, {"primitives": [no_uvs, prim]}]
    d.doc["nodes"] = [{"mesh": 1}]
    mesh = load_gltf(d.write(tmp_path / "face.gltf")).mesh
    np.testing.assert_array_equal(mesh.rest, POSITIONS[:4])


@pytest.mark.parametrize(
    "meshes",
    [None, [{}], [{"primitives": [{}]}], [{"primitives": [{"attributes": {"TEXCOORD_0": 0}}]}]],
)
def test_a_file_without_a_triangle_mesh_says_so(tmp_path: Path, meshes: list | None) -> None:
    d = Doc()
    if meshes is not None:
        d.doc["meshes"] = meshes
    refused(d.write(tmp_path / "empty.gltf"), "the file holds no triangle mesh")


def test_a_mesh_without_uvs_says_so(tmp_path: Path) -> None:
    """No TEXCOORD_0: UVs made by xatlas (issue #37), said in the report."""
    d, prim = face()
    del prim["attributes"]["TEXCOORD_0"]
    path = d.write(tmp_path / "bare.gltf")
    report: list[str] = []
    project = load_gltf(path, report=report)
    assert any(line.startswith(f"no UVs in {path}: made them with xatlas") for line in report)
    assert (project.mesh.uvs >= 0).all() and (project.mesh.uvs <= 1).all()


@pytest.mark.parametrize(
    ("attribute", "problem"),
    [
        ("POSITION", "POSITION (accessor 0) is 'VEC2' of component type 5126, expected VEC3"),
        ("TEXCOORD_0", "TEXCOORD_0 (accessor 0) is 'VEC2' of component type 5126, expected VEC2"),
    ],
)
def test_attributes_of_the_wrong_type_are_named(
    tmp_path: Path, attribute: str, problem: str
) -> None:
    d, prim = face()
    wrong = {"POSITION": d.data(UVS), "TEXCOORD_0": d.data(POSITIONS)}[attribute]
    prim["attributes"][attribute] = wrong
    problem = problem.replace("accessor 0", f"accessor {wrong}")
    if attribute == "TEXCOORD_0":
        problem = problem.replace("'VEC2'", "'VEC3'")
    refused(d.write(tmp_path / "typed.gltf"), problem)


def test_uvs_must_match_the_positions(tmp_path: Path) -> None:
    d, prim = face()
    prim["attributes"]["TEXCOORD_0"] = d.data(UVS[:3])
    refused(d.write(tmp_path / "uvs.gltf"), "TEXCOORD_0 has 3 values, POSITION has 5")


def test_float_indices_are_refused(tmp_path: Path) -> None:
    d, prim = face()
    prim["indices"] = d.data(INDICES.astype(np.float32))
    refused(
        d.write(tmp_path / "idx.gltf"),
        f"the indices (accessor {prim['indices']}) is "
        "'SCALAR' of component type 5126, expected SCALAR of unsigned integers",
    )


@pytest.mark.parametrize("indices", [[0, 1, 2, 4, 3], [0, 1, 2, 5, 3, 2]])
def test_indices_must_be_triangles_over_existing_vertices(
    tmp_path: Path, indices: list[int]
) -> None:
    d, prim = face()
    prim["indices"] = d.data(np.array(indices, np.uint16))
    refused(
        d.write(tmp_path / "idx.gltf"),
        "the indices are not triangles over the 5 vertices "
        "(a count not divisible by 3, or a vertex that does not exist)",
    )


def test_indices_as_uint8_and_uint32_read_alike(tmp_path: Path) -> None:
    for dtype in (np.uint8, np.uint32):
        d, prim = face()
        prim["indices"] = d.data(INDICES.astype(dtype))
        mesh = load_gltf(d.write(tmp_path / "idx.gltf")).mesh
        np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [4, 3, 2]])


# --- _WELD: the studio's own welding -------------------------------------------------------
def welded(weld: list[float], positions: np.ndarray = POSITIONS) -> Doc:
    d, prim = face()
    prim["attributes"]["POSITION"] = d.data(positions)
    prim["attributes"]["_WELD"] = d.data(np.array(weld, np.float32))
    return d


def test_weld_keeps_the_studio_s_numbering(tmp_path: Path) -> None:
    # vertex 4 lies on vertex 1, but _WELD says it is a vertex of its own: the file decides
    path = welded([0, 1, 2, 3, 4]).write(tmp_path / "weld.gltf")
    project = load_gltf(path)
    np.testing.assert_array_equal(project.mesh.weld, [0, 1, 2, 3, 4])
    np.testing.assert_array_equal(project.mesh.rest, POSITIONS)
    assert project.mesh.source == str(path)
    # and a numbering other than the positions' order: welded vertex 0 is render vertex 3
    order = welded([1, 2, 3, 0, 2]).write(tmp_path / "order.gltf")
    mesh = load_gltf(order).mesh
    np.testing.assert_array_equal(mesh.rest, POSITIONS[[3, 0, 1, 2]])
    np.testing.assert_array_equal(mesh.weld, [1, 2, 3, 0, 2])


@pytest.mark.parametrize("weld", [[0, 1, 2, 3, 0.5], [0, 1, 2, 3, -1], [0, 1, 2, 3, 5]])
def test_weld_must_hold_vertex_numbers(tmp_path: Path, weld: list[float]) -> None:
    refused(
        welded(weld).write(tmp_path / "weld.gltf"),
        "the _WELD attribute does not hold vertex numbers",
    )


def test_welded_vertices_must_share_a_position(tmp_path: Path) -> None:
    refused(
        welded([0, 1, 2, 3, 2]).write(tmp_path / "weld.gltf"),
        "vertices welded by _WELD are not at one position",
    )


# --- morph targets --------------------------------------------------------------------------
def test_target_names_from_the_primitive_when_the_mesh_has_none(tmp_path: Path) -> None:
    d, prim = face(None)
    prim["extras"] = {"targetNames": ["up", "down"]}
    project = load_gltf(d.write(tmp_path / "face.gltf"))
    assert [p.name for p in project.poses] == ["up", "down"]


def test_unnamed_targets_are_numbered(tmp_path: Path) -> None:
    d, _ = face(None)
    assert [p.name for p in load_gltf(d.write(tmp_path / "a.gltf")).poses] == [
        "target_0",
        "target_1",
    ]
    d, _ = face(["smile"])
    assert [p.name for p in load_gltf(d.write(tmp_path / "b.gltf")).poses] == ["smile", "target_1"]


def test_a_target_without_positions_is_skipped(tmp_path: Path) -> None:
    d, prim = face(["normals only", "smile", "frown"])
    prim["targets"].insert(0, {"NORMAL": d.data(SMILE)})
    project = load_gltf(d.write(tmp_path / "face.gltf"))
    assert [p.name for p in project.poses] == ["smile", "frown"]
    np.testing.assert_array_equal(project.poses[1].positions, (POSITIONS + FROWN)[:4])


def test_no_targets_no_poses(tmp_path: Path) -> None:
    d, _ = face(targets=())
    assert load_gltf(d.write(tmp_path / "face.gltf")).poses == []


def test_a_target_of_the_wrong_size_or_type_is_named(tmp_path: Path) -> None:
    d, prim = face(["smile", "frown"])
    prim["targets"][0]["POSITION"] = d.data(SMILE[:3])
    refused(
        d.write(tmp_path / "size.gltf"), "morph target 'smile' moves 3 vertices, the mesh has 5"
    )
    d, prim = face(["smile", "frown"])
    prim["targets"][1]["POSITION"] = bad = d.data(UVS)
    refused(
        d.write(tmp_path / "type.gltf"),
        f"morph target 'frown' (accessor {bad}) is 'VEC2' of component type 5126, expected VEC3",
    )


def test_too_many_targets_name_the_setting(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_POSES", "1")
    d, _ = face(["smile", "frown"])
    refused(
        d.write(tmp_path / "many.gltf"),
        "the morph target count is 2 key poses, more than "
        "the limit of 1 key poses (set WRINKLE_STUDIO_MAX_POSES to change it)",
    )


# --- material -------------------------------------------------------------------------------
def test_the_material_s_three_textures(tmp_path: Path) -> None:
    d, prim = face()
    diffuse = np.arange(12, dtype=np.uint8).reshape(2, 2, 3) * 20
    neutral = np.full((2, 2, 3), (120, 130, 250), np.uint8)
    wrinkled = np.array([[10, 20], [30, 40]], np.uint8)  # grey: repeated into RGB
    d.doc["materials"] = [
        {},
        {
            "pbrMetallicRoughness": {"baseColorTexture": d.texture(diffuse)},
            "normalTexture": d.texture(neutral),
            "extras": {"wrinkleNormalTexture": d.texture(wrinkled)},
        },
    ]
    prim["material"] = 1
    textures = load_gltf(d.write(tmp_path / "face.gltf")).textures
    np.testing.assert_array_equal(textures.diffuse, diffuse)
    np.testing.assert_array_equal(textures.normal_neutral, neutral)
    np.testing.assert_array_equal(textures.normal_wrinkled, np.repeat(wrinkled[:, :, None], 3, 2))


def test_a_missing_material_is_named(tmp_path: Path) -> None:
    d, prim = face()
    prim["material"] = 2
    d.doc["materials"] = [{}]
    refused(d.write(tmp_path / "mat.gltf"), "the mesh refers to a material that does not exist")


# --- the studio's extras ---------------------------------------------------------------------
def test_the_studio_s_extras_come_back_with_their_values(tmp_path: Path) -> None:
    d, prim = face(["smile", "frown"])
    attrs = prim["attributes"]
    masks = [np.array([[0, 65535], [32768, 1]], np.uint16), np.array([[7, 0], [0, 9]], np.uint16)]
    maps = [np.full((2, 2, 3), 40, np.uint8), np.full((2, 2, 3), 90, np.uint8)]
    dirs = np.arange(15, dtype=np.float32).reshape(5, 3) / 15
    lengths = np.array([0.5, 1.0, 1.5, 2.0, 1.0], np.float32)
    cones = np.array([0.0, 5.0, 10.0, 15.0, 5.0], np.float32)
    attrs["_WRINKLE_DIR_0"] = d.data(dirs)
    attrs["_WRINKLE_LEN_0"] = d.data(lengths)
    attrs["_WRINKLE_CONE_0"] = d.data(cones)
    attrs["_WRINKLE_DIR_1"] = d.data(dirs[::-1].copy())
    attrs["_WRINKLE_LEN_1"] = d.data(lengths[::-1].copy())
    attrs["_NOT_FACE"] = d.data(np.array([0.0, 0.5, 0.75, 1.0, 0.5], np.float32))
    attrs["_UDIM_TILE"] = d.data(np.array([0, 1, 1, 0, 1], np.float32))
    layout = {"tiles": [1001, 1002], "cells": [[0.0, 0.0, 0.5], [0.5, 0.0, 0.5]]}
    timeline = {
        "fps": 30.0,
        "start": 2,
        "end": 40,
        "tracks": [{"pose": "smile", "keys": [[4.0, 1.0, "smooth"]]}],
    }
    d.doc["extras"] = {
        "wrinkleStudio": {
            "name": "Ada",
            "influence": {
                "links": {"smile": {"brow": 0.5}},
                "areas": [
                    {
                        "name": "brow",
                        "image": d.image(masks[0]),
                        "colour": [1, 2, 3],
                        "activation": 0.25,
                        "visible": False,
                        "wrinkle_map": "second",
                    },
                    {"name": "chin", "image": d.image(masks[1])},
                ],
            },
            "wrinkle_maps": [
                {"name": "first", "image": d.image(maps[0])},
                {"name": "second", "image": d.image(maps[1])},
            ],
            "uv_tiles": layout,
            "timeline": timeline,
            "tangent_frame": "thesis",
            "wdv": {
                "expression_factor": 2.5,
                "scale_free": False,
                "areas": [
                    {
                        "name": "w0",
                        "pose": "smile",
                        "colour": [9, 8, 7],
                        "cone_angle_deg": 35.0,
                        "enabled": False,
                        "wrinkle_map": "second",
                    },
                    {"name": "w1", "pose": "frown"},
                ],
            },
        }
    }
    # an animation too, which the studio's own timeline overrides
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0])
    project = load_gltf(d.write(tmp_path / "face.gltf"))
    assert project.name == "Ada"
    brow, chin = project.influence.areas
    np.testing.assert_array_equal(brow.mask, masks[0] / np.float32(65535))
    assert brow.mask.dtype == np.float32
    assert (brow.name, brow.colour, brow.activation, brow.visible, brow.wrinkle_map) == (
        "brow",
        (1, 2, 3),
        0.25,
        False,
        "second",
    )
    np.testing.assert_array_equal(chin.mask, masks[1] / np.float32(65535))
    assert (chin.name, chin.colour, chin.activation, chin.visible, chin.wrinkle_map) == (
        "chin",
        (255, 128, 0),
        0.0,
        True,
        "",
    )
    assert project.influence.links == {"smile": {"brow": 0.5}}
    assert list(project.textures.wrinkle_maps) == ["first", "second"]
    np.testing.assert_array_equal(project.textures.wrinkle_maps["second"], maps[1])
    np.testing.assert_array_equal(project.textures.normal_wrinkled, maps[0])
    np.testing.assert_array_equal(project.not_face, [False, False, True, True])
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.to_dict() == layout
    np.testing.assert_array_equal(project.uv_tiles.vertex_tile, [0, 1, 1, 0, 1])
    assert project.uv_tiles.vertex_tile.dtype == np.int16
    w0, w1 = project.wdv.areas
    assert (project.wdv.expression_factor, project.wdv.scale_free) == (2.5, False)
    assert (w0.name, w0.pose, w0.colour, w0.cone_angle_deg, w0.enabled, w0.wrinkle_map) == (
        "w0",
        "smile",
        (9, 8, 7),
        35.0,
        False,
        "second",
    )
    assert (w1.name, w1.pose, w1.colour, w1.cone_angle_deg, w1.enabled, w1.wrinkle_map) == (
        "w1",
        "frown",
        (0, 170, 255),
        20.0,
        True,
        "",
    )
    np.testing.assert_array_equal(w0.directions, dirs[:4])
    np.testing.assert_array_equal(w0.lengths, lengths[:4])
    np.testing.assert_array_equal(w0.cone_angles_deg, cones[:4])
    np.testing.assert_array_equal(w1.directions, dirs[::-1][:4])
    np.testing.assert_array_equal(w1.lengths, lengths[::-1][:4])
    assert w1.cone_angles_deg is None
    assert project.timeline.to_dict() == timeline
    assert project.view == {"view": {"tangent_frame": "thesis"}}


def test_wdv_settings_default_when_absent(tmp_path: Path) -> None:
    d, prim = face(["smile", "frown"])
    prim["attributes"]["_WRINKLE_DIR_0"] = d.data(np.ones((5, 3), np.float32))
    prim["attributes"]["_WRINKLE_LEN_0"] = d.data(np.ones(5, np.float32))
    d.doc["extras"] = {
        "wrinkleStudio": {
            "wdv": {"areas": [{"name": "w", "pose": "smile"}]},
            "tangent_frame": "no such frame",
        }
    }
    project = load_gltf(d.write(tmp_path / "face.gltf"))
    assert project.wdv.expression_factor == 1.0 and project.wdv.scale_free is True
    assert project.wdv.areas[0].enabled is True
    assert project.view == {}  # an unknown frame is not taken


@pytest.mark.parametrize("udim", ["extras", "attribute"])
def test_udim_tiles_need_both_the_layout_and_the_attribute(tmp_path: Path, udim: str) -> None:
    d, prim = face()
    if udim == "extras":
        d.doc["extras"] = {"wrinkleStudio": {"uv_tiles": {"tiles": [1001], "cells": [[0, 0, 1]]}}}
    else:
        prim["attributes"]["_UDIM_TILE"] = d.data(np.zeros(5, np.float32))
    assert load_gltf(d.write(tmp_path / "face.gltf")).uv_tiles is None


def test_malformed_studio_extras_are_one_error(tmp_path: Path) -> None:
    d, _ = face()
    d.doc["extras"] = {"wrinkleStudio": {"influence": {"areas": [{"image": 0}]}}}
    d.image(np.zeros((2, 2), np.uint16))
    refused(
        d.write(tmp_path / "extras.gltf"),
        "the studio data in extras.wrinkleStudio is malformed ('name')",
    )


def test_a_structure_no_check_foresaw_is_one_error(tmp_path: Path) -> None:
    d, _ = face()
    d.doc["extras"] = ["not", "an", "object"]
    refused(
        d.write(tmp_path / "odd.gltf"),
        "the glTF file is malformed (AttributeError: 'list' object has no attribute 'get')",
    )


# --- the weights animation as the timeline ---------------------------------------------------
def timeline_of(tmp_path: Path, d: Doc) -> Timeline:
    return load_gltf(d.write(tmp_path / "anim.gltf")).timeline


def test_a_linear_animation_becomes_linear_keys_at_24_fps(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 0.5, 1.0], [0.0, 1.0, 0.25, 0.5, 1.0, 0.0])  # no interpolation: LINEAR
    timeline = timeline_of(tmp_path, d)
    assert (timeline.fps, timeline.start, timeline.end) == (24.0, 0, 24)
    assert timeline.to_dict()["tracks"] == [
        {
            "pose": "smile",
            "keys": [[0.0, 0.0, "linear"], [12.0, 0.25, "linear"], [24.0, 1.0, "linear"]],
        },
        {
            "pose": "frown",
            "keys": [[0.0, 1.0, "linear"], [12.0, 0.5, "linear"], [24.0, 0.0, "linear"]],
        },
    ]


def test_the_animation_s_own_range_and_rate(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(
        d,
        [0.0, 0.5],
        [0.0, 1.0, 1.0, 0.0],
        "LINEAR",
        extras={"wrinkleStudio": {"fps": 30.0, "start": 10, "end": 50}},
    )
    timeline = timeline_of(tmp_path, d)
    assert (timeline.fps, timeline.start, timeline.end) == (30.0, 10, 50)
    assert [k.frame for k in timeline.tracks[0].keys] == [10.0, 25.0]


def test_frames_snap_to_a_thousandth_and_a_fraction_stays(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    # frame 2.0004 (float32 seconds' rounding) snaps to 2; frame 1.5 stays a half frame
    animate(d, [1.5 / 24, 2.0004 / 24], [0.0, 1.0, 1.0, 0.0], "LINEAR")
    assert [k.frame for k in timeline_of(tmp_path, d).tracks[0].keys] == [1.5, 2.0]


def test_a_single_key_gives_a_one_frame_range(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0], [0.5, 0.25], "LINEAR")
    timeline = timeline_of(tmp_path, d)
    assert (timeline.start, timeline.end) == (0, 1)
    assert timeline.to_dict()["tracks"][1] == {"pose": "frown", "keys": [[0.0, 0.25, "linear"]]}


def test_a_step_animation_becomes_constant_keys(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0], "STEP")
    assert timeline_of(tmp_path, d).to_dict()["tracks"][0] == {
        "pose": "smile",
        "keys": [[0.0, 0.0, "constant"], [24.0, 1.0, "constant"]],
    }


def test_a_cubic_spline_animation_keeps_its_values(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    # per key: in-tangents (2 targets), values, out-tangents
    animate(d, [0.0, 1.0], [9, 8, 0.25, 0.75, 7, 6, 5, 4, 1.0, 0.5, 3, 2], "CUBICSPLINE")
    assert timeline_of(tmp_path, d).to_dict()["tracks"] == [
        {"pose": "smile", "keys": [[0.0, 0.25, "linear"], [24.0, 1.0, "linear"]]},
        {"pose": "frown", "keys": [[0.0, 0.75, "linear"], [24.0, 0.5, "linear"]]},
    ]


def test_only_the_weights_channel_of_the_mesh_s_node_counts(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    d.doc["nodes"] = [{}, {"name": "other"}, {"mesh": 0}]  # the mesh's node is node 2
    other = animate(d, [0.0], [0.5, 0.5], "LINEAR", node=1)
    other["channels"].insert(0, {"sampler": 0})  # no target at all
    other["channels"].append({"sampler": 0, "target": {"node": 2, "path": "translation"}})
    d.doc["animations"].insert(0, {})  # no channels
    later = animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0], "LINEAR", node=2)
    other["samplers"].append(later["samplers"][0])
    later["samplers"][0] = dict(later["samplers"][0], output=d.data(np.full(4, 0.5, np.float32)))
    other["channels"].append({"sampler": 1, "target": {"node": 2, "path": "weights"}})
    timeline = timeline_of(tmp_path, d)  # the first weights channel on node 2: the fourth
    assert [k.value for k in timeline.tracks[0].keys] == [0.0, 1.0]


def test_no_animation_or_no_poses_keep_the_default_timeline(tmp_path: Path) -> None:
    d, _ = face(targets=())
    animate(d, [0.0, 1.0], [0.0, 1.0])
    assert timeline_of(tmp_path, d).to_dict() == Timeline().to_dict()
    d, _ = face(["smile", "frown"], node=False)
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0])
    del d.doc["animations"][0]["channels"][0]["target"]["node"]
    assert timeline_of(tmp_path, d).to_dict() == Timeline().to_dict()


def test_a_studio_extras_block_without_the_studio_s_key(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0], extras={"otherTool": {"fps": 5}})
    assert timeline_of(tmp_path, d).fps == 24.0


def test_a_slow_but_valid_frame_rate(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 2.0], [0.0, 1.0, 1.0, 0.0], extras={"wrinkleStudio": {"fps": 1.0}})
    timeline = timeline_of(tmp_path, d)
    assert (timeline.fps, timeline.end) == (1.0, 2)


@pytest.mark.parametrize("studio", [{"fps": 0.0, "end": 10}, {"start": 5, "end": 5}])
def test_an_invalid_rate_or_range_is_refused(tmp_path: Path, studio: dict) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0], extras={"wrinkleStudio": studio})
    refused(
        d.write(tmp_path / "anim.gltf"),
        "the morph-weight animation is malformed (the animation's frame rate or range is invalid)",
    )


def test_a_malformed_animation_is_one_error(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    animate(d, [0.0, 1.0], [0.0, 1.0, 1.0, 0.0])["channels"][0]["sampler"] = 3
    refused(
        d.write(tmp_path / "anim.gltf"),
        "the morph-weight animation is malformed (list index out of range)",
    )


def test_nodes_that_are_not_a_list_are_named(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    d.doc["nodes"] = {"0": {"mesh": 0}}
    refused(d.write(tmp_path / "nodes.gltf"), "'nodes' is not a JSON list")


def test_timeline_from_animation_reads_through_the_given_accessor() -> None:
    arrays = {0: np.array([[0.0], [0.25]]), 1: np.array([[0.5], [1.0]])}
    doc = {
        "animations": [
            {
                "samplers": [{"input": 0, "output": 1}],
                "channels": [{"sampler": 0, "target": {"node": 3, "path": "weights"}}],
            }
        ]
    }
    timeline = timeline_from_animation(doc, 3, ["smile"], arrays.__getitem__)
    assert timeline is not None
    assert timeline.to_dict() == {
        "fps": 24.0,
        "start": 0,
        "end": 6,
        "tracks": [{"pose": "smile", "keys": [[0.0, 0.5, "linear"], [6.0, 1.0, "linear"]]}],
    }
    assert timeline_from_animation(doc, 2, ["smile"], arrays.__getitem__) is None
    assert timeline_from_animation({}, 3, ["smile"], arrays.__getitem__) is None


def test_sample_frames_are_whole_frames_and_keys_in_range() -> None:
    timeline = Timeline.from_dict(
        {
            "fps": 24,
            "start": 3,
            "end": 6,
            "tracks": [
                {"pose": "a", "keys": [[1.0, 0.0, "linear"], [4.5, 1.0, "linear"]]},
                {"pose": "b", "keys": [[10.0, 0.0, "linear"], [6.0, 1.0, "linear"]]},
            ],
        }
    )
    frames = sample_frames(timeline)
    assert frames.dtype == np.float64
    assert frames.tolist() == [3.0, 4.0, 4.5, 5.0, 6.0]


# --- load_weight_animation -------------------------------------------------------------------
def weights_file(
    tmp_path: Path,
    interpolation: str | None = "LINEAR",
    names: list[str] | None = None,
    times: tuple[float, ...] = (0.0, 0.5, 1.0),
    n_targets: int = 2,
) -> tuple[Doc, dict]:
    targets = (SMILE, FROWN, SMILE)[:n_targets]
    d, _ = face(["smile", "frown", "again"][:n_targets] if names is None else names, targets)
    values = np.arange(len(times) * n_targets, dtype=np.float32) / 8
    return d, animate(d, list(times), values.tolist(), interpolation)


def test_weight_animation_names_times_and_weights(tmp_path: Path) -> None:
    d, _ = weights_file(tmp_path, None)
    names, times, weights = load_weight_animation(d.write(tmp_path / "w.gltf"))
    assert names == ["smile", "frown"]
    np.testing.assert_array_equal(times, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(weights, np.arange(6).reshape(3, 2) / 8)


def test_weight_animation_of_a_single_target(tmp_path: Path) -> None:
    d, _ = weights_file(tmp_path, "LINEAR", n_targets=1)
    names, times, weights = load_weight_animation(d.write(tmp_path / "w.gltf"))
    assert names == ["smile"] and times.tolist() == [0.0, 0.5, 1.0]
    np.testing.assert_array_equal(weights, [[0.0], [0.125], [0.25]])


def test_a_step_weight_animation_holds_each_value(tmp_path: Path) -> None:
    d, _ = weights_file(tmp_path, "STEP")
    _, times, weights = load_weight_animation(d.write(tmp_path / "w.gltf"))
    np.testing.assert_allclose(times, [0.0, 0.5 - 1e-6, 0.5, 1.0 - 1e-6, 1.0], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(weights, np.array([[0, 1], [0, 1], [2, 3], [2, 3], [4, 5]]) / 8)
    d, _ = weights_file(tmp_path, "STEP", times=(0.0, 0.25))  # two keys are held too
    _, times, weights = load_weight_animation(d.write(tmp_path / "w2.gltf"))
    np.testing.assert_allclose(times, [0.0, 0.25 - 1e-6, 0.25], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(weights, np.array([[0, 1], [0, 1], [2, 3]]) / 8)


def test_a_cubic_spline_weight_animation_is_refused(tmp_path: Path) -> None:
    d, _ = weights_file(tmp_path, "CUBICSPLINE")
    refused(
        d.write(tmp_path / "w.gltf"),
        "the weights animation is CUBICSPLINE; re-export it sampled (LINEAR)",
        load_weight_animation,
    )


@pytest.mark.parametrize(
    ("names", "mesh_name", "problem"),
    [
        (
            ["smile"],
            "head",
            "the animated mesh 'head' does not name its 2 morph targets in extras.targetNames",
        ),
        (
            None,
            None,
            "the animated mesh '' does not name its 2 morph targets in extras.targetNames",
        ),
        (
            [],
            "head",
            "the animated mesh 'head' does not name its 2 morph targets in extras.targetNames",
        ),
    ],
)
def test_the_animated_mesh_must_name_its_targets(
    tmp_path: Path, names: list[str] | None, mesh_name: str | None, problem: str
) -> None:
    d, _ = weights_file(tmp_path, names=["x", "y"])
    mesh = d.doc["meshes"][0]
    if names is None:
        del mesh["extras"]
    elif names:
        mesh["extras"]["targetNames"] = names
    else:
        mesh["extras"] = {}
    if mesh_name is None:
        del mesh["name"]
    refused(d.write(tmp_path / "w.gltf"), problem, load_weight_animation)


def test_an_animated_mesh_without_targets_is_refused(tmp_path: Path) -> None:
    d, _ = face([], targets=())
    animate(d, [0.0], [0.5])
    refused(
        d.write(tmp_path / "w.gltf"),
        "the animated mesh 'head' does not name its 0 morph targets in extras.targetNames",
        load_weight_animation,
    )


def test_weights_of_the_wrong_count_or_type_are_named(tmp_path: Path) -> None:
    d, animation = weights_file(tmp_path)
    sampler = animation["samplers"][0]
    sampler["output"] = d.data(np.zeros(5, np.float32))
    refused(
        d.write(tmp_path / "count.gltf"),
        "the weights animation has 5 values for 3 keys of 2 targets",
        load_weight_animation,
    )
    sampler["output"] = bad = d.data(np.zeros((6, 2), np.float32))
    refused(
        d.write(tmp_path / "out.gltf"),
        f"the animation's weights (accessor {bad}) is "
        "'VEC2' of component type 5126, expected SCALAR",
        load_weight_animation,
    )
    sampler["input"] = bad = d.data(np.zeros((3, 2), np.float32))
    refused(
        d.write(tmp_path / "in.gltf"),
        f"the animation's key times (accessor {bad}) is "
        "'VEC2' of component type 5126, expected SCALAR",
        load_weight_animation,
    )


def test_other_channels_are_skipped_to_the_weights_one(tmp_path: Path) -> None:
    d, animation = weights_file(tmp_path)
    animation["channels"][:0] = [
        {"sampler": 0},  # no target
        {"sampler": 0, "target": {"node": 0, "path": "translation"}},
        {"sampler": 0, "target": {"path": "weights"}},  # no node
    ]
    d.doc["animations"].insert(0, {})  # neither samplers nor channels
    names, times, _ = load_weight_animation(d.write(tmp_path / "w.gltf"))
    assert names == ["smile", "frown"] and times.tolist() == [0.0, 0.5, 1.0]


@pytest.mark.parametrize(
    "animations", [[], [{}], [{"channels": [{"target": {"node": 0, "path": "rotation"}}]}]]
)
def test_no_weights_animation_says_so(tmp_path: Path, animations: list) -> None:
    d, _ = face(["smile", "frown"])
    d.doc["animations"] = animations
    refused(
        d.write(tmp_path / "w.gltf"),
        "no animation of morph-target weights in the glTF file",
        load_weight_animation,
    )


def test_animations_that_are_not_a_list_are_named(tmp_path: Path) -> None:
    d, _ = face(["smile", "frown"])
    d.doc["animations"] = {}
    refused(d.write(tmp_path / "w.gltf"), "'animations' is not a JSON list", load_weight_animation)


def test_a_malformed_weight_animation_is_one_error(tmp_path: Path) -> None:
    d, animation = weights_file(tmp_path)
    del animation["samplers"]
    refused(
        d.write(tmp_path / "w.gltf"),
        "the glTF file is malformed (IndexError: list index out of range)",
        load_weight_animation,
    )
    del animation["channels"][0]["sampler"]
    refused(
        d.write(tmp_path / "w2.gltf"),
        "the glTF file is malformed (KeyError: 'sampler')",
        load_weight_animation,
    )
