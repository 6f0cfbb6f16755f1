"""The engine layout planner (studio/core/engines/plan.py) and its export
(studio/core/engines/export.py) on small faces built by hand: which area goes into which channel,
the maps and samplers each layout counts, what is refused, and the files and sheet written."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.engines.export import (
    SHEET,
    channel_values,
    export_layout,
    flex_table,
    layout_sheet,
    map_image,
    mask_texture,
    vertex_values,
)
from studio.core.engines.layouts import CC, LAYOUTS, METAHUMAN, O3DE, SOURCE, STUDIO
from studio.core.engines.plan import (
    Channel,
    Flex,
    LayoutError,
    MapSlot,
    MaskTexture,
    Plan,
    linked_poses,
    own_maps,
    plan_export,
)
from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import UvTiles, plan_layout
from studio.core.project.model import Project
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.textures import FaceTextures

pytestmark = pytest.mark.core

MASK = 4  # masks are MASK x MASK texels


def flat(size: int, rgb: tuple[int, int, int] = (128, 128, 255)) -> np.ndarray:
    image = np.empty((size, size, 3), np.uint8)
    image[...] = rgb
    return image


def face(areas: list[str | InfluenceArea], links: dict[str, dict[str, float]],
         maps: tuple[str, ...] = ("brow", "smile lines"),
         uvs: tuple[tuple[float, float], ...] = ((0, 0), (1, 0), (1, 1), (0, 1))) -> Project:
    """A quad of four vertices at ``uvs``; areas (a name: a MASK x MASK mask of 0.5, on the
    first map); a neutral map of 6 x 6, unlike the masks and maps."""
    rest = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    mesh = FaceMesh(rest, np.array([[0, 1, 2], [0, 2, 3]]), np.array(uvs, np.float32),
                    np.arange(4))
    textures = FaceTextures(flat(MASK, (200, 150, 140)), flat(6),
                            wrinkle_maps={name: flat(MASK, (100 + 40 * k, 90, 250))
                                          for k, name in enumerate(maps)})
    made = [a if isinstance(a, InfluenceArea) else InfluenceArea(a, np.full((MASK, MASK), 0.5))
            for a in areas]
    return Project("test", mesh, [], textures, InfluenceSetup(made, links))


def sources(plan: Plan) -> dict[tuple[str, str], list[tuple[int, float]]]:
    """(texture, channel) → the (area, gain) added into it, for the channels that hold any."""
    return {(t.name, c.channel): c.sources for t in plan.masks for c in t.channels if c.sources}


def regions_of(plan: Plan, project: Project) -> dict[str, list[str]]:
    """Area name → the regions it went into, in mask order."""
    out: dict[str, list[str]] = {a.name: [] for a in project.influence.areas}
    for t in plan.masks:
        for c in t.channels:
            for i, _ in c.sources:
                out[project.influence.areas[i].name].append(c.region)
    return out


# --- choosing a layout, and its limit ---------------------------------------------------------


def test_an_unknown_layout_names_the_known_ones() -> None:
    """plan_export refuses a key that is no layout, listing the layouts."""
    with pytest.raises(StudioError, match=r"unknown layout 'unreal' \(layouts: metahuman, cc, "
                                          r"o3de, source, studio\)"):
        plan_export(face([], {}), "unreal")


@pytest.mark.parametrize("key", list(LAYOUTS))
def test_each_layout_gets_its_own_planner(key: str) -> None:
    """The plan is made for the layout asked for, whatever its kind."""
    project = face(["brow left"], {"browDown_L": {"brow left": 1.0}})
    plan = plan_export(project, key)
    assert plan.layout is LAYOUTS[key]


def test_a_plan_at_the_limit_passes_and_one_over_is_refused() -> None:
    """check() accepts exactly the engine's limit and refuses one more, in one line."""
    Plan(STUDIO, [], [], [], 16, 16).check()
    with pytest.raises(LayoutError) as refused:
        Plan(STUDIO, [], [], [], 17, 17).check()
    assert str(refused.value) == (
        "the studio layout needs 17 samplers, more than the 16 texture units a fragment "
        "shader is guaranteed (OpenGL 3.3, Direct3D 11)")


# --- links ------------------------------------------------------------------------------------


def test_linked_poses_keeps_positive_links_to_known_areas_in_link_order() -> None:
    """Area → its (pose, gain) links that raise it; zero, negative and dangling ones left out."""
    project = face(["a", "b", "c"], {
        "smile": {"b": 0.5, "ghost": 1.0, "a": 0},
        "frown": {"b": 1, "c": -0.5},
        "blink": {"a": 2.0}})
    got = linked_poses(project)
    assert got == {1: [("smile", 0.5), ("frown", 1.0)], 0: [("blink", 2.0)]}
    assert all(isinstance(g, float) for poses in got.values() for _, g in poses)


# --- the studio's own: four areas to a texture ------------------------------------------------


def test_the_studio_packs_areas_four_to_a_texture_in_order() -> None:
    """Areas 0-3 in packed_00's RGBA, 4-5 in packed_01; samplers = textures + project maps."""
    areas = ["brow left", "brow right", "frown", "cheek", "lip L", "chin"]
    project = face(areas, {})
    project.influence.areas[3].wrinkle_map = "smile lines"
    project.influence.areas[5].wrinkle_map = "smile lines"
    plan = plan_export(project, "studio")
    assert plan.masks == [
        MaskTexture("packed_00", "masks/packed_00.png", [
            Channel("R", "brow left", "left", 0, [(0, 1.0)]),
            Channel("G", "brow right", "right", 0, [(1, 1.0)]),
            Channel("B", "frown", None, 0, [(2, 1.0)]),
            Channel("A", "cheek", None, 1, [(3, 1.0)])]),
        MaskTexture("packed_01", "masks/packed_01.png", [
            Channel("R", "lip L", "left", 0, [(4, 1.0)]),
            Channel("G", "chin", None, 1, [(5, 1.0)])])]
    assert plan.maps == [MapSlot("brow", "maps/wrinkled_0_brow.png", source="brow"),
                         MapSlot("smile lines", "maps/wrinkled_1_smile_lines.png",
                                 source="smile lines")]
    assert (plan.used, plan.samplers, plan.unassigned, plan.flexes) == (4, 4, [], [])


def test_the_studio_plan_of_nine_areas_has_three_textures() -> None:
    """⌈9 / 4⌉ = 3 packed textures; the last holds the ninth area alone."""
    plan = plan_export(face([f"area {i}" for i in range(9)], {}, maps=("only",)), "studio")
    assert [m.name for m in plan.masks] == ["packed_00", "packed_01", "packed_02"]
    assert [[s for c in m.channels for s in c.sources] for m in plan.masks] == [
        [(0, 1.0), (1, 1.0), (2, 1.0), (3, 1.0)], [(4, 1.0), (5, 1.0), (6, 1.0), (7, 1.0)],
        [(8, 1.0)]]
    assert (plan.used, plan.samplers) == (4, 4)


def test_own_maps_name_the_files_as_the_folder_export() -> None:
    """The project's maps, numbered and made file-safe, under the folder asked for."""
    project = face([], {}, maps=("brow", "smile lines"))
    assert own_maps(project, "out") == [
        MapSlot("brow", "out/wrinkled_0_brow.png", source="brow"),
        MapSlot("smile lines", "out/wrinkled_1_smile_lines.png", source="smile lines")]


# --- O3DE: a mask per morph target ------------------------------------------------------------


def test_o3de_has_a_mask_per_driving_pose_a_channel_per_wrinkle_layer() -> None:
    """A .tif per driving pose beside the model, each area's gain in its map's channel."""
    project = face(["forehead", "smile L", "smile R", "mole"], {
        "browInnerUp": {"forehead": 1.0, "smile L": 0.25},
        "jawOpen": {"mole": 0.0},
        "mouthSmile_L": {"smile L": 0.75, "ghost": 1.0}})
    for i in (1, 2):
        project.influence.areas[i].wrinkle_map = "smile lines"
    plan = plan_export(project, "o3de")
    layers = ["wrinkleLayers.normalMap1", "wrinkleLayers.normalMap2",
              "wrinkleLayers.normalMap3", "wrinkleLayers.normalMap4"]

    def channels(*filled: list[tuple[int, float]]) -> list[Channel]:
        return [Channel(c, layers[k], map_slot=k,
                        sources=filled[k] if k < len(filled) else [])
                for k, c in enumerate("RGBA")]

    assert plan.masks == [
        MaskTexture("browInnerUp", "face_wrinklemasks/browInnerUp_wrinklemask.tif",
                    channels([(0, 1.0)], [(1, 0.25)])),
        MaskTexture("mouthSmile_L", "face_wrinklemasks/mouthSmile_L_wrinklemask.tif",
                    channels([], [(1, 0.75)]))]
    assert plan.maps == [
        MapSlot(layers[0], "maps/wrinkled_0_brow.png", source="brow"),
        MapSlot(layers[1], "maps/wrinkled_1_smile_lines.png", source="smile lines")]
    why = "no pose drives it, and O3DE masks belong to morph targets"
    assert plan.unassigned == [("smile R", why), ("mole", why)]
    assert (plan.used, plan.samplers) == (2, 4)


# --- Source: flexes ---------------------------------------------------------------------------


def test_source_has_a_flex_per_driving_pose_and_one_compress_map() -> None:
    """A flex per driving pose; $bumpcompress of the driven areas, $bumpstretch neutral."""
    project = face(["mole", "frown", "smile", "dimple"], {
        "smile": {"smile": 0.5, "ghost": 1.0, "frown": 0.0},
        "frown": {"frown": 1.0, "mole": -1.0},
        "dimple": {"ghost": 1.0}})
    plan = plan_export(project, "source")
    assert plan.flexes == [Flex("smile", [(2, 0.5)]), Flex("frown", [(1, 1.0)])]
    assert plan.maps == [MapSlot("bumpcompress", "maps/bumpcompress.png", areas=[1, 2]),
                         MapSlot("bumpstretch", "maps/bumpstretch.png")]
    why = "no pose drives it, and Source wrinkles belong to flexes"
    assert plan.unassigned == [("mole", why), ("dimple", why)]
    assert (plan.masks, plan.used, plan.samplers) == ([], 2, 4)
    assert plan.layout is SOURCE


# --- MetaHuman and Character Creator: region tables -------------------------------------------


def test_metahuman_plan_has_every_mask_texture_and_counts_13_samplers() -> None:
    """Even an empty face plans the 10 masks (every channel of the table) and 3 maps."""
    plan = plan_export(face([], {}), "metahuman")
    assert [(m.name, m.file) for m in plan.masks] == [
        (t, f"masks/{t}.png") for t in METAHUMAN.textures]
    assert [len(m.channels) for m in plan.masks] == [4, 4, 4, 3, 4, 4, 2, 4, 4, 4]
    first = plan.masks[0].channels
    assert first == [Channel("R", "head_wm1_blink_L", "left", 0),
                     Channel("G", "head_wm1_blink_R", "right", 0),
                     Channel("B", "head_wm1_browsRaiseInner_L", "left", 0),
                     Channel("A", "head_wm1_browsRaiseInner_R", "right", 0)]
    assert plan.maps == [MapSlot(m, f"maps/{m}.png") for m in METAHUMAN.maps]
    assert (plan.used, plan.samplers, plan.unassigned, plan.flexes) == (13, 13, [], [])


def test_metahuman_areas_go_to_the_regions_of_their_strongest_pose() -> None:
    """The strongest pose picks the pair; the side is the name's, else the pose's, else both."""
    project = face(["brow knot", "cheek left", "frown line", "pucker"], {
        "browDown_L": {"brow knot": 1.0},
        "browInnerUp": {"cheek left": 1.0},
        "jawOpen": {"frown line": 0.3},
        "browDown_R": {"frown line": 0.9},
        "mouthPucker": {"pucker": 1.0}})
    plan = plan_export(project, "metahuman")
    assert regions_of(plan, project) == {
        "brow knot": ["head_wm2_browsLateral_L"],  # the side of its pose
        "cheek left": ["head_wm1_browsRaiseInner_L"],  # its name's side, on a middle pose
        "frown line": ["head_wm2_browsLateral_R"],  # browDown_R is stronger than jawOpen
        "pucker": ["head_wm1_purse_DL", "head_wm1_purse_DR"],  # both sides of the pair
    }
    got = sources(plan)
    assert got[("T_head_wm2_msk_01", "R")] == [(0, 1.0)]
    assert got[("T_head_wm1_msk_03", "G")] == got[("T_head_wm1_msk_03", "B")] == [(3, 1.0)]
    # each wrinkle map slot lists the areas whose channels reveal it, sorted
    assert [m.areas for m in plan.maps] == [[1, 3], [0, 2], []]
    assert plan.unassigned == []


def test_metahuman_ranks_an_areas_poses_by_gain() -> None:
    """The strongest link (not the first, nor the first by name) decides region and side."""
    project = face(["lip knot", "crease"], {
        "browDown_L": {"lip knot": 0.3},
        "mouthPucker": {"lip knot": 0.9},
        "browInnerUp": {"crease": 0.3},
        "mouthSmile_R": {"crease": 0.9}})
    plan = plan_export(project, "metahuman")
    assert regions_of(plan, project) == {
        "lip knot": ["head_wm1_purse_DL", "head_wm1_purse_DR"],
        "crease": ["head_wm3_smile_R"]}


def test_metahuman_second_areas_take_the_next_free_pair() -> None:
    """Later areas of a pose take the next free pair, else share the first."""
    project = face(["pucker 1", "pucker 2", "pucker 3", "brow L", "brow R"], {
        "mouthPucker": {"pucker 1": 1.0, "pucker 2": 1.0, "pucker 3": 1.0},
        "browDown_L": {"brow L": 1.0},
        "browDown_R": {"brow R": 1.0}})
    plan = plan_export(project, "metahuman")
    assert regions_of(plan, project) == {
        "pucker 1": ["head_wm1_purse_DL", "head_wm1_purse_DR"],
        "pucker 2": ["head_wm1_purse_UL", "head_wm1_purse_UR"],
        "pucker 3": ["head_wm1_purse_DL", "head_wm1_purse_DR"],
        "brow L": ["head_wm2_browsLateral_L"],
        "brow R": ["head_wm2_browsLateral_R"]}


def test_metahuman_falls_back_to_the_face_region_word() -> None:
    """No region for the shape: the pose's face-region word, else the name's, else reported."""
    project = face(["puff", "left cheek crease", "tongue tip", "mole", "cheek fold"], {
        "cheekPuff": {"puff": 1.0},
        "smirk": {"left cheek crease": 1.0},
        "tongueOut": {"tongue tip": 1.0},
        "smirk_R": {"cheek fold": 1.0}})
    plan = plan_export(project, "metahuman")
    got = regions_of(plan, project)
    assert got["puff"] == ["head_wm3_cheekRaiseInner_L", "head_wm3_cheekRaiseInner_R"]
    assert got["left cheek crease"] == ["head_wm3_cheekRaiseOuter_L"]  # Inner_L is taken
    assert got["cheek fold"] == ["head_wm3_cheekRaiseOuter_R"]  # the side of its pose's name
    why = "none of its poses, nor its name, names a region of the metahuman layout"
    assert plan.unassigned == [("tongue tip", why), ("mole", why)]
    assert got["tongue tip"] == got["mole"] == []


def test_cc_shares_each_channel_between_the_sides() -> None:
    """On CC a right area joins a channel holding a left one; a second left area moves on."""
    project = face(["brow L", "brow R", "brow L2", "brow mid", "blink"], {
        "browDown_L": {"brow L": 1.0, "brow L2": 1.0},
        "browDown_R": {"brow R": 1.0},
        "browInnerUp": {"brow mid": 1.0},
        "eyeBlink_R": {"blink": 0.5}})
    plan = plan_export(project, "cc")
    wm2 = "head_wm2_normal_head_wm2_"
    assert regions_of(plan, project) == {
        "brow L": [wm2 + "browsDown"], "brow R": [wm2 + "browsDown"],
        "brow L2": [wm2 + "browsLateral"],
        "brow mid": ["head_wm1_normal_head_wm1_browRaiseInner"],
        "blink": ["head_wm1_normal_head_wm1_blink"]}
    assert sources(plan)[("_WrinkleMaskSet2", "R")] == [(0, 1.0), (1, 1.0)]
    assert [(m.name, m.file) for m in plan.masks] == [(t, f"masks/{t}.png") for t in CC.textures]
    assert all(c.side is None for m in plan.masks for c in m.channels)
    assert [m.areas for m in plan.maps] == [[3, 4], [0, 1, 2], []]
    assert (plan.used, plan.samplers) == (8, 8)


def test_cc_a_middle_area_does_not_join_a_used_channel() -> None:
    """A middle area finds browsDown taken (by any side) and moves on to browsLateral."""
    project = face(["brow L", "frown"], {"browDown_L": {"brow L": 1.0},
                                         "browDown": {"frown": 1.0}})
    # "browDown" names no ARKit shape: the brow word matches the first free brow region
    plan = plan_export(project, "cc")
    got = regions_of(plan, project)
    assert got["brow L"] == ["head_wm2_normal_head_wm2_browsDown"]
    assert got["frown"] == ["head_wm1_normal_head_wm1_browRaiseInner"]


# --- the export: files, pixels, the sheet -----------------------------------------------------

# 4 x 4 masks with distinct texels (rows top to bottom)
M1 = np.array([[0.0, 0.25, 0.5, 0.75], [1.0, 0.5, 0.25, 0.0],
               [0.2, 0.4, 0.6, 0.8], [0.9, 0.7, 0.3, 0.1]], np.float32)
M2 = np.array([[0.5, 0.5, 0.0, 0.0], [0.25, 0.75, 1.0, 0.6],
               [0.0, 0.0, 0.6, 0.6], [0.3, 0.2, 0.1, 0.05]], np.float32)


def eight_bit(values: np.ndarray) -> np.ndarray:
    """Unit values as an 8-bit mask channel stores them."""
    return np.round(np.clip(values, 0, 1) * 255).astype(np.uint8)


def pixels(path: Path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image)


def glb_extras(path: Path) -> dict:
    """The studio's extras in a .glb's JSON chunk."""
    data = path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20:20 + length])["extras"]["wrinkleStudio"]


def test_channel_values_add_the_gained_masks_and_clamp() -> None:
    """0.5·M1 + M2, clamped to [0, 1]; no sources: zeros of the masks' size."""
    project = face([InfluenceArea("a", M1), InfluenceArea("b", M2)], {})
    got = channel_values(project, [(0, 0.5), (1, 1.0)])
    assert got.dtype == np.float32
    np.testing.assert_allclose(got, np.clip(0.5 * M1 + M2, 0, 1), atol=1e-7)
    assert got.max() == 1.0
    assert np.array_equal(channel_values(project, []), np.zeros((4, 4), np.float32))


def test_mask_texture_fills_each_named_channel() -> None:
    """RGBA uint8 of the masks' size (no areas: the neutral's), each channel its areas' sum."""
    project = face([InfluenceArea("a", M1), InfluenceArea("b", M2)], {})
    texture = MaskTexture("t", "t.png", [Channel("B", sources=[(0, 1.0), (1, 1.0)]),
                                         Channel("A", sources=[(1, 1.0)])])
    rgba = mask_texture(project, texture)
    assert rgba.shape == (4, 4, 4) and rgba.dtype == np.uint8
    assert np.array_equal(rgba[:, :, 2], eight_bit(M1 + M2))
    assert np.array_equal(rgba[:, :, 3], eight_bit(M2))
    assert not rgba[:, :, :2].any()
    empty = mask_texture(face([], {}), MaskTexture("t", "t.png", [Channel("R")]))
    assert empty.shape == (6, 6, 4) and not empty.any()


def test_vertex_values_take_the_texel_under_each_uv() -> None:
    """Row from v (row 0 at v = 1), column from u, both clamped into the image."""
    project = face([], {}, uvs=((0, 0), (1, 1), (0.99, 0.01), (-0.5, 1.5)))
    values = np.arange(16, dtype=np.float32).reshape(4, 4)
    assert vertex_values(project, values).tolist() == [12.0, 3.0, 15.0, 0.0]


def maps_face() -> Project:
    """Two 4 x 6 masks over three maps of mixed size and depth: brow 8 x 12 16-bit, smile and
    folds 4 x 6 8-bit; the neutral map 4 x 6."""
    left = np.zeros((4, 6), np.float32)
    left[:3, :3], left[:3, 3:] = 0.8, 0.1
    right = np.zeros((4, 6), np.float32)
    right[:3, :3], right[:3, 3:] = 0.2, 0.9
    project = face([InfluenceArea("brow", left, wrinkle_map="brow"),
                    InfluenceArea("smile", right, wrinkle_map="smile"),
                    InfluenceArea("folds", left, wrinkle_map="folds")], {})
    brow = (1000 + np.arange(8 * 12 * 3, dtype=np.uint16)).reshape(8, 12, 3)
    smile = (np.arange(4 * 6 * 3) % 200).astype(np.uint8).reshape(4, 6, 3)
    folds = np.full((4, 6, 3), (200, 100, 50), np.uint8)
    neutral = np.full((4, 6, 3), (128, 128, 255), np.uint8)
    project.textures = FaceTextures(neutral, neutral, wrinkle_maps={
        "brow": brow, "smile": smile, "folds": folds})
    return project


def test_a_map_slot_of_several_maps_takes_each_texel_from_the_strongest_area() -> None:
    """Each texel from the strongest area's map (neutral where none), at the largest size."""
    project = maps_face()
    got = map_image(project, MapSlot("wm", "wm.png", areas=[0, 1]))
    textures = project.textures
    up = {name: np.repeat(np.repeat(image, 2, axis=0), 2, axis=1).astype(np.uint16) * 257
          for name, image in (("smile", textures.wrinkle_maps["smile"]),
                              ("neutral", textures.normal_neutral))}
    want = np.empty((8, 12, 3), np.uint16)
    want[:, :6] = textures.wrinkle_maps["brow"][:, :6]
    want[:, 6:] = up["smile"][:, 6:]
    want[6:] = up["neutral"][6:]
    assert got.dtype == np.uint16 and np.array_equal(got, want)


def test_a_map_slot_of_eight_bit_maps_stays_eight_bit() -> None:
    """folds on the left, smile on the right, neutral in the last row, at the maps' size."""
    project = maps_face()
    got = map_image(project, MapSlot("wm", "wm.png", areas=[1, 2]))
    textures = project.textures
    want = textures.wrinkle_maps["smile"].copy()
    want[:, :3] = textures.wrinkle_maps["folds"][:, :3]
    want[3] = textures.normal_neutral[3]
    assert got.dtype == np.uint8 and np.array_equal(got, want)


def test_a_map_slot_of_one_map_or_none() -> None:
    """A project map as it is; the areas of one map give that map; no areas, the neutral."""
    project = maps_face()
    maps = project.textures.wrinkle_maps
    assert map_image(project, MapSlot("x", "x.png", source="folds")) is maps["folds"]
    assert map_image(project, MapSlot("x", "x.png", areas=[1])) is maps["smile"]
    assert map_image(project, MapSlot("x", "x.png", areas=[0])) is maps["brow"]
    assert map_image(project, MapSlot("x", "x.png")) is project.textures.normal_neutral


def mh_face() -> Project:
    """Three pucker areas (the third shares purse_D with the first) and a left brow area on the
    second map."""
    return face([InfluenceArea("pucker 1", M1), InfluenceArea("pucker 2", M2),
                 InfluenceArea("pucker 3", M2),
                 InfluenceArea("brow L", M1, wrinkle_map="smile lines")],
                {"mouthPucker": {"pucker 1": 1.0, "pucker 2": 1.0, "pucker 3": 1.0},
                 "browDown_L": {"brow L": 1.0}})


def test_metahuman_export_writes_each_texture_channel_and_map(tmp_path: Path) -> None:
    """Model, masks, maps and sheet in order; each channel its areas' sum, each slot its map."""
    project = mh_face()
    out = tmp_path / "new" / "mh"
    plan, files = export_layout(project, out, "metahuman", tangent_frame="thesis")
    assert files == [out / "face.glb", *(out / "masks" / f"{t}.png" for t in METAHUMAN.textures),
                     *(out / "maps" / f"{m}.png" for m in METAHUMAN.maps), out / SHEET]
    assert glb_extras(out / "face.glb")["tangent_frame"] == "thesis"
    msk3 = pixels(out / "masks" / "T_head_wm1_msk_03.png")
    assert msk3.shape == (4, 4, 4)
    assert np.array_equal(msk3[:, :, 1], eight_bit(M1 + M2))  # purse_DL: pucker 1 + 3
    assert np.array_equal(msk3[:, :, 2], eight_bit(M1 + M2))  # purse_DR
    assert np.array_equal(msk3[:, :, 3], eight_bit(M2))  # purse_UL: pucker 2
    assert not msk3[:, :, 0].any()  # jawOpen
    brows = pixels(out / "masks" / "T_head_wm2_msk_01.png")
    assert np.array_equal(brows[:, :, 0], eight_bit(M1)) and not brows[:, :, 1:].any()
    textures = project.textures
    wm = [pixels(out / "maps" / f"{m}.png") for m in METAHUMAN.maps]
    assert np.array_equal(wm[0], textures.wrinkle_maps["brow"])
    assert np.array_equal(wm[1], textures.wrinkle_maps["smile lines"])
    assert np.array_equal(wm[2], textures.normal_neutral)
    sheet = json.loads((out / SHEET).read_text())
    assert sheet == layout_sheet(project, plan)


def test_a_udim_face_gets_each_texture_per_skin_tile_too(tmp_path: Path) -> None:
    """Every mask and map also comes as NAME.1001.png, the skin tile's cell of the atlas."""
    project = mh_face()
    layout = plan_layout([1001, 1002], skin_tiles=[1001])
    project.uv_tiles = UvTiles(layout, np.zeros(4, np.int16))
    _, files = export_layout(project, tmp_path, "metahuman")
    atlas = tmp_path / "masks" / "T_head_wm1_msk_03.png"
    tile = tmp_path / "masks" / "T_head_wm1_msk_03.1001.png"
    assert files[files.index(atlas) + 1] == tile
    assert np.array_equal(pixels(tile), layout.crop(pixels(atlas), 1001))
    assert pixels(tile).shape[:2] == (2, 2)
    wm1 = tmp_path / "maps" / "head_wm1_normal.png"
    assert files[files.index(wm1) + 1] == wm1.with_name("head_wm1_normal.1001.png")
    sheet = json.loads((tmp_path / SHEET).read_text())
    assert sheet["uv_tiles"]["skin_tiles"] == [1001]
    assert sheet["uv_tiles"]["tiles"] == [1001, 1002]


def test_an_engine_export_never_writes_over_an_input(tmp_path: Path) -> None:
    """A destination that is one of the inputs is refused by name, before anything is written."""
    target = tmp_path / "maps" / "head_wm2_normal.png"
    target.parent.mkdir()
    target.write_bytes(b"input")
    with pytest.raises(StudioError, match="the export file would overwrite the input file"):
        export_layout(mh_face(), tmp_path, "metahuman", inputs=[None, target])
    assert target.read_bytes() == b"input"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["maps"]


def test_source_export_writes_the_flex_table_and_colour_maps(tmp_path: Path) -> None:
    """Source writes the bump maps, the diffuse as colour maps and the per-vertex flex table."""
    project = face([InfluenceArea("a", M1), InfluenceArea("b", M2)],
                   {"smile,wide": {"a": 1.0}, "frown": {"a": 0.5, "b": 1.0}})
    plan, files = export_layout(project, tmp_path, "source")
    maps = tmp_path / "maps"
    assert files == [tmp_path / "face.glb", maps / "bumpcompress.png", maps / "bumpstretch.png",
                     maps / "compress.png", maps / "stretch.png", tmp_path / "flex_wrinkles.csv",
                     tmp_path / SHEET]
    for name in ("compress", "stretch"):
        assert np.array_equal(pixels(maps / f"{name}.png"), project.textures.diffuse)
    assert np.array_equal(pixels(maps / "bumpcompress.png"), project.textures.wrinkle_maps["brow"])
    assert np.array_equal(pixels(maps / "bumpstretch.png"), project.textures.normal_neutral)
    # the UVs (0, 0), (1, 0), (1, 1), (0, 1): texels (3, 0), (3, 3), (0, 3), (0, 0)
    table = (tmp_path / "flex_wrinkles.csv").read_text()
    assert table == ("vertex,smile_wide,frown\n"
                     "0,0.9000,0.7500\n"  # M1 0.9, 0.5·0.9 + 0.3
                     "1,0.1000,0.1000\n"  # M1 0.1, 0.5·0.1 + 0.05
                     "2,0.7500,0.3750\n"  # M1 0.75, 0.5·0.75 + 0
                     "3,0.0000,0.5000\n")  # M1 0, 0.5·0 + 0.5
    assert table == flex_table(project, plan)


def test_the_sheet_of_a_per_pose_layout(tmp_path: Path) -> None:
    """The whole sheet of an O3DE export, indented, with each non-linear curve of an area."""
    project = face(["forehead", "smile L", "mole"], {
        "browInnerUp": {"forehead": 1.0, "smile L": 0.25},
        "mouthSmile_L": {"smile L": 0.75}})
    project.influence.areas[1].wrinkle_map = "smile lines"
    project.influence.curves = {"browInnerUp": {"forehead": ResponseCurve("ease_in"),
                                                "smile L": ResponseCurve("linear")},
                                "mouthSmile_L": {"smile L": ResponseCurve("ease_out")}}
    export_layout(project, tmp_path, "o3de")
    layers = list(O3DE.maps)
    assert (tmp_path / SHEET).read_text().startswith('{\n  "layout": "o3de",\n  "engine": ')

    def channel(k: int, areas: list[dict]) -> dict:
        return {"region": layers[k], "side": None, "wrinkle_map": layers[k], "areas": areas}

    forehead = {"area": "forehead", "gain": 1.0, "poses": ["browInnerUp"],
                "response": {"browInnerUp": {"kind": "ease_in"}}}
    smile = {"area": "smile L", "gain": 0.25, "poses": ["browInnerUp", "mouthSmile_L"],
             "response": {"mouthSmile_L": {"kind": "ease_out"}}}
    why = "no pose drives it, and O3DE masks belong to morph targets"
    assert json.loads((tmp_path / SHEET).read_text()) == {
        "layout": "o3de", "engine": O3DE.label, "doc": "docs/engines/o3de.md",
        "samplers": 4,
        "limit": {"used": 2, "most": 16, "counts": "wrinkle masks", "why": O3DE.limit_why},
        "model": "face.glb",
        "mask_textures": [
            {"texture": "browInnerUp", "file": "face_wrinklemasks/browInnerUp_wrinklemask.tif",
             "channels": {"R": channel(0, [forehead]), "G": channel(1, [smile]),
                          "B": channel(2, []), "A": channel(3, [])}},
            {"texture": "mouthSmile_L", "file": "face_wrinklemasks/mouthSmile_L_wrinklemask.tif",
             "channels": {"R": channel(0, []), "G": channel(1, [{**smile, "gain": 0.75}]),
                          "B": channel(2, []), "A": channel(3, [])}}],
        "wrinkle_maps": [
            {"name": layers[0], "file": "maps/wrinkled_0_brow.png", "project_map": "brow",
             "areas": []},
            {"name": layers[1], "file": "maps/wrinkled_1_smile_lines.png",
             "project_map": "smile lines", "areas": []}],
        "areas": [
            {"area": "forehead",
             "channels": [{"texture": "browInnerUp", "channel": "R", "region": layers[0]}]},
            {"area": "smile L",
             "channels": [{"texture": "browInnerUp", "channel": "G", "region": layers[1]},
                          {"texture": "mouthSmile_L", "channel": "G", "region": layers[1]}]},
            {"area": "mole", "channels": []}],
        "flexes": [],
        "unassigned": [{"area": "mole", "why": why}]}


def test_the_sheet_of_flexes_and_of_the_studios_own_maps() -> None:
    """Flexes are compress at scale 1; the studio's channels name the project's maps."""
    project = face(["a", "b"], {"frown": {"b": 0.5}})
    project.influence.areas[1].wrinkle_map = "smile lines"
    sheet = layout_sheet(project, plan_export(project, "source"))
    assert sheet["flexes"] == [{"flex": "frown", "wrinkle_scale": 1.0, "wrinkle": "compress",
                                "areas": [{"area": "b", "gain": 0.5, "poses": ["frown"]}],
                                "table": "flex_wrinkles.csv"}]
    assert sheet["wrinkle_maps"][0]["areas"] == ["b"]
    studio = layout_sheet(project, plan_export(project, "studio"))
    channels = studio["mask_textures"][0]["channels"]
    assert [c["wrinkle_map"] for c in channels.values()] == ["brow", "smile lines"]
    assert channels["R"]["areas"] == [{"area": "a", "gain": 1.0, "poses": []}]
    bare = Plan(STUDIO, [MaskTexture("t", "t.png", [Channel("R")])], [], [], 1, 1)
    assert layout_sheet(project, bare)["mask_textures"][0]["channels"]["R"]["wrinkle_map"] is None


def test_the_studio_layout_is_the_folder_export_plus_the_sheet(tmp_path: Path) -> None:
    """studio: export_folder's files (at the bits and tangent frame asked for), then the sheet."""
    project = face([InfluenceArea("a", M1)], {"frown": {"a": 1.0}})
    _, files = export_layout(project, tmp_path, "studio", bits=8, tangent_frame="thesis")
    names = [p.relative_to(tmp_path).as_posix() for p in files]
    assert names[0] == "face.glb" and names[-1] == SHEET
    assert "wrinkles.json" in names and "masks/00_a.png" in names
    assert np.array_equal(pixels(tmp_path / "masks" / "00_a.png"), eight_bit(M1))
    assert glb_extras(tmp_path / "face.glb")["tangent_frame"] == "thesis"
    assert json.loads((tmp_path / SHEET).read_text())["layout"] == "studio"
    export_layout(project, tmp_path / "deep", "studio")  # 16 bits unless asked
    deep = pixels(tmp_path / "deep" / "masks" / "00_a.png")
    assert np.array_equal(deep, np.round(M1 * 65535).astype(np.uint16))


def test_source_refuses_an_input_among_its_colour_maps(tmp_path: Path) -> None:
    """Source's colour maps are destinations checked against the inputs; other layouts' not."""
    project = face([InfluenceArea("a", M1)], {"frown": {"a": 1.0}})
    source = tmp_path / "maps" / "compress.png"
    source.parent.mkdir()
    source.write_bytes(b"input")
    for colour in ("compress", "stretch"):
        with pytest.raises(StudioError, match="overwrite the input"):
            export_layout(project, tmp_path, "source", inputs=[tmp_path / "maps" / f"{colour}.png"])
    assert source.read_bytes() == b"input"
    export_layout(project, tmp_path, "metahuman", inputs=[source])
    assert source.read_bytes() == b"input"


def test_a_udim_o3de_export_writes_tiff_tile_copies(tmp_path: Path) -> None:
    """A morph target's tile copy is a TIFF like its atlas."""
    project = face([InfluenceArea("a", M1)], {"frown": {"a": 1.0}})
    project.uv_tiles = UvTiles(plan_layout([1001, 1002], skin_tiles=[1001]), np.zeros(4))
    _, files = export_layout(project, tmp_path, "o3de")
    tile = tmp_path / "face_wrinklemasks" / "frown_wrinklemask.1001.tif"
    assert tile in files
    with Image.open(tile) as image:
        assert image.format == "TIFF"
