"""The engine layout tables against the engines' pages in docs/engines/: MetaHuman's region
names, mask textures, channels, wrinkle maps and driving ARKit shapes; Character Creator's five
mask sets; the textures, maps and limits each page states.

The region tables are built afresh by their builders in each test (``layouts._metahuman()``,
``layouts._cc()``): the published tables are made once, at import.
"""

from __future__ import annotations

import dataclasses

import pytest

from studio.core.animation import pose_names
from studio.core.engines import layouts
from studio.core.engines.layouts import (
    CC,
    CHANNELS,
    LAYOUTS,
    LEFT,
    METAHUMAN,
    O3DE,
    RIGHT,
    SOURCE,
    STUDIO,
    EngineLayout,
    Region,
)

pytestmark = pytest.mark.core

# docs/engines/metahuman.md, "Assignment": the ARKit shape ("*": its Left and Right shapes) →
# the regions it drives, in the order the doc gives them ("browsLateral then browsDown").
# The doc's list leaves out browOuterUp; its wm1 count of 15 regions needs browsRaiseOuter,
# which the outer brow raise drives.
DOC_ASSIGNMENT: dict[str, tuple[str, ...]] = {
    "eyeBlink*": ("blink",),
    "browInnerUp": ("browsRaiseInner",),
    "browOuterUp*": ("browsRaiseOuter",),
    "mouthShrugLower": ("chinRaise",),
    "jawOpen": ("jawOpen",),
    "mouthPucker": ("purse_D", "purse_U"),  # mouthPucker/mouthRoll* → purse: lower and upper
    "mouthRollLower": ("purse_D",),
    "mouthRollUpper": ("purse_U",),
    "eyeSquint*": ("squintInner", "cheekRaiseOuter"),
    "browDown*": ("browsLateral", "browsDown"),
    "mouthStretch*": ("mouthStretch",),
    "mouthFrown*": ("neckStretch",),
    "noseSneer*": ("noseWrinkler",),
    "cheekSquint*": ("cheekRaiseInner", "cheekRaiseUpper"),
    "mouthSmile*": ("smile",),
    "mouthFunnel": ("lips_D", "lips_U"),
}

# the part of the face each region lies on: the pose_names.REGIONS word an area of no known
# ARKit shape is matched by ("else by its pose's or name's face-region word")
REGION_PART = {
    "blink": "eye", "browsRaiseInner": "brow", "browsRaiseOuter": "brow", "chinRaise": "mouth",
    "jawOpen": "jaw", "purse_D": "mouth", "purse_U": "mouth", "squintInner": "eye",
    "browsLateral": "brow", "browsDown": "brow", "mouthStretch": "mouth", "neckStretch": "jaw",
    "noseWrinkler": "nose", "cheekRaiseInner": "cheek", "cheekRaiseOuter": "cheek",
    "cheekRaiseUpper": "cheek", "smile": "mouth", "lips_D": "mouth", "lips_U": "mouth",
}

# "wm1: 15, wm2: 10, wm3: 8, wm13: 4": every region of each map, as the doc names them
METAHUMAN_MAPS = {
    "wm1": ["blink_L", "blink_R", "browsRaiseInner_L", "browsRaiseInner_R", "browsRaiseOuter_L",
            "browsRaiseOuter_R", "chinRaise_L", "chinRaise_R", "jawOpen", "purse_DL", "purse_DR",
            "purse_UL", "purse_UR", "squintInner_L", "squintInner_R"],
    "wm2": ["browsDown_L", "browsDown_R", "browsLateral_L", "browsLateral_R", "mouthStretch_L",
            "mouthStretch_R", "neckStretch_L", "neckStretch_R", "noseWrinkler_L",
            "noseWrinkler_R"],
    "wm3": ["cheekRaiseInner_L", "cheekRaiseInner_R", "cheekRaiseOuter_L", "cheekRaiseOuter_R",
            "cheekRaiseUpper_L", "cheekRaiseUpper_R", "smile_L", "smile_R"],
    "wm13": ["lips_DL", "lips_DR", "lips_UL", "lips_UR"],
}
# the normal map each mask group reveals (wm13's lips: wm1, as CC's Set123 lips)
MAP_OF_GROUP = {"wm1": 0, "wm2": 1, "wm3": 2, "wm13": 0}


def metahuman_regions() -> tuple[Region, ...]:
    """MetaHuman's region table, built afresh (the one METAHUMAN publishes)."""
    return layouts._metahuman()


def cc_regions() -> tuple[Region, ...]:
    """Character Creator's region table, built afresh (the one CC publishes)."""
    return layouts._cc()


def spelled(shape: str, side: str) -> str:
    """A doc shape in ARKit's spelling for one side ("eyeBlink*", "Left" → "eyeBlinkLeft")."""
    return shape.replace("*", side)


def mh_stem(region: Region) -> str:
    """The region's doc name: its pair without the ``head_wmN_`` prefix (``purse_D``)."""
    return region.pair.split("_", 2)[2]


def mh_group(region: Region) -> str:
    """The mask group of a region (``wm1``, ``wm13``): the texture names it."""
    return region.name.split("_")[1]


# --- MetaHuman ------------------------------------------------------------------------------


def test_metahuman_regions_are_the_docs_per_map() -> None:
    """Each wrinkle-map group holds exactly the regions the doc counts (15, 10, 8, 4)."""
    regions = metahuman_regions()
    by_group: dict[str, list[str]] = {}
    for r in regions:
        by_group.setdefault(mh_group(r), []).append(r.name)
    assert {g: sorted(names) for g, names in by_group.items()} == {
        g: sorted(f"head_{g}_{n}" for n in names) for g, names in METAHUMAN_MAPS.items()}
    assert [len(v) for v in by_group.values()] == [15, 10, 8, 4]
    assert len({r.name for r in regions}) == len(regions) == 37


def test_metahuman_textures_are_the_anim_masks() -> None:
    """The masks are T_head_wmN_msk_0K: wm1 01..04, wm2 01..03, wm3 01..02, wm13 01, in order."""
    layout = dataclasses.replace(METAHUMAN, regions=metahuman_regions())
    assert layout.textures == (
        "T_head_wm1_msk_01", "T_head_wm1_msk_02", "T_head_wm1_msk_03", "T_head_wm1_msk_04",
        "T_head_wm2_msk_01", "T_head_wm2_msk_02", "T_head_wm2_msk_03",
        "T_head_wm3_msk_01", "T_head_wm3_msk_02", "T_head_wm13_msk_01")
    # 13 samplers: 10 masks + 3 maps, under Unreal's 16
    assert len(layout.textures) + len(layout.maps) == 13 <= METAHUMAN.limit == 16
    assert layout.maps == ("head_wm1_normal", "head_wm2_normal", "head_wm3_normal")


def test_metahuman_regions_fill_the_textures_four_at_a_time_alphabetically() -> None:
    """Per map, the k-th region in alphabetical order is in msk_(k//4 + 1), channel k % 4."""
    regions = metahuman_regions()
    for group in METAHUMAN_MAPS:
        ordered = sorted((r for r in regions if mh_group(r) == group), key=lambda r: r.name)
        for k, r in enumerate(ordered):
            assert r.texture == f"T_head_{group}_msk_{k // 4 + 1:02d}", r.name
            if r.texture != "T_head_wm2_msk_01":  # see test_metahuman_brows_down_textures
                assert r.channel == CHANNELS[k % 4], r.name


def test_metahuman_brows_down_texture_holds_both_brow_pairs() -> None:
    """T_head_wm2_msk_01 holds browsLateral and browsDown, each pair's L before its R."""
    regions = [r for r in metahuman_regions() if r.texture == "T_head_wm2_msk_01"]
    channels = {r.name.removeprefix("head_wm2_"): r.channel for r in regions}
    assert set(channels) == {"browsDown_L", "browsDown_R", "browsLateral_L", "browsLateral_R"}
    assert sorted(channels.values()) == sorted(CHANNELS)
    for stem in ("browsDown", "browsLateral"):
        left, right = CHANNELS.index(channels[f"{stem}_L"]), CHANNELS.index(channels[f"{stem}_R"])
        assert right == left + 1 and left % 2 == 0


def test_metahuman_each_texture_channel_holds_one_region() -> None:
    """No two regions share a (texture, channel), and every channel is R, G, B or A."""
    regions = metahuman_regions()
    slots = [(r.texture, r.channel) for r in regions]
    assert len(set(slots)) == len(slots)
    assert {r.channel for r in regions} == set(CHANNELS)
    # the ten textures carry 37 regions: wm1_msk_04 leaves A free, wm2_msk_03 B and A
    assert len(slots) == 4 * 10 - 3


def test_metahuman_regions_reveal_their_groups_map() -> None:
    """A region of head_wmN reveals wrinkle map N (wm13's lips: wm1)."""
    for r in metahuman_regions():
        assert r.wrinkle_map == MAP_OF_GROUP[mh_group(r)], r.name


def test_metahuman_regions_are_driven_by_the_documented_arkit_shapes() -> None:
    """Each region's poses are the ARKit shapes the doc's assignment sends to it, sided."""
    for r in metahuman_regions():
        side = {LEFT: "Left", RIGHT: "Right", None: None}[r.side]
        want = tuple(spelled(shape, side) if "*" in shape else shape
                     for shape, stems in DOC_ASSIGNMENT.items() if mh_stem(r) in stems)
        assert r.poses == want, r.name
        assert all(p in pose_names.ARKIT_NAMES for p in r.poses), r.name


def test_metahuman_shapes_drive_regions_in_the_documented_order() -> None:
    """A shape driving several regions finds them in the doc's order ("… then …")."""
    regions = metahuman_regions()
    for shape, stems in DOC_ASSIGNMENT.items():
        for side in ("Left", "Right"):
            name = spelled(shape, side)
            found = [mh_stem(r) for r in regions if name in r.poses]
            assert list(dict.fromkeys(found)) == list(stems), name


def test_metahuman_region_hints_are_the_part_of_the_face() -> None:
    """Each region's fallback word is a face-region word: the part of the face it lies on."""
    for r in metahuman_regions():
        assert r.hint in pose_names.REGIONS
        assert r.hint == REGION_PART[mh_stem(r)], r.name


def test_metahuman_left_and_right_pairs() -> None:
    """_L regions are the left side, _R the right; a pair shares group, map, hint and shapes."""
    regions = metahuman_regions()
    by_name = {r.name: r for r in regions}
    middle = [r for r in regions if r.side is None]
    assert [r.name for r in middle] == ["head_wm1_jawOpen"]
    assert middle[0].group == "" and middle[0].pair == "head_wm1_jawOpen"
    lefts = [r for r in regions if r.side == LEFT]
    assert len(lefts) == len([r for r in regions if r.side == RIGHT]) == 18
    for left in lefts:
        assert left.name in (f"{left.group}_L", f"{left.group}L"), left.name
        right = by_name[left.name[:-1] + "R"]
        assert right.side == RIGHT and right.group == left.group == left.pair == right.pair
        assert (right.wrinkle_map, right.hint) == (left.wrinkle_map, left.hint)
        assert right.poses == tuple(p.replace("Left", "Right") for p in left.poses)
        assert not any("Right" in p for p in left.poses)
        assert not any("Left" in p for p in right.poses)
        # the pair's channels come one after the other, L first (across a texture's end too)
        slot = {r.name: (r.texture, CHANNELS.index(r.channel)) for r in (left, right)}
        (lt, lc), (rt, rc) = slot[left.name], slot[right.name]
        assert (rt, rc) == (lt, lc + 1) or ((lc, rc) == (3, 0) and rt > lt)


def test_sided_writes_a_pair_into_two_channels() -> None:
    """_sided: one region per side, named _L/_R, poses formatted with Left/Right."""
    left, right = layouts._sided("head_wm9_test", "T_x", "BA", 2, ("eyeBlink{side}",
                                                                    "browInnerUp"), "eye")
    assert left == Region("head_wm9_test_L", "T_x", "B", 2, ("eyeBlinkLeft", "browInnerUp"),
                          "eye", LEFT, "head_wm9_test")
    assert right == Region("head_wm9_test_R", "T_x", "A", 2, ("eyeBlinkRight", "browInnerUp"),
                           "eye", RIGHT, "head_wm9_test")


# --- Character Creator ------------------------------------------------------------------------

# docs/engines/cc.md, "Layout": set → channel → (region, map)
CC_DOC = {
    "_WrinkleMaskSet1A": {"R": ("blink", 1), "G": ("browRaiseInner", 1), "B": ("purse_D", 1),
                          "A": ("purse_U", 1)},
    "_WrinkleMaskSet1B": {"R": ("browRaiseOuter", 1), "G": ("chinRaise", 1),
                          "B": ("jawOpen", 1), "A": ("squintInner", 1)},
    "_WrinkleMaskSet2": {"R": ("browsDown", 2), "G": ("browsLateral", 2),
                         "B": ("mouthStretch", 2), "A": ("neckStretch", 2)},
    "_WrinkleMaskSet3": {"R": ("cheekRaiseInner", 3), "G": ("cheekRaiseOuter", 3),
                         "B": ("cheekRaiseUpper", 3), "A": ("smile", 3)},
    "_WrinkleMaskSet123": {"R": ("lips_D", 1), "G": ("lips_U", 1), "B": ("noseWrinkler", 2),
                           "A": ("noseCrease", 2)},
}
# "the ARKit → region assignment is ours, as for MetaHuman": CC's brow raise rules are
# MetaHuman's browsRaise regions; noseCrease (no MetaHuman region) follows the upper lip raise
CC_AS_METAHUMAN = {"browRaiseInner": "browsRaiseInner", "browRaiseOuter": "browsRaiseOuter"}
CC_ASSIGNMENT = {**DOC_ASSIGNMENT, "mouthUpperUp*": ("noseCrease",)}
CC_PART = {**REGION_PART, "noseCrease": "nose"}


def test_cc_has_five_rgba_mask_sets_as_documented() -> None:
    """Five mask sets, each R, G, B and A used once, in the doc's order; 8 samplers."""
    regions = cc_regions()
    table = {}
    for r in regions:
        table.setdefault(r.texture, {})[r.channel] = r
    assert list(table) == list(CC_DOC)
    assert all(list(channels) == list(CHANNELS) for channels in table.values())
    assert len(regions) == 20
    layout = dataclasses.replace(CC, regions=regions)
    assert layout.textures == tuple(CC_DOC)
    assert len(layout.textures) + len(layout.maps) == 8 <= CC.limit == 16
    assert layout.maps == ("_WrinkleNormalBlend1", "_WrinkleNormalBlend2", "_WrinkleNormalBlend3")


def test_cc_regions_are_the_rule_names_and_maps_of_the_doc() -> None:
    """Each channel's region is head_wmN_normal_head_wmN_<rule>, revealing map N."""
    for r in cc_regions():
        stem, number = CC_DOC[r.texture][r.channel]
        assert r.name == f"head_wm{number}_normal_head_wm{number}_{stem}"
        assert r.wrinkle_map == number - 1, r.name


def test_cc_channels_serve_both_sides() -> None:
    """No region has a side: one channel holds both sides, driven by both sides' shapes."""
    assert CC.shared_sides and not METAHUMAN.shared_sides
    for r in cc_regions():
        stem = r.name.split("_", 5)[5]
        shapes = [s for s, stems in CC_ASSIGNMENT.items()
                  if CC_AS_METAHUMAN.get(stem, stem) in stems]
        want = {spelled(s, side) for s in shapes for side in ("Left", "Right")}
        assert (r.side, r.group, r.pair) == (None, "", r.name)
        assert set(r.poses) == want, r.name
        assert all(p in pose_names.ARKIT_NAMES for p in r.poses)
        assert r.hint == CC_PART[CC_AS_METAHUMAN.get(stem, stem)], r.name


# --- the other engines, and the list ---------------------------------------------------------


def test_the_other_engines_maps_and_limits_are_their_docs() -> None:
    """O3DE, Source and the studio's maps, mask format and limits are their pages'."""
    assert O3DE.kind == "per_pose" and O3DE.mask_suffix == ".tif"
    assert O3DE.maps == tuple(f"wrinkleLayers.normalMap{k}" for k in (1, 2, 3, 4))
    assert (O3DE.limit, O3DE.limit_unit) == (16, "wrinkle masks")
    assert SOURCE.kind == "vertex" and SOURCE.maps == ("bumpcompress", "bumpstretch")
    assert (SOURCE.limit, SOURCE.limit_unit) == (96, "flex controllers")
    assert "MAXSTUDIOFLEXCTRL" in SOURCE.limit_why
    assert STUDIO.kind == "per_area" and (STUDIO.limit, STUDIO.limit_unit) == (16, "samplers")
    assert (METAHUMAN.kind, CC.kind) == ("regions", "regions")
    assert all(layout.mask_suffix == ".png" for layout in (METAHUMAN, CC, STUDIO))


def test_each_layout_names_its_doc_page() -> None:
    """LAYOUTS lists the five engines by key, each with its docs/engines page."""
    assert list(LAYOUTS) == ["metahuman", "cc", "o3de", "source", "studio"]
    for key, layout in LAYOUTS.items():
        assert isinstance(layout, EngineLayout) and layout.key == key == layout.doc
    assert STUDIO.textures == ()  # no region table: areas are packed in order
