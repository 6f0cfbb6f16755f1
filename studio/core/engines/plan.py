"""Which of the project's areas go into which channel of an engine's textures — decided before
anything is written, so a layout the engine cannot hold is refused with no file touched.

Areas are matched to an engine's regions by the poses that drive them (their pose → area links):
the pose's ARKit name (core/pose_names.py) first, then its face-region word, then the area's own
name's; the side comes from the area's name, else the pose's. An area of the middle of the face
on a left/right pair of regions fills both. Several areas in one channel are added and clamped to
1, as the studio's shader adds masks; what matches nothing is reported, not silently dropped.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from studio.core.animation import pose_names
from studio.core.engines.layouts import CHANNELS, LAYOUTS, MODEL_FILE, EngineLayout, Region
from studio.core.files.errors import StudioError
from studio.core.project.model import Project
from studio.core.wrinkles.influence import InfluenceArea


class LayoutError(StudioError):
    """A layout the engine cannot hold (more masks, samplers or flexes than it allows);
    ``mergeable`` when merging the weakest masks would fit it (``plan_export(merge=True)``)."""

    def __init__(self, message: str, mergeable: bool = False) -> None:
        super().__init__(message)
        self.mergeable = mergeable


@dataclass
class Channel:
    """One channel of a mask texture and the areas added into it (area index, gain)."""

    channel: str
    region: str | None = None
    side: str | None = None
    map_slot: int | None = None  # which of the plan's maps the channel reveals
    sources: list[tuple[int, float]] = field(default_factory=list)


@dataclass
class MaskTexture:
    name: str  # the engine's name for it
    file: str  # path relative to the export folder
    channels: list[Channel]


@dataclass
class MapSlot:
    """One wrinkle normal map the engine samples: ``source`` names the project's map it is (a
    straight copy); otherwise it is composed from ``areas``' maps (the neutral map without)."""

    name: str
    file: str
    source: str | None = None
    areas: list[int] = field(default_factory=list)


@dataclass
class Flex:
    """A Source flex (one key pose): its areas' masks give each vertex's wrinkle weight."""

    name: str
    sources: list[tuple[int, float]]


@dataclass(frozen=True)
class Merge:
    """A mask folded into another to fit the engine: ``mask``'s channels now ride in
    ``into``'s (added, clamped), so its areas show when ``into``'s pose moves, not its own."""

    mask: str
    into: str
    strength: float  # the merged mask's influence: its channels' mean value, added
    overlap: float  # the share of that influence lying where ``into``'s masks reach

    def describe(self) -> str:
        return (f"the mask of '{self.mask}' (the weakest, {self.strength:.4f}) merged into "
                f"'{self.into}' ({self.overlap:.0%} of it where '{self.into}' reaches)")


@dataclass
class Plan:
    layout: EngineLayout
    masks: list[MaskTexture]
    maps: list[MapSlot]
    unassigned: list[tuple[str, str]]  # (area, why it has no channel)
    used: int  # what the engine's limit counts (layout.limit_unit)
    samplers: int
    flexes: list[Flex] = field(default_factory=list)
    merged: list[Merge] = field(default_factory=list)

    @property
    def mergeable(self) -> bool:
        """Over the limit, but by masks that can be merged: a mask per pose (O3DE)."""
        return self.used > self.layout.limit and self.layout.kind == "per_pose"

    def check(self) -> None:
        """Refuse a layout over the engine's documented limit (a one-line LayoutError)."""
        layout = self.layout
        if self.used > layout.limit:
            offer = (f"; merging the {self.used - layout.limit} weakest masks into the ones "
                     "they overlap most fits it" if self.mergeable else "")
            raise LayoutError(f"the {layout.key} layout needs {self.used} {layout.limit_unit}, "
                              f"more than the {layout.limit} {layout.limit_why}{offer}",
                              self.mergeable)


def linked_poses(project: Project) -> dict[int, list[tuple[str, float]]]:
    """Area index → [(pose, gain)] of the poses whose links raise it, in link order."""
    index = {a.name: i for i, a in enumerate(project.influence.areas)}
    out: dict[int, list[tuple[str, float]]] = {}
    for pose, gains in project.influence.links.items():
        for area, gain in gains.items():
            if area in index and gain > 0:
                out.setdefault(index[area], []).append((pose, float(gain)))
    return out


def plan_export(project: Project, key: str, merge: bool = False) -> Plan:
    """The plan for the layout named ``key`` (see engine_layouts.LAYOUTS); not yet checked.
    ``merge``: where the plan is :attr:`Plan.mergeable`, the weakest masks are merged until
    the engine holds it (:func:`merge_weakest`)."""
    try:
        layout = LAYOUTS[key]
    except KeyError:
        raise StudioError(f"unknown layout '{key}' (layouts: {', '.join(LAYOUTS)})") from None
    planner = {"regions": _plan_regions, "per_pose": _plan_per_pose, "per_area": _plan_per_area,
               "vertex": _plan_vertex}[layout.kind]
    plan = planner(project, layout)
    if merge and plan.mergeable:
        merge_weakest(project, plan)
    return plan


def merge_weakest(project: Project, plan: Plan) -> None:
    """Fold the weakest mask into the one it overlaps most until the engine's limit holds.

    Why the weakest and why there: O3DE blends at most 16 masks, each a morph target's; a mask
    whose areas hardly reach is what the face loses least without, and in the mask lying over
    the same skin it still shows when a neighbouring pose (often its other side or its partner
    in an expression) moves. Weakness is a mask's influence: its channels' mean values added
    (masks × gains, clamped per channel as written); a tie in overlap goes to the stronger.
    """
    areas = project.influence.areas

    def coverage(texture: MaskTexture) -> np.ndarray:
        """Where a mask reaches: its channels' values added (each clamped as it is written)."""
        total = np.zeros(project.influence.resolution or (1, 1), np.float32)
        for channel in texture.channels:
            values = sum((np.float32(g) * areas[i].mask for i, g in channel.sources),
                         np.zeros_like(total))
            total += np.clip(values, 0.0, 1.0)
        return total

    cover = {t.name: coverage(t) for t in plan.masks}
    while len(plan.masks) > plan.layout.limit:
        weak = min(plan.masks, key=lambda t: float(cover[t.name].mean()))
        strength = float(cover[weak.name].mean())
        others = [t for t in plan.masks if t is not weak]
        shared = {t.name: float(np.minimum(cover[weak.name], cover[t.name]).mean())
                  for t in others}
        into = max(others, key=lambda t: (shared[t.name], float(cover[t.name].mean())))
        for channel in weak.channels:
            target = next(c for c in into.channels if c.channel == channel.channel)
            target.sources += channel.sources
        plan.masks.remove(weak)
        cover[into.name] = coverage(into)
        plan.merged.append(Merge(weak.name, into.name, strength,
                                 shared[into.name] / strength if strength > 0 else 0.0))
    plan.used = len(plan.masks)
    plan.samplers = len(plan.masks) + len(plan.maps)


def own_maps(project: Project, folder: str = "maps") -> list[MapSlot]:
    """The project's wrinkled maps as they are, named as the studio's folder export names them."""
    from studio.core.formats.export import safe_name

    return [MapSlot(name, f"{folder}/wrinkled_{i}_{safe_name(name)}.png", source=name)
            for i, name in enumerate(project.textures.wrinkle_map_names)]


# --- the studio's own: four areas to a texture, in order -------------------------------------

def _plan_per_area(project: Project, layout: EngineLayout) -> Plan:
    areas = project.influence.areas
    masks = [MaskTexture(f"packed_{k:02d}", f"masks/packed_{k:02d}.png",
                         [Channel(CHANNELS[c], area.name, pose_names.side(area.name),
                                  project.textures.map_index(area.wrinkle_map), [(4 * k + c, 1.0)])
                          for c, area in enumerate(areas[4 * k:4 * k + 4])])
             for k in range(math.ceil(len(areas) / 4))]
    maps = own_maps(project)
    return Plan(layout, masks, maps, [], len(masks) + len(maps), len(masks) + len(maps))


# --- O3DE: a mask per morph target, a channel per wrinkle layer ------------------------------

def _plan_per_pose(project: Project, layout: EngineLayout) -> Plan:
    areas = project.influence.areas
    # O3DE looks for a morph target's mask in <model stem>_wrinklemasks/ beside the model
    folder = f"{MODEL_FILE.rsplit('.', 1)[0]}_wrinklemasks"
    masks: list[MaskTexture] = []
    for pose, gains in project.influence.links.items():
        channels = [Channel(c, layout.maps[k], map_slot=k) for k, c in enumerate(CHANNELS)]
        for i, area in enumerate(areas):
            gain = gains.get(area.name, 0.0)
            if gain > 0:
                channels[project.textures.map_index(area.wrinkle_map)].sources.append((i, gain))
        if any(c.sources for c in channels):
            masks.append(MaskTexture(pose, f"{folder}/{pose}_wrinklemask{layout.mask_suffix}",
                                     channels))
    maps = [MapSlot(layout.maps[k], slot.file, source=slot.source)
            for k, slot in enumerate(own_maps(project))]
    unassigned = _unlinked(project, "no pose drives it, and O3DE masks belong to morph targets")
    return Plan(layout, masks, maps, unassigned, len(masks), len(masks) + len(maps))


# --- Source: wrinkle weights per vertex and flex, one compress map ---------------------------

def _plan_vertex(project: Project, layout: EngineLayout) -> Plan:
    index = {a.name: i for i, a in enumerate(project.influence.areas)}
    flexes = []
    for pose, gains in project.influence.links.items():
        sources = [(index[a], float(g)) for a, g in gains.items() if a in index and g > 0]
        if sources:
            flexes.append(Flex(pose, sources))
    driven = sorted({i for flex in flexes for i, _ in flex.sources})
    maps = [MapSlot(layout.maps[0], f"maps/{layout.maps[0]}.png", areas=driven),
            MapSlot(layout.maps[1], f"maps/{layout.maps[1]}.png")]
    unassigned = _unlinked(project, "no pose drives it, and Source wrinkles belong to flexes")
    # $compress and $stretch (colour) join the two bump maps in VertexLitGeneric
    return Plan(layout, [], maps, unassigned, len(flexes), 2 * len(maps), flexes)


def _unlinked(project: Project, why: str) -> list[tuple[str, str]]:
    linked = linked_poses(project)
    return [(a.name, why) for i, a in enumerate(project.influence.areas) if i not in linked]


# --- MetaHuman, Character Creator: a fixed region table --------------------------------------

def _plan_regions(project: Project, layout: EngineLayout) -> Plan:
    channels = {(r.texture, r.channel): Channel(r.channel, r.name, r.side, r.wrinkle_map)
                for r in layout.regions}
    links = linked_poses(project)
    sides = [_area_side(area, links.get(i, [])) for i, area in enumerate(project.influence.areas)]
    unassigned = []
    for i, area in enumerate(project.influence.areas):
        free = partial(_free, channels, sides, sides[i])
        chosen = _choose(layout, area, links.get(i, []), sides[i], free)
        if not chosen:
            unassigned.append((area.name, "none of its poses, nor its name, names a region of "
                                          f"the {layout.key} layout"))
        for region in chosen:
            channels[region.texture, region.channel].sources.append((i, 1.0))
    masks = [MaskTexture(t, f"masks/{t}{layout.mask_suffix}",
                         [channels[t, c] for c in CHANNELS if (t, c) in channels])
             for t in layout.textures]
    maps = [MapSlot(name, f"maps/{name}.png",
                    areas=sorted({i for ch in channels.values() if ch.map_slot == k
                                  for i, _ in ch.sources}))
            for k, name in enumerate(layout.maps)]
    samplers = len(masks) + len(maps)
    return Plan(layout, masks, maps, unassigned, samplers, samplers)


def _free(channels: dict[tuple[str, str], Channel], sides: list[str | None],
          side: str | None, region: Region) -> bool:
    """Whether a region's channel is free for an area of ``side``: empty, or (a channel shared
    by both sides) holding only areas of the other side."""
    return not any(side is None or sides[j] in (None, side)
                   for j, _ in channels[region.texture, region.channel].sources)


def _area_side(area: InfluenceArea, poses: list[tuple[str, float]]) -> str | None:
    """The side an area's name says, else its strongest pose's."""
    strongest = [p for p, _ in sorted(poses, key=lambda pg: -pg[1])]
    return pose_names.side(area.name) or next((pose_names.side(p) for p in strongest), None)


def _choose(layout: EngineLayout, area: InfluenceArea, poses: list[tuple[str, float]],
            side: str | None, free: Callable[[Region], bool]) -> list[Region]:
    """The regions an area goes into: the first pair of regions matched by its strongest pose's
    ARKit name, else by a face-region word, preferring a pair whose channels are still free."""
    ranked = [p for p, _ in sorted(poses, key=lambda pg: -pg[1])]
    for pose in ranked:
        known = pose_names.canonical(pose)
        found = _pairs((r for r in layout.regions if known in r.poses), side, layout)
        if found:
            return _first_free(found, free)
    for word in [*map(pose_names.region_hint, ranked), pose_names.region_hint(area.name)]:
        found = _pairs((r for r in layout.regions if word is not None and r.hint == word),
                       side, layout)
        if found:
            return _first_free(found, free)
    return []


def _pairs(regions: Iterable[Region], side: str | None, layout: EngineLayout
           ) -> list[list[Region]]:
    """Matching regions grouped by pair, in table order, keeping the side's half of a pair
    (both halves for an area of the middle of the face; any for a table of shared sides)."""
    groups: dict[str, list[Region]] = {}
    for r in regions:
        if layout.shared_sides or side is None or r.side in (None, side):
            groups.setdefault(r.pair, []).append(r)
    return list(groups.values())


def _first_free(groups: list[list[Region]], free: Callable[[Region], bool]) -> list[Region]:
    return next((group for group in groups if all(map(free, group))), groups[0])
