"""Engine layouts out (``export --layout``): every texture and channel the sheet claims is read
back with PIL and compared with the areas it names; the names are the engines' own; a project an
engine cannot hold is refused before anything is written."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import Timeline
from studio.core.engines.export import SHEET, export_layout
from studio.core.engines.layouts import LAYOUTS
from studio.core.engines.plan import LayoutError
from studio.core.files.errors import StudioError
from studio.core.project.model import Project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.wdv import WdvSetup

# the sample's areas, linked to ARKit poses as a capture rig would drive them
ARKIT_LINKS = {
    "browInnerUp": {"forehead right": 1.0, "forehead left": 1.0},
    "browDown_L": {"between brows": 1.0},
    "eyeSquint_L": {"eye corner left": 1.0, "under eye left": 0.5},
    "eyeSquint_R": {"eye corner right": 1.0, "under eye right": 0.5},
    "mouthSmile_R": {"cheeks": 1.0},
}


def arkit_face() -> Project:
    """The small sample face with its five key poses renamed to the ARKit shapes above."""
    project = make_test_face(561, texture_size=64, mask_size=32)
    project.poses = [KeyPose(name, pose.positions)
                     for name, pose in zip(ARKIT_LINKS, project.poses, strict=True)]
    project.timeline = Timeline()
    project.wdv = WdvSetup()  # technique 2 is not part of a layout
    project.influence.links = {pose: dict(gains) for pose, gains in ARKIT_LINKS.items()}
    return project


def pil_pixels(path: Path) -> np.ndarray:
    """The file's pixels as PIL reads them (RGBA, 8-bit)."""
    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))


def expected_channel(project: Project, sources: list[dict]) -> np.ndarray:
    """What a channel must hold: the named areas' masks × gains, added, clamped, 8-bit."""
    masks = {a.name: a.mask for a in project.influence.areas}
    shape = project.influence.areas[0].mask.shape
    total = sum((masks[s["area"]] * s["gain"] for s in sources), np.zeros(shape))
    return np.round(np.clip(total, 0, 1) * 255).astype(np.uint8)


def check_sheet_against_files(project: Project, folder: Path) -> dict:
    """Every mask texture channel holds exactly the areas the sheet says; returns the sheet."""
    sheet = json.loads((folder / SHEET).read_text())
    for texture in sheet["mask_textures"]:
        pixels = pil_pixels(folder / texture["file"])
        for c, channel in enumerate("RGBA"):
            claimed = texture["channels"].get(channel, {"areas": []})["areas"]
            assert np.array_equal(pixels[:, :, c], expected_channel(project, claimed)), \
                f"{texture['file']} {channel}"
    return sheet


@pytest.mark.core
@pytest.mark.parametrize("key", list(LAYOUTS))
def test_each_channel_holds_the_areas_its_sheet_names(key, tmp_path):
    project = arkit_face()
    plan, files = export_layout(project, tmp_path, key)
    sheet = check_sheet_against_files(project, tmp_path)
    assert sheet["layout"] == key and sheet["samplers"] == plan.samplers
    assert all(path.is_file() for path in files)
    placed = {a["area"] for a in sheet["areas"] if a["channels"]}
    flexed = {s["area"] for f in sheet["flexes"] for s in f["areas"]}
    unassigned = {u["area"] for u in sheet["unassigned"]}
    # every area is somewhere, or said not to be
    assert placed | flexed | unassigned == {a.name for a in project.influence.areas}


@pytest.mark.core
def test_the_sheet_names_the_engines_regions(tmp_path):
    project = arkit_face()
    export_layout(project, tmp_path / "mh", "metahuman")
    mh = json.loads((tmp_path / "mh" / SHEET).read_text())
    where = {a["area"]: {(c["texture"], c["channel"], c["region"]) for c in a["channels"]}
             for a in mh["areas"]}
    # a central pose on a sided pair: each side's area in its own half
    assert where["forehead left"] == {("T_head_wm1_msk_01", "B", "head_wm1_browsRaiseInner_L")}
    assert where["forehead right"] == {("T_head_wm1_msk_01", "A", "head_wm1_browsRaiseInner_R")}
    assert where["between brows"] == {("T_head_wm2_msk_01", "R", "head_wm2_browsLateral_L")}
    assert where["cheeks"] == {("T_head_wm3_msk_02", "A", "head_wm3_smile_R")}
    assert [m["name"] for m in mh["wrinkle_maps"]] == ["head_wm1_normal", "head_wm2_normal",
                                                       "head_wm3_normal"]
    export_layout(project, tmp_path / "cc", "cc")
    cc = json.loads((tmp_path / "cc" / SHEET).read_text())
    sets = {t["texture"]: t["channels"] for t in cc["mask_textures"]}
    assert list(sets) == ["_WrinkleMaskSet1A", "_WrinkleMaskSet1B", "_WrinkleMaskSet2",
                          "_WrinkleMaskSet3", "_WrinkleMaskSet123"]
    # Character Creator shares a channel between the sides
    inner = sets["_WrinkleMaskSet1A"]["G"]
    assert inner["region"] == "head_wm1_normal_head_wm1_browRaiseInner"
    assert {a["area"] for a in inner["areas"]} == {"forehead left", "forehead right"}
    assert sets["_WrinkleMaskSet3"]["A"]["region"] == "head_wm3_normal_head_wm3_smile"
    export_layout(project, tmp_path / "o3de", "o3de")
    assert (tmp_path / "o3de" / "face_wrinklemasks" / "mouthSmile_R_wrinklemask.tif").is_file()


@pytest.mark.core
def test_the_sheet_carries_each_links_response_curve(tmp_path):
    project = arkit_face()
    pose, gains = next(iter(ARKIT_LINKS.items()))
    area = next(iter(gains))
    project.influence.curves = {pose: {area: ResponseCurve("ease_in")}}
    export_layout(project, tmp_path / "mh", "metahuman")
    sheet = json.loads((tmp_path / "mh" / SHEET).read_text())
    entries = [a for t in sheet["mask_textures"] for c in t["channels"].values()
               for a in c["areas"]]
    curved = [a for a in entries if "response" in a]
    assert curved and {a["area"] for a in curved} == {area}
    assert all(a["response"] == {pose: {"kind": "ease_in"}} for a in curved)
    assert all("response" not in a for a in entries if a["area"] != area)  # linear: left out


@pytest.mark.core
def test_a_second_area_of_a_pose_takes_the_next_free_region(tmp_path):
    """browDown drives two MetaHuman regions: the first area fills browsLateral, the next
    browsDown; a third has no free region left and is added into the first."""
    project = arkit_face()
    for name in ("brow lower left", "brow knot left"):
        project.influence.areas.append(InfluenceArea(name, np.full((32, 32), 0.25, np.float32)))
        project.influence.links["browDown_L"][name] = 1.0
    export_layout(project, tmp_path, "metahuman")
    sheet = check_sheet_against_files(project, tmp_path)
    where = {a["area"]: [c["region"] for c in a["channels"]] for a in sheet["areas"]}
    assert where["between brows"] == ["head_wm2_browsLateral_L"]
    assert where["brow lower left"] == ["head_wm2_browsDown_L"]
    assert where["brow knot left"] == ["head_wm2_browsLateral_L"]


@pytest.mark.core
def test_o3de_masks_follow_the_links_gains_per_wrinkle_layer(tmp_path):
    project = arkit_face()
    export_layout(project, tmp_path, "o3de")
    squint = pil_pixels(tmp_path / "face_wrinklemasks" / "eyeSquint_L_wrinklemask.tif")
    areas = {a.name: a for a in project.influence.areas}
    layer = project.textures.map_index(areas["eye corner left"].wrinkle_map)
    want = np.clip(areas["eye corner left"].mask + 0.5 * areas["under eye left"].mask, 0, 1)
    assert np.array_equal(squint[:, :, layer], np.round(want * 255).astype(np.uint8))
    assert not squint[:, :, [c for c in range(4) if c != layer]].any()


@pytest.mark.core
def test_source_flex_weights_per_vertex_and_one_compress_map(tmp_path):
    project = arkit_face()
    export_layout(project, tmp_path, "source")
    with open(tmp_path / "flex_wrinkles.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["vertex", *ARKIT_LINKS]
    assert len(rows) == 1 + project.mesh.n_vertices
    # the brow flex's weight at each vertex: the forehead masks under its UV (nearest texel)
    uv = project.mesh.uvs
    r = np.clip(((1 - uv[:, 1]) * 32).astype(int), 0, 31)
    c = np.clip((uv[:, 0] * 32).astype(int), 0, 31)
    areas = {a.name: a.mask for a in project.influence.areas}
    want = np.clip(areas["forehead right"][r, c] + areas["forehead left"][r, c], 0, 1)
    got = np.array([float(row[1]) for row in rows[1:]])
    np.testing.assert_allclose(got, want, atol=5e-5)
    assert got.max() > 0.5
    sheet = json.loads((tmp_path / SHEET).read_text())
    assert [m["name"] for m in sheet["wrinkle_maps"]] == ["bumpcompress", "bumpstretch"]
    assert all(f["wrinkle_scale"] > 0 for f in sheet["flexes"])  # compression, never stretch


@pytest.mark.core
def test_a_wrinkle_map_slot_shows_each_areas_own_map(tmp_path):
    """The sample's forehead reveals the brow map and the eye corners another; MetaHuman's wm1
    holds both, each texel from the map of the area strongest there, neutral elsewhere."""
    project = arkit_face()
    export_layout(project, tmp_path, "metahuman")
    sheet = json.loads((tmp_path / SHEET).read_text())
    slot = next(m for m in sheet["wrinkle_maps"] if m["name"] == "head_wm1_normal")
    wm1 = pil_pixels(tmp_path / slot["file"])[:, :, :3]
    areas = {a.name: a for a in project.influence.areas}
    textures = project.textures
    assert len({areas[name].wrinkle_map for name in slot["areas"]}) == 2
    stack = np.stack([areas[name].mask for name in slot["areas"]])
    scale = wm1.shape[0] // stack.shape[1]
    for k, name in enumerate(slot["areas"]):  # where the area is the strongest of the slot
        lead = np.where(stack.argmax(axis=0) == k, stack[k], 0)
        y, x = np.unravel_index(np.argmax(lead), lead.shape)
        assert lead[y, x] > 0.5
        own = textures.wrinkle_maps[areas[name].wrinkle_map]
        assert np.array_equal(wm1[y * scale, x * scale], own[y * scale, x * scale, :3]), name
    # where no area of the slot reaches, the neutral map (not the wrinkled maps' folds)
    none = np.kron(stack.max(axis=0) == 0, np.ones((scale, scale), bool))
    first = textures.wrinkle_maps[areas[slot["areas"][0]].wrinkle_map][:, :, :3]
    folds = none & (first != textures.normal_neutral[:, :, :3]).any(axis=2)
    assert folds.any()
    assert np.array_equal(wm1[none], textures.normal_neutral[:, :, :3][none])


@pytest.mark.core
def test_an_area_no_region_fits_is_reported(tmp_path):
    project = arkit_face()
    project.influence.areas.append(InfluenceArea("tongue", np.ones((32, 32), np.float32)))
    project.influence.links["tongueOut"] = {"tongue": 1.0}
    plan, _ = export_layout(project, tmp_path, "metahuman")
    assert [area for area, _ in plan.unassigned] == ["tongue"]
    sheet = check_sheet_against_files(project, tmp_path)
    (said,) = sheet["unassigned"]
    assert said["area"] == "tongue" and "metahuman" in said["why"]


@pytest.mark.core
def test_more_morph_target_masks_than_o3de_blends_is_refused(tmp_path):
    project = arkit_face()
    for i in range(17 - len(ARKIT_LINKS)):
        project.influence.links[f"extra_{i}"] = {"cheeks": 1.0}
    with pytest.raises(LayoutError, match="17 wrinkle masks, more than the 16"):
        export_layout(project, tmp_path / "out", "o3de")
    assert not (tmp_path / "out").exists()


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "studio.cli", *args], capture_output=True,
                          text=True, cwd=Path(__file__).parents[1], timeout=300)


def test_too_many_areas_for_a_layout_is_one_line_and_writes_nothing(tmp_path):
    project = arkit_face()
    project.influence.areas += [InfluenceArea(f"extra {i}", np.zeros((32, 32), np.float32))
                                for i in range(61 - len(project.influence.areas))]
    save_project(project, tmp_path / "crowded.wrinkle")
    out = tmp_path / "out"
    done = run_cli("export", str(tmp_path / "crowded.wrinkle"), "--layout", "studio",
                   "--folder", str(out))
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and str(tmp_path / "crowded.wrinkle") in lines[0]
    # 61 areas: 16 packed textures, and the sample's 2 wrinkled maps
    assert "needs 18 samplers, more than the 16" in lines[0]
    assert not out.exists()


@pytest.mark.core
def test_a_layout_never_writes_over_its_input(tmp_path):
    project = arkit_face()
    target = tmp_path / "face.glb"  # the name the layout gives its model
    save_project(project, target)
    before = target.read_bytes()
    with pytest.raises(StudioError, match="overwrite the input"):
        export_layout(project, tmp_path, "metahuman", inputs=[target])
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["face.glb"]


@pytest.fixture(scope="module")
def production_head(tmp_path_factory) -> tuple[Path, Project]:
    """A head in production conventions (mm, Z up, UDIM tiles, ARKit names) set up by
    ``new --auto``, as tests/test_production_head.py imports it."""
    from studio.cli import main
    from studio.core.project.reader import load_project
    from tests.test_production_head import import_head

    folder = tmp_path_factory.mktemp("head")
    _, args = import_head(folder)
    assert main(args) == 0
    path = folder / "mm.wrinkle"
    return path, load_project(path)


@pytest.mark.parametrize("key", list(LAYOUTS))
def test_a_production_head_exports_in_every_layout(production_head, key, tmp_path):
    path, project = production_head
    out = tmp_path / key
    done = run_cli("export", str(path), "--layout", key, "--folder", str(out))
    assert done.returncode == 0, done.stderr
    assert f"{LAYOUTS[key].label}: " in done.stdout
    sheet = check_sheet_against_files(project, out)
    assert project.skin_tiles() == [1001]
    layout = project.uv_tiles.layout
    for texture in sheet["mask_textures"]:  # the skin tile's own square beside each atlas
        atlas = out / texture["file"]
        tile = atlas.with_name(f"{atlas.stem}.1001{atlas.suffix}")
        assert np.array_equal(pil_pixels(tile), layout.crop(pil_pixels(atlas), 1001))
    placed = {a["area"]: {c["region"] for c in a["channels"]} for a in sheet["areas"]}
    expected = {"metahuman": {"browDown_L": "head_wm2_browsLateral_L",
                              "mouthSmile_R": "head_wm3_smile_R",
                              "eyeSquint_L": "head_wm1_squintInner_L"},
                "cc": {"browDown_L": "head_wm2_normal_head_wm2_browsDown",
                       "mouthSmile_R": "head_wm3_normal_head_wm3_smile"}}.get(key, {})
    for area, region in expected.items():
        assert placed[area] == {region}, area
    if key == "metahuman":  # the pose of the middle of the face fills both halves of its pair
        assert placed["browInnerUp"] == {"head_wm1_browsRaiseInner_L",
                                         "head_wm1_browsRaiseInner_R"}
    if key == "o3de":
        masks = {t["texture"] for t in sheet["mask_textures"]}
        assert {"browInnerUp", "mouthSmile_L", "eyeSquint_R"} <= masks
    if key == "source":
        assert {"browDown_L", "mouthSmile_L"} <= {f["flex"] for f in sheet["flexes"]}
