"""The wrinkle layouts game engines' shaders expect, as data: one table per engine.

Why tables: each engine samples its own fixed set of mask textures, reads a fixed region from
each RGBA channel and reveals a fixed wrinkle normal map there. Written down as data, one
planner (core/layout_plan.py) assigns the project's areas to any of them, the export writes any
of them, and the GUI builds its layout list from :data:`LAYOUTS` — no engine is special-cased.

Where each table comes from, and what was assumed where an engine's layout is not public, is on
the engine's page in ``docs/engines/``.
"""

from __future__ import annotations

from dataclasses import dataclass

CHANNELS = "RGBA"
MODEL_FILE = "face.glb"  # the mesh and its morph targets, written beside every layout's textures
LEFT, RIGHT = "left", "right"


@dataclass(frozen=True)
class Region:
    """One channel of an engine's mask texture: the region it holds and what drives it."""

    name: str  # the engine's own name for the region (its material parameter / rig output)
    texture: str  # the mask texture holding it (file stem, as the engine names it)
    channel: str  # R, G, B or A
    wrinkle_map: int  # index into the layout's ``maps``: the normal map the region reveals
    poses: tuple[str, ...]  # ARKit shapes (pose_names.ARKIT_NAMES) that drive the region
    hint: str  # pose_names.REGIONS word: the fallback for poses with no ARKit name
    side: str | None = None  # the character's left or right; None = the middle of the face
    group: str = ""  # the region without its side: a left/right pair shares it

    @property
    def pair(self) -> str:
        return self.group or self.name


@dataclass(frozen=True)
class EngineLayout:
    """How one engine's shader wants the masks and wrinkle maps.

    ``kind`` says how areas become channels: ``regions`` (a fixed region table), ``per_pose``
    (one RGBA mask per morph target, a channel per wrinkle layer: O3DE), ``per_area`` (areas
    four to a texture in order: the studio's own) or ``vertex`` (per-vertex weights per flex and
    one compress map: Source). ``limit`` is the engine's documented ceiling on ``limit_unit``.
    """

    key: str
    label: str
    kind: str
    maps: tuple[str, ...]  # the engine's wrinkle normal map names (file stems), in its order
    limit: int
    limit_unit: str  # what ``limit`` counts: "samplers", "wrinkle masks", "flex controllers"
    limit_why: str  # where the limit comes from, for the refusal message
    regions: tuple[Region, ...] = ()
    shared_sides: bool = False  # one channel serves both sides; the shader splits at u = 0.5
    mask_suffix: str = ".png"
    doc: str = ""  # docs/engines/<doc>.md

    @property
    def textures(self) -> tuple[str, ...]:
        """The mask textures of a region table, in the order they first appear."""
        return tuple(dict.fromkeys(r.texture for r in self.regions))


def _sided(name: str, texture: str, channels: str, wrinkle_map: int, poses: tuple[str, ...],
           hint: str) -> tuple[Region, Region]:
    """A left/right pair in two channels; ``poses`` are spelled with ``{side}`` (Left/Right)
    for sided ARKit shapes, or plain for a shape that moves both sides (browInnerUp)."""
    left, right = channels
    return (Region(f"{name}_L", texture, left, wrinkle_map,
                   tuple(p.format(side="Left") for p in poses), hint, LEFT, name),
            Region(f"{name}_R", texture, right, wrinkle_map,
                   tuple(p.format(side="Right") for p in poses), hint, RIGHT, name))


def _metahuman() -> tuple[Region, ...]:
    """MetaHuman's animated wrinkle-map regions: T_head_wmN_msk_0K textures under
    Common/Face/Textures/Utilities/AnimMasks, channels in the regions' alphabetical order."""
    wm1, wm2, wm3 = 0, 1, 2
    msk = "T_head_{}_msk_{:02d}".format
    squint, smile = ("eyeSquint{side}",), ("mouthSmile{side}",)
    return (
        *_sided("head_wm1_blink", msk("wm1", 1), "RG", wm1, ("eyeBlink{side}",), "eye"),
        *_sided("head_wm1_browsRaiseInner", msk("wm1", 1), "BA", wm1, ("browInnerUp",), "brow"),
        *_sided("head_wm1_browsRaiseOuter", msk("wm1", 2), "RG", wm1, ("browOuterUp{side}",),
                "brow"),
        *_sided("head_wm1_chinRaise", msk("wm1", 2), "BA", wm1, ("mouthShrugLower",), "mouth"),
        Region("head_wm1_jawOpen", msk("wm1", 3), "R", wm1, ("jawOpen",), "jaw"),
        Region("head_wm1_purse_DL", msk("wm1", 3), "G", wm1, ("mouthPucker", "mouthRollLower"),
               "mouth", LEFT, "head_wm1_purse_D"),
        Region("head_wm1_purse_DR", msk("wm1", 3), "B", wm1, ("mouthPucker", "mouthRollLower"),
               "mouth", RIGHT, "head_wm1_purse_D"),
        Region("head_wm1_purse_UL", msk("wm1", 3), "A", wm1, ("mouthPucker", "mouthRollUpper"),
               "mouth", LEFT, "head_wm1_purse_U"),
        Region("head_wm1_purse_UR", msk("wm1", 4), "R", wm1, ("mouthPucker", "mouthRollUpper"),
               "mouth", RIGHT, "head_wm1_purse_U"),
        *_sided("head_wm1_squintInner", msk("wm1", 4), "GB", wm1, squint, "eye"),
        *_sided("head_wm2_browsLateral", msk("wm2", 1), "RG", wm2, ("browDown{side}",), "brow"),
        *_sided("head_wm2_browsDown", msk("wm2", 1), "BA", wm2, ("browDown{side}",), "brow"),
        *_sided("head_wm2_mouthStretch", msk("wm2", 2), "RG", wm2, ("mouthStretch{side}",),
                "mouth"),
        *_sided("head_wm2_neckStretch", msk("wm2", 2), "BA", wm2, ("mouthFrown{side}",), "jaw"),
        *_sided("head_wm2_noseWrinkler", msk("wm2", 3), "RG", wm2, ("noseSneer{side}",), "nose"),
        *_sided("head_wm3_cheekRaiseInner", msk("wm3", 1), "RG", wm3, ("cheekSquint{side}",),
                "cheek"),
        *_sided("head_wm3_cheekRaiseOuter", msk("wm3", 1), "BA", wm3, squint, "cheek"),
        *_sided("head_wm3_cheekRaiseUpper", msk("wm3", 2), "RG", wm3, ("cheekSquint{side}",),
                "cheek"),
        *_sided("head_wm3_smile", msk("wm3", 2), "BA", wm3, smile, "mouth"),
        Region("head_wm13_lips_DL", "T_head_wm13_msk_01", "R", wm1, ("mouthFunnel",), "mouth",
               LEFT, "head_wm13_lips_D"),
        Region("head_wm13_lips_DR", "T_head_wm13_msk_01", "G", wm1, ("mouthFunnel",), "mouth",
               RIGHT, "head_wm13_lips_D"),
        Region("head_wm13_lips_UL", "T_head_wm13_msk_01", "B", wm1, ("mouthFunnel",), "mouth",
               LEFT, "head_wm13_lips_U"),
        Region("head_wm13_lips_UR", "T_head_wm13_msk_01", "A", wm1, ("mouthFunnel",), "mouth",
               RIGHT, "head_wm13_lips_U"),
    )


def _cc() -> tuple[Region, ...]:
    """Reallusion CC3+/CC4 head shader: five RGBA mask sets, each channel shared by both sides
    (the shader weighs left and right by the texel's side of u = 0.5)."""
    wm1, wm2, wm3 = 0, 1, 2
    table = (  # texture, channel, region (the rule name without its side), map, ARKit, hint
        ("_WrinkleMaskSet1A", "R", "blink", wm1, ("eyeBlink{side}",), "eye"),
        ("_WrinkleMaskSet1A", "G", "browRaiseInner", wm1, ("browInnerUp",), "brow"),
        ("_WrinkleMaskSet1A", "B", "purse_D", wm1, ("mouthPucker", "mouthRollLower"), "mouth"),
        ("_WrinkleMaskSet1A", "A", "purse_U", wm1, ("mouthPucker", "mouthRollUpper"), "mouth"),
        ("_WrinkleMaskSet1B", "R", "browRaiseOuter", wm1, ("browOuterUp{side}",), "brow"),
        ("_WrinkleMaskSet1B", "G", "chinRaise", wm1, ("mouthShrugLower",), "mouth"),
        ("_WrinkleMaskSet1B", "B", "jawOpen", wm1, ("jawOpen",), "jaw"),
        ("_WrinkleMaskSet1B", "A", "squintInner", wm1, ("eyeSquint{side}",), "eye"),
        ("_WrinkleMaskSet2", "R", "browsDown", wm2, ("browDown{side}",), "brow"),
        ("_WrinkleMaskSet2", "G", "browsLateral", wm2, ("browDown{side}",), "brow"),
        ("_WrinkleMaskSet2", "B", "mouthStretch", wm2, ("mouthStretch{side}",), "mouth"),
        ("_WrinkleMaskSet2", "A", "neckStretch", wm2, ("mouthFrown{side}",), "jaw"),
        ("_WrinkleMaskSet3", "R", "cheekRaiseInner", wm3, ("cheekSquint{side}",), "cheek"),
        ("_WrinkleMaskSet3", "G", "cheekRaiseOuter", wm3, ("eyeSquint{side}",), "cheek"),
        ("_WrinkleMaskSet3", "B", "cheekRaiseUpper", wm3, ("cheekSquint{side}",), "cheek"),
        ("_WrinkleMaskSet3", "A", "smile", wm3, ("mouthSmile{side}",), "mouth"),
        ("_WrinkleMaskSet123", "R", "lips_D", wm1, ("mouthFunnel",), "mouth"),
        ("_WrinkleMaskSet123", "G", "lips_U", wm1, ("mouthFunnel",), "mouth"),
        ("_WrinkleMaskSet123", "B", "noseWrinkler", wm2, ("noseSneer{side}",), "nose"),
        ("_WrinkleMaskSet123", "A", "noseCrease", wm2, ("mouthUpperUp{side}",), "nose"),
    )
    wm = ("head_wm1_normal_head_wm1", "head_wm2_normal_head_wm2", "head_wm3_normal_head_wm3")
    return tuple(Region(f"{wm[m]}_{name}", texture, channel, m,
                        tuple(p.format(side=s) for s in ("Left", "Right") for p in poses), hint)
                 for texture, channel, name, m, poses, hint in table)


# The studio's own shader samples at least 16 textures in a fragment shader: OpenGL 3.3's and
# Direct3D 11's guaranteed minimum, the target the studio's GLSL is written for.
STUDIO = EngineLayout(
    "studio", "Wrinkle Studio (packed RGBA, one texture per four areas)", "per_area",
    maps=(), limit=16, limit_unit="samplers",
    limit_why="texture units a fragment shader is guaranteed (OpenGL 3.3, Direct3D 11)",
    doc="studio")
METAHUMAN = EngineLayout(
    "metahuman", "Unreal MetaHuman (3 wrinkle maps, 10 region masks)", "regions",
    maps=("head_wm1_normal", "head_wm2_normal", "head_wm3_normal"), limit=16,
    limit_unit="samplers",
    limit_why="texture samplers an Unreal material may use without shared samplers (SM5)",
    regions=_metahuman(), doc="metahuman")
CC = EngineLayout(
    "cc", "Character Creator 4 (3 wrinkle maps, 5 mask sets)", "regions",
    maps=("_WrinkleNormalBlend1", "_WrinkleNormalBlend2", "_WrinkleNormalBlend3"), limit=16,
    limit_unit="samplers",
    limit_why="texture samplers a Unity or Unreal material may use without shared samplers",
    regions=_cc(), shared_sides=True, doc="cc")
# O3DE: AtomActorInstance's s_maxActiveWrinkleMasks; the Skin material has 4 wrinkle layers
O3DE = EngineLayout(
    "o3de", "O3DE Skin material (a mask per morph target, 4 wrinkle layers)", "per_pose",
    maps=("wrinkleLayers.normalMap1", "wrinkleLayers.normalMap2", "wrinkleLayers.normalMap3",
          "wrinkleLayers.normalMap4"),
    limit=16, limit_unit="wrinkle masks",
    limit_why="morph targets with wrinkle masks the O3DE skinning shader blends at once",
    mask_suffix=".tif", doc="o3de")
# Source: studio.h's MAXSTUDIOFLEXCTRL; VertexLitGeneric has one compress and one stretch map
SOURCE = EngineLayout(
    "source", "Source engine (VertexLitGeneric $bumpcompress / $bumpstretch)", "vertex",
    maps=("bumpcompress", "bumpstretch"), limit=96, limit_unit="flex controllers",
    limit_why="flex controllers a Source model may have (MAXSTUDIOFLEXCTRL)", doc="source")

LAYOUTS: dict[str, EngineLayout] = {layout.key: layout
                                    for layout in (METAHUMAN, CC, O3DE, SOURCE, STUDIO)}
