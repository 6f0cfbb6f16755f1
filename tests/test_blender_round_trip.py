"""Through Blender and back: the studio's export imported by stock Blender (bpy 4.5 LTS) and
exported again, with Blender's default glTF options and with custom properties on, opens in the
studio with its whole set-up.

Blender's export drops the file's root extras (even with custom properties on) and every custom
vertex attribute, renumbers the textures and rebuilds the timeline as one track per pose. What
survives: the UV maps (TEXCOORD_1 holds the studio's welding and UDIM tiles) and each PNG byte
for byte (the neutral normal map's ``wrSt`` chunk holds the extras, naming images, and the
per-vertex data): core/formats/gltf/carry.py. Before, the default re-export lost the not-face
parts, and ``new --gltf FILE --auto`` showed 0.2 % (t1) and 0.55 % (t2) of pixels changed by
browInnerUp_L, its masks spread over the eyes.
"""

from __future__ import annotations

import io
import json
import struct
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.formats.gltf.codec import load_gltf, save_gltf
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from tests.test_blender_import import blender

POSES = ["browInnerUp_L", "browDown_L", "mouthSmile_L", "eyeSquint_L", "jawOpen"]
JUDGED = "browInnerUp_L"


def set_up_head() -> Project:
    """The ICT head with five poses set up as ``new --auto`` does (eyes, lashes and teeth not
    face, seven UDIM tiles, three wrinkled maps)."""
    from studio.core.sample.ict_head import load_ict_head
    from studio.core.setup.auto_setup import auto_start
    from studio.core.setup.face_frame import face_frame, face_locator

    project = load_ict_head(poses=POSES)
    auto_start(project, locate=face_locator(face_frame(project)))
    return project


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory) -> tuple[Project, dict[str, Path]]:
    """The set-up head exported, and Blender's two re-exports of it."""
    project = set_up_head()
    folder = tmp_path_factory.mktemp("round_trip")
    save_gltf(project, folder / "head.glb")
    files = {"default": folder / "default.glb", "extras": folder / "extras.glb"}
    blender(folder / "head.glb", "--export", files["default"])
    blender(folder / "head.glb", "--export", files["extras"], "--extras")
    return load_gltf(folder / "head.glb"), files


def glb_json(path: Path) -> dict:
    data = path.read_bytes()
    return json.loads(data[20:20 + struct.unpack_from("<I", data, 12)[0]])


def check_same_set_up(back: Project, project: Project) -> None:
    np.testing.assert_array_equal(back.mesh.weld, project.mesh.weld)
    np.testing.assert_array_equal(back.mesh.triangles, project.mesh.triangles)
    for got, want in zip(back.poses, project.poses, strict=True):
        assert got.name == want.name
        np.testing.assert_array_equal(got.positions, want.positions)
    np.testing.assert_array_equal(back.not_face, project.not_face)
    assert back.uv_tiles.layout.to_dict() == project.uv_tiles.layout.to_dict()
    np.testing.assert_array_equal(back.uv_tiles.vertex_tile, project.uv_tiles.vertex_tile)
    assert back.textures.wrinkle_map_names == project.textures.wrinkle_map_names
    for name, image in project.textures.wrinkle_maps.items():
        np.testing.assert_array_equal(back.textures.wrinkle_maps[name], image)
    np.testing.assert_array_equal(back.textures.normal_neutral, project.textures.normal_neutral)
    assert [a.name for a in back.influence.areas] == [a.name for a in project.influence.areas]
    for got, want in zip(back.influence.areas, project.influence.areas, strict=True):
        np.testing.assert_array_equal(got.mask, want.mask)
        assert got.wrinkle_map == want.wrinkle_map
    assert back.influence.links == project.influence.links
    assert [a.name for a in back.wdv.areas] == [a.name for a in project.wdv.areas]
    for got, want in zip(back.wdv.areas, project.wdv.areas, strict=True):
        np.testing.assert_array_equal(got.directions, want.directions)
        np.testing.assert_array_equal(got.lengths, want.lengths)
    assert back.timeline.to_dict() == project.timeline.to_dict()
    assert back.view == project.view


@pytest.mark.parametrize("options", ["default", "extras"])
def test_blender_s_re_export_opens_with_the_whole_set_up(round_trip, options):
    project, files = round_trip
    doc = glb_json(files[options])
    assert "Blender" in doc["asset"]["generator"]
    assert "extras" not in doc  # what the studio's extras rode in before
    assert not any(a.startswith("_") for a in doc["meshes"][0]["primitives"][0]["attributes"])
    report: list[str] = []
    back = load_gltf(files[options], report=report)
    check_same_set_up(back, project)
    assert report == ["the studio's set-up came back from the neutral normal map: another "
                      "tool re-exported this file without its extras"]


def changed_shares(project: Project, pose: str) -> dict[str, float]:
    """800 × 800, the default camera, ``pose`` at full weight: the share of pixels each
    technique changes against no technique (as tests/test_ict_head.py measures)."""
    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    with OffscreenStudio(project, 800, 800) as studio:
        plain = studio.render(RenderSettings(technique="none"), {pose: 1.0}).astype(int)
        return {t: float((np.abs(studio.render(RenderSettings(technique=t), {pose: 1.0})
                                 .astype(int) - plain).max(-1) > 4).mean())
                for t in ("t1", "t2")}


def test_new_auto_on_blender_s_default_re_export_shows_the_wrinkles(round_trip, tmp_path):
    _, files = round_trip
    out = io.StringIO()
    with redirect_stdout(out):
        assert main(["new", "--gltf", str(files["default"]), "--auto",
                     "-o", str(tmp_path / "back.wrinkle")]) == 0
    assert "came back from the neutral normal map" in out.getvalue()
    shares = changed_shares(load_project(tmp_path / "back.wrinkle"), JUDGED)
    assert shares["t1"] >= 0.01 and shares["t2"] >= 0.01, shares


def test_the_studio_s_own_reading_of_the_default_re_export_shows_the_wrinkles(round_trip):
    _, files = round_trip
    shares = changed_shares(load_gltf(files["default"]), JUDGED)
    assert shares["t1"] >= 0.01 and shares["t2"] >= 0.01, shares
