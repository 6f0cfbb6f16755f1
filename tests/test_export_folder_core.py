"""The engine-ready export folder (``export_folder``), checked file by file on a tiny face.

A game engine reads these files by name: the glb, one mask per area (16-bit by default), the
masks packed four to an RGBA image, each wrinkled normal map, the neutral map, the GLSL, and
``wrinkles.json`` that ties them together. A face on two UDIM tiles also gets each file cut
back into one image per tile. Every name, pixel and manifest entry below is worked out by hand
from the tiny face's inputs, and a folder that cannot be written must say which file failed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import StudioError
from studio.core.files.images import read_image
from studio.core.formats.export import export_folder
from studio.core.formats.gltf.codec import load_gltf
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import pack_mesh
from studio.core.project.model import Project
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.textures import FaceTextures
from studio.core.wrinkles.wdv import WdvArea
from studio.paths import shader_dir

pytestmark = pytest.mark.core

REST = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
AREA_NAMES = ["brow L/R", "smile", "crow's feet", "nose", "chin"]
SAFE_NAMES = ["brow_L_R", "smile", "crow_s_feet", "nose", "chin"]
SHADERS = [
    "common.glsl",
    "skin.glsl",
    "relief.glsl",
    "face.vert",
    "face.tesc",
    "face.tese",
    "face.frag",
    "t1_compose.vert",
    "t1_compose.frag",
]


def levels(i: int) -> np.ndarray:
    """(4, 4) whole levels 0..5 for area ``i``: its mask is levels / 5."""
    r, c = np.mgrid[0:4, 0:4]
    return (r * 4 + c + i) % 6


def rgb(offset: int) -> np.ndarray:
    """A 4 × 4 RGB map whose every channel value is distinct (offset + 0..47)."""
    return (np.arange(48).reshape(4, 4, 3) + offset).astype(np.uint8)


def tiny_project(udim: bool) -> Project:
    """Two triangles (a quad), one per UDIM tile 1001 / 1002 when ``udim`` (both skin: the
    atlas puts 1001 in the top-left quarter, 1002 in the top-right one), else both in 1001.
    Five influence areas (so two packed images), two wrinkled maps, two WDV areas."""
    shift = 1.0 if udim else 0.0
    uvs = np.array(
        [
            [0.1, 0.1],
            [0.9, 0.1],
            [0.1, 0.9],
            [0.1 + shift, 0.1],
            [0.9 + shift, 0.1],
            [0.1 + shift, 0.9],
        ]
    )
    mesh = FaceMesh(REST, [[0, 1, 2], [3, 4, 5]], uvs, [1, 0, 2, 1, 3, 2], source="face.obj")
    mesh, tiles = pack_mesh(mesh)
    textures = FaceTextures(
        rgb(0), rgb(200), wrinkle_maps={"forehead": rgb(50), "smile lines": rgb(100)}
    )
    project = Project(
        "tiny",
        mesh,
        [KeyPose("smile", REST + np.array([0, 0, 0.1], np.float32))],
        textures,
        uv_tiles=tiles,
    )
    maps = ["", "smile lines", "missing", "", "smile lines"]
    activations = [0.25, 0.0, 0.5, 0.0, 1.0]
    project.influence.areas = [
        InfluenceArea(name, levels(i) / 5.0, activation=activations[i], wrinkle_map=maps[i])
        for i, name in enumerate(AREA_NAMES)
    ]
    project.influence.links = {"smile": {"smile": 0.75, "chin": 0.5}}
    project.wdv.expression_factor = 1.5
    project.wdv.scale_free = False
    project.wdv.areas = [
        WdvArea.empty("forehead lift", "smile", 4, cone_angle_deg=15.0, wrinkle_map="smile lines"),
        WdvArea.empty(
            "cheek", "smile", 4, cone_angle_deg=30.0, cone_angles_deg=np.array([0, 10, 0, 5])
        ),
    ]
    return project


def export_quickly(project: Project, folder: Path, **kwargs: object) -> list[Path]:
    """``export_folder`` without the fsyncs (durability is not under test; they cost 0.4 s)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(os, "fsync", lambda _fd: None)
        return export_folder(project, folder, **kwargs)


@pytest.fixture(scope="module")
def udim_export(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path]]:
    folder = tmp_path_factory.mktemp("udim") / "engine"
    return folder, export_quickly(tiny_project(udim=True), folder)


def relative(folder: Path, written: list[Path]) -> list[str]:
    return [path.relative_to(folder).as_posix() for path in written]


def test_every_file_written_is_listed_in_order(udim_export: tuple[Path, list[Path]]) -> None:
    """The glb with the three.js module and its example page, each mask and its two tile
    copies, the packed masks (five areas: two images), the wrinkled maps, the neutral map, the
    Blender script, the sheet and the shaders; nothing else is there."""
    folder, written = udim_export
    expected = ["face.glb", "wrinkles.js", "example.html"]
    for i, name in enumerate(SAFE_NAMES):
        expected += [f"masks/{i:02d}_{name}{tile}.png" for tile in ("", ".1001", ".1002")]
    for k in (0, 1):
        expected += [f"masks/packed_0{k}{tile}.png" for tile in ("", ".1001", ".1002")]
    for stem in ("wrinkled_0_forehead", "wrinkled_1_smile_lines"):
        expected += [f"maps/{stem}{tile}.png" for tile in ("", ".1001", ".1002")]
    expected += ["maps/neutral.png", "blender_wrinkles.py", "wrinkles.json",
                 *(f"shaders/{s}" for s in SHADERS)]
    assert relative(folder, written) == expected
    on_disk = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())
    assert on_disk == sorted(expected)


def test_masks_are_16_bit_by_default_with_a_copy_per_tile(
    udim_export: tuple[Path, list[Path]],
) -> None:
    """Level k/5 is k · 13107 in 16 bits; tile 1001's copy is the atlas's top-left 2 × 2,
    tile 1002's the top-right 2 × 2 (each tile's cell is a quarter of the atlas)."""
    folder, _ = udim_export
    for i, name in enumerate(SAFE_NAMES):
        expected = levels(i) * 13107
        mask = read_image(folder / "masks" / f"{i:02d}_{name}.png")
        assert mask.dtype == np.uint16 and mask.shape == (4, 4)
        assert np.array_equal(mask, expected)
        left = read_image(folder / "masks" / f"{i:02d}_{name}.1001.png")
        right = read_image(folder / "masks" / f"{i:02d}_{name}.1002.png")
        assert left.dtype == right.dtype == np.uint16
        assert np.array_equal(left, expected[:2, :2])
        assert np.array_equal(right, expected[:2, 2:])


def test_packed_masks_hold_four_areas_each_in_8_bits(udim_export: tuple[Path, list[Path]]) -> None:
    """packed_00 is areas 0-3 in R, G, B, A (level k/5 is k · 51); packed_01 has area 4 in R
    and zero in G, B and A. Their tile copies are the same quarters as the masks'."""
    folder, _ = udim_export
    first = read_image(folder / "masks" / "packed_00.png")
    second = read_image(folder / "masks" / "packed_01.png")
    assert first.dtype == second.dtype == np.uint8
    assert first.shape == second.shape == (4, 4, 4)
    for channel in range(4):
        assert np.array_equal(first[:, :, channel], levels(channel) * 51)
    assert np.array_equal(second[:, :, 0], levels(4) * 51)
    assert not second[:, :, 1:].any()
    assert np.array_equal(read_image(folder / "masks" / "packed_00.1001.png"), first[:2, :2])
    assert np.array_equal(read_image(folder / "masks" / "packed_01.1002.png"), second[:2, 2:])


def test_maps_are_written_as_they_are_with_a_copy_per_tile(
    udim_export: tuple[Path, list[Path]],
) -> None:
    folder, _ = udim_export
    maps = folder / "maps"
    for stem, image in (("wrinkled_0_forehead", rgb(50)), ("wrinkled_1_smile_lines", rgb(100))):
        assert np.array_equal(read_image(maps / f"{stem}.png"), image)
        assert np.array_equal(read_image(maps / f"{stem}.1001.png"), image[:2, :2])
        assert np.array_equal(read_image(maps / f"{stem}.1002.png"), image[:2, 2:])
    assert np.array_equal(read_image(maps / "neutral.png"), rgb(200))


def area_entry(i: int, activation: float, wrinkle_map: int) -> dict:
    return {
        "name": AREA_NAMES[i],
        "mask": f"masks/{i:02d}_{SAFE_NAMES[i]}.png",
        "packed": {"image": f"masks/packed_0{i // 4}.png", "channel": "RGBA"[i % 4]},
        "activation": activation,
        "wrinkle_map": wrinkle_map,
    }


EXPECTED_SHEET = {
    "wrinkle_maps": [
        {"name": "forehead", "index": 0, "image": "maps/wrinkled_0_forehead.png"},
        {"name": "smile lines", "index": 1, "image": "maps/wrinkled_1_smile_lines.png"},
    ],
    # "missing" names no map: the first one (0)
    "areas": [
        area_entry(0, 0.25, 0),
        area_entry(1, 0.0, 1),
        area_entry(2, 0.5, 0),
        area_entry(3, 0.0, 0),
        area_entry(4, 1.0, 1),
    ],
    "pose_links": {"smile": {"smile": 0.75, "chin": 0.5}},
    "pose_curves": {},
    "uv_tiles": {
        "tiles": [1001, 1002],
        "cells": [[0.0, 0.0, 0.5], [0.5, 0.0, 0.5]],
        "skin_tiles": [1001, 1002],
        "note": "masks and maps are atlases (the glTF's UVs); files named NAME.<UDIM>.png hold "
        "each skin tile in its own 0-1 square",
    },
    "packed_layout": [
        {"image": "packed_00.png", "channels": ["brow L/R", "smile", "crow's feet", "nose"]},
        {"image": "packed_01.png", "channels": ["chin"]},
    ],
    "wdv": {
        "expression_factor": 1.5,
        "scale_free": False,
        "areas": [
            {
                "name": "forehead lift",
                "pose": "smile",
                "cone_angle_deg": 15.0,
                "wrinkle_map": 1,
                "attributes": ["_WRINKLE_DIR_0", "_WRINKLE_LEN_CONE_0"],
                "painted_cones": False,
            },
            {
                "name": "cheek",
                "pose": "smile",
                "cone_angle_deg": 30.0,
                "wrinkle_map": 0,
                "attributes": ["_WRINKLE_DIR_1", "_WRINKLE_LEN_CONE_1"],
                "painted_cones": True,
            },
        ],
    },
}


def test_the_link_sheet_names_every_file_and_setting(udim_export: tuple[Path, list[Path]]) -> None:
    """wrinkles.json, key by key; a WDV area says whether its cone angles are painted."""
    folder, _ = udim_export
    sheet = json.loads((folder / "wrinkles.json").read_text(encoding="utf-8"))
    assert list(sheet) == list(EXPECTED_SHEET)
    for key, value in EXPECTED_SHEET.items():
        assert sheet[key] == value, key


def test_the_link_sheet_is_indented_by_two_spaces(udim_export: tuple[Path, list[Path]]) -> None:
    folder, _ = udim_export
    text = (folder / "wrinkles.json").read_text(encoding="utf-8")
    assert text.startswith('{\n  "wrinkle_maps": [\n    {\n      "name": "forehead",\n')


def test_the_shaders_are_copied_byte_for_byte(udim_export: tuple[Path, list[Path]]) -> None:
    folder, _ = udim_export
    for name in SHADERS:
        copied = (folder / "shaders" / name).read_bytes()
        assert copied and copied == (shader_dir() / name).read_bytes(), name


def test_the_glb_is_the_whole_face_in_the_projects_tangent_frame(
    udim_export: tuple[Path, list[Path]],
) -> None:
    folder, _ = udim_export
    back = load_gltf(folder / "face.glb")
    assert back.pose_names == ["neutral", "smile"]
    assert [a.name for a in back.influence.areas] == AREA_NAMES
    assert back.view["view"]["tangent_frame"] == "mikktspace"
    assert back.uv_tiles is not None and back.uv_tiles.layout.tiles == (1001, 1002)


def test_an_8_bit_export_of_a_face_on_one_tile(tmp_path: Path) -> None:
    """bits=8: masks in 8 bits (level k/5 is k · 51); one tile: no per-tile copies and no
    ``uv_tiles`` entry; the tangent frame asked for is the glb's."""
    folder = tmp_path / "out"
    written = export_quickly(tiny_project(udim=False), folder, bits=8, tangent_frame="thesis")
    names = relative(folder, written)
    assert not [name for name in names if ".100" in name]
    assert names[:5] == ["face.glb", "wrinkles.js", "example.html", "masks/00_brow_L_R.png",
                         "masks/01_smile.png"]
    assert len(names) == 3 + 5 + 2 + 2 + 1 + 1 + 1 + len(SHADERS)
    mask = read_image(folder / "masks" / "04_chin.png")
    assert mask.dtype == np.uint8 and np.array_equal(mask, levels(4) * 51)
    sheet = json.loads((folder / "wrinkles.json").read_text(encoding="utf-8"))
    assert "uv_tiles" not in sheet
    assert sheet["packed_layout"] == EXPECTED_SHEET["packed_layout"]
    assert load_gltf(folder / "face.glb").view["view"]["tangent_frame"] == "thesis"


def test_a_folder_that_is_a_file_is_refused(tmp_path: Path) -> None:
    target = tmp_path / "engine"
    target.write_text("not a folder")
    with pytest.raises(StudioError, match=r"engine: cannot create the export folder: "):
        export_quickly(tiny_project(udim=False), target)


def test_a_link_sheet_that_cannot_be_written_is_named(tmp_path: Path) -> None:
    folder = tmp_path / "out"
    (folder / "wrinkles.json").mkdir(parents=True)
    with pytest.raises(StudioError, match=r"wrinkles\.json: cannot write the link sheet: "):
        export_quickly(tiny_project(udim=False), folder)


def test_a_shader_that_cannot_be_written_is_named(tmp_path: Path) -> None:
    folder = tmp_path / "out"
    (folder / "shaders" / "face.vert").mkdir(parents=True)
    with pytest.raises(StudioError, match=r"face\.vert: cannot write the shader: "):
        export_quickly(tiny_project(udim=False), folder)
