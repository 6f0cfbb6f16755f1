"""Starting points derived from the key poses, so an imported face shows wrinkles at once.

``--auto`` and Tools ▸ Auto Setup: for each key pose, a technique-2 area with wrinkle direction
vectors on the vertices the pose moves (directions from its motion; cones narrowed where another
pose's motion would show them on skin it does not wrinkle) and a technique-1 soft mask from its
skin compression, linked to the pose. And what the automatic (strain) mode shows
at some pose weights, turned into an editable mask or WDV area.

Both go through the same two builders: :func:`mask_from_weights` (per-vertex weights → a soft UV
mask) and :func:`wdv_area_from_selection` (selected vertices + a target shape → vectors), so an
auto mask, an auto WDV area and a converted strain result are made the same way. Vertices marked
not-face never get any. Nothing here changes the project except :func:`apply_setup` (and
:func:`auto_setup`, which is suggest + apply): the GUI pushes the suggestion as one undo step.
"""

from __future__ import annotations

import colorsys
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import NEUTRAL, PoseBlender
from studio.core.files.errors import StudioError
from studio.core.files.naming import unique_name
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.selection import suggest
from studio.core.project.model import Project
from studio.core.setup.skin_tone_maps import add_tone_maps
from studio.core.setup.stage_clock import stage
from studio.core.setup.wrinkle_synth import (
    UvRaster,
    fill_placeholder,
    placed_lines,
    pose_workers,
)
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.skin_strain import PoseStrain, SkinStrain, compression_weights
from studio.core.wrinkles.strain import DEFAULT_FULL_AT, StrainField
from studio.core.wrinkles.wdv import WdvArea, wrinkle_directions

Array = np.ndarray

DEFAULT_MASK_SIZE = 1024  # a fresh project's mask resolution (the areas panel's default too)
WORK_SIZE = 1024  # masks are drawn at most this size, then resampled (they are smooth)
SETUP_WORK_SIZE = 512  # … and for the soft masks of a whole auto setup, one per pose
SUGGEST_FRACTION = 0.2  # the WDV panel's Suggest default: moved by > 20 % of the largest motion
MASK_THRESHOLD = 0.1  # compression below 10 % of the pose's strong compression makes no mask
MASK_SOFTNESS = 4.0  # blur of an auto mask, pixels of its size (as the areas panel's Auto mask)
STILL_MOTION = 1e-4  # skin moved by less than this fraction of the face's size: not moved
STRAIN_THRESHOLD = 0.25  # a strain → WDV area takes vertices with a wrinkle weight above this
MAX_LINK_GAIN = 2.0  # the areas panel's largest link gain
CROSS_SHOWN = 0.05  # another pose whose motion would show an area's wrinkles this much …
CROSS_SQUEEZED = 0.1  # … at a vertex it compresses less than this (its compression weight) …
CONE_SHRINK = 0.9  # … gets the vertex's cone narrowed to this share of its motion's angle …
LEAST_CONE = 0.5  # … but no narrower than this (degrees)
PAIR_SHOWN = 0.3  # … or two other poses at once would show them this much (a frown's brow
# lowerer and mouth frown, a squint's crow's feet at the temple: 1.0); 0.05 took a smile's
# crow's feet from its cheek raise wherever two unrelated poses together moved that skin alike
UNDER_A_TEXEL = "its compression covers no texel of the masks"
PLACED_CONE = 45.0  # degrees: the cone on the vertices of lines anatomy placed (see below)


@dataclass
class AutoSetupReport:
    """What an automatic setup adds (new areas and links) and which poses gave nothing."""

    influence_areas: list[InfluenceArea] = field(default_factory=list)
    wdv_areas: list[WdvArea] = field(default_factory=list)
    links: dict[str, dict[str, float]] = field(default_factory=dict)  # pose -> {area: gain}
    still_poses: list[str] = field(default_factory=list)  # move no skin: no WDV area
    flat_poses: list[str] = field(default_factory=list)  # no mask (see ``no_mask``)
    no_mask: dict[str, str] = field(default_factory=dict)  # pose -> why it got none, in words
    strains: dict[str, PoseStrain] = field(default_factory=dict)  # what each pose does
    regions: dict[str, str] = field(default_factory=dict)  # where it compresses, by name

    @property
    def empty(self) -> bool:
        return not self.influence_areas and not self.wdv_areas

    def summary(self) -> str:
        """One or two sentences for a status bar, a message box or the command line."""
        if self.empty and not self.still_poses and not self.flat_poses:
            return "No key poses to start from."
        parts = [f"added {len(self.wdv_areas)} wrinkle-vector area(s) and "
                 f"{len(self.influence_areas)} mask(s)"]
        if self.still_poses:
            parts.append(f"no vectors for {', '.join(self.still_poses)} (moves no skin)")
        if self.flat_poses:
            reasons: dict[str, list[str]] = {}
            for pose in self.flat_poses:
                reason = (UNDER_A_TEXEL if self.no_mask.get(pose) == UNDER_A_TEXEL
                          else "compresses no skin")
                reasons.setdefault(reason, []).append(pose)
            parts += [f"no mask for {', '.join(poses)} ({reason})"
                      for reason, poses in reasons.items()]
        text = "; ".join(parts)
        return text[0].upper() + text[1:] + "."

    def pose_lines(self) -> list[str]:
        """A line per pose: how much skin it compresses, where and how strongly, or why it
        got no mask — what a user checks first on a face made elsewhere."""
        lines = []
        for pose, strain in self.strains.items():
            if pose in self.flat_poses or not strain.compresses:
                # the reason the mask was not made, the one the summary gives
                why = self.no_mask.get(pose) or strain.describe()
                lines.append(f"{pose}: no mask, {why if why == UNDER_A_TEXEL else 'it ' + why}")
            else:
                where = f" ({self.regions[pose]})" if pose in self.regions else ""
                lines.append(f"{pose}: compresses {100 * strain.compressed_share:.1f} % of the "
                             f"skin{where}, peak {100 * strain.peak_compression:.0f} %")
        return lines


def area_colour(index: int) -> tuple[int, int, int]:
    """Distinct colours for a run of new areas: hues a golden angle apart."""
    r, g, b = colorsys.hsv_to_rgb((0.08 + index * 0.381966) % 1.0, 0.7, 0.95)
    return round(r * 255), round(g * 255), round(b * 255)


# --- the shared builders -------------------------------------------------------------------------

def mask_from_weights(mesh: FaceMesh, weights: Array, shape: tuple[int, int],
                      softness: float = 0.0, raster: UvRaster | None = None) -> Array:
    """A (h, w) UV mask from per-welded-vertex weights in [0, 1], interpolated over the
    triangles.

    Drawn with ``raster`` (made at ``WORK_SIZE`` at most when not given: smooth masks lose
    nothing), blurred by ``softness`` pixels of the target size and resampled to ``shape``;
    values below 1e-3 drop to exactly 0, so untouched skin stays out of the area.
    """
    h, w = shape
    raster = raster or UvRaster(mesh, min(max(w, h), WORK_SIZE))
    img = raster.image(np.clip(np.asarray(weights, np.float32), 0.0, 1.0)[mesh.weld])
    img = mask_ops.blur(img, softness * raster.size / max(w, h))
    out = mask_ops.resample(img, (w, h))
    out[out < 1e-3] = 0.0
    return out


def wdv_area_from_selection(name: str, pose: str, rest: Array, target: Array, selected: Array,
                            **kwargs) -> WdvArea | None:
    """A technique-2 area whose selected vertices point along their motion from ``rest`` to
    ``target`` (the thesis's "create wrinkle directions"); None when none of them moves."""
    result = wrinkle_directions(rest, target, np.flatnonzero(selected))
    if not result.lengths.any():
        return None
    return WdvArea(name, pose, result.directions, result.lengths, **kwargs)


# --- per-pose weights ----------------------------------------------------------------------------

def skin_target(project: Project, target: Array) -> Array:
    """The target with not-face vertices held at rest: their motion selects nothing."""
    if project.not_face is None:
        return np.asarray(target, np.float32)
    return np.where(project.not_face[:, None], project.mesh.rest, target).astype(np.float32)


def face_size(project: Project) -> float:
    """The diagonal of the skin's bounding box: what motions are measured against, so no
    threshold depends on the face's units."""
    skin = project.skin_weights() > 0
    points = project.mesh.rest[skin] if skin.any() else project.mesh.rest
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) or 1.0


def setup_mask_size(project: Project, mask_size: int | None) -> tuple[int, int]:
    """The mask shape new areas get: the project's resolution (all masks share one)."""
    current = project.influence.resolution
    if mask_size is None:
        return current or (DEFAULT_MASK_SIZE, DEFAULT_MASK_SIZE)
    if mask_size < 1:
        raise StudioError(f"a mask size must be positive, got {mask_size}")
    if current is not None and current != (mask_size, mask_size):
        raise StudioError(f"the project's masks are {current[1]}×{current[0]}; new masks must "
                          f"match, not {mask_size}×{mask_size}")
    return mask_size, mask_size


# --- a starting point from every key pose ------------------------------------------------

def suggest_setup(project: Project, *, mask_size: int | None = None,
                  poses: Iterable[str] | None = None, fraction: float = SUGGEST_FRACTION,
                  threshold: float = MASK_THRESHOLD, softness: float = MASK_SOFTNESS,
                  locate: Callable[[Array], str] | None = None,
                  progress: Callable[[int, int], bool] | None = None,
                  placed: Mapping[str, tuple[Array, Array]] | None = None, frame=None
                  ) -> AutoSetupReport | None:
    """The areas and links an automatic setup would add, without changing the project.

    For each key pose (all, or ``poses``): a WDV area named after it on the vertices it moves by
    more than ``fraction`` of its largest skin motion, and a soft mask from its compression
    linked to it with gain 1. Poses that move or compress no skin are reported instead.
    Each pose's strain goes into the report; ``locate`` names the region of a neutral-face
    point, for the report to say where a pose compresses the skin. None if ``progress``
    (called with poses done, poses in all) returned False. ``placed``: for the poses whose
    lines anatomy places on a synthesised map, {pose: (the vertices of those lines, those
    where anatomy lets them lie)} — by default ``wrinkle_synth.placed_lines`` (from the face's
    ``frame``, found when not given), so ``new --auto`` and Tools ▸ Auto Setup make the same
    areas: the pose's WDV area and mask hold the lines' vertices besides what it moves and
    compresses most, and it wrinkles nowhere outside anatomy's place. Each area's cones are
    narrowed where another of these poses would show its wrinkles without wrinkling the skin
    there (``narrow_cones``).
    """
    names = [p.name for p in project.poses] if poses is None else list(poses)
    shape = setup_mask_size(project, mask_size)
    if placed is None:
        with stage("strain"):
            placed = placed_lines(project, [n for n in names if n != NEUTRAL], frame)
    rest = project.mesh.rest
    report = AutoSetupReport()
    wdv_taken = [a.name for a in project.wdv.areas]
    mask_taken = [a.name for a in project.influence.areas]
    skin = project.skin_weights()
    strain = SkinStrain(project.mesh, skin)
    size = face_size(project)
    with stage("masks"):
        raster = UvRaster(project.skin_mesh(), min(max(shape), SETUP_WORK_SIZE))
    motions: dict[str, Array] = {}  # what each pose does, for narrowing the areas' cones
    squeezed: dict[str, Array] = {}
    for done, name in enumerate(names, start=1):
        if progress is not None and not progress(done, len(names)):
            return None
        if name == NEUTRAL:
            continue
        target = project.pose(name).positions
        moved = skin_target(project, target)
        motion = float(np.linalg.norm(moved - rest, axis=1).max(initial=0.0)) / size
        colour = area_colour(len(report.wdv_areas) + len(report.flat_poses))
        with stage("vectors"):
            area = _pose_vectors(name, rest, moved, motion, fraction, placed, wdv_taken,
                                 colour)
        if motion > STILL_MOTION:
            motions[name] = (moved - rest).astype(np.float32)
        if area is None:
            report.still_poses.append(name)
        else:
            wdv_taken.append(area.name)
            report.wdv_areas.append(area)
        with stage("strain"):
            pose_strain = strain.of(target)
            summary = strain.summary(pose_strain, motion if motion > STILL_MOTION else 0.0)
            report.strains[name] = summary
            if locate is not None and summary.centre is not None:
                report.regions[name] = locate(summary.centre)
            # its mask holds anatomy's lines whole, and it wrinkles only there
            own = compression_weights(strain, pose_strain.compression, threshold)
        weights = placed_or_own(own, placed.get(name), 1.0)
        squeezed[name] = weights
        with stage("masks"):
            mask = mask_from_weights(project.mesh, weights, shape, softness, raster)
        if not mask.any():
            report.flat_poses.append(name)
            report.no_mask[name] = (UNDER_A_TEXEL if summary.compresses
                                    else summary.describe())
            continue
        mask_area = InfluenceArea(unique_name(name, mask_taken), mask, colour=colour)
        mask_taken.append(mask_area.name)
        report.influence_areas.append(mask_area)
        report.links.setdefault(name, {})[mask_area.name] = 1.0
    with stage("vectors"):
        narrow_cones(report.wdv_areas, motions, squeezed,
                     {name: np.asarray(v[0], bool) for name, v in placed.items()})
    return report


def _pose_vectors(name: str, rest: Array, moved: Array, motion: float, fraction: float,
                  placed: Mapping[str, tuple[Array, Array]], taken: list[str],
                  colour: tuple[int, int, int]) -> WdvArea | None:
    """A pose's technique-2 area (``suggest_setup``): on the vertices it moves by more than
    ``fraction`` of its largest skin motion (``moved``: its target, not-face held at rest),
    narrowed to anatomy's lines where it places some; None for a pose that moves no skin."""
    if motion <= STILL_MOTION:
        return None
    selected = suggest(rest, moved, fraction)
    # anatomy's lines, and what the pose moves around them only: its vectors
    # elsewhere would reveal other poses' furrows on its map (a sneer's, pulling the
    # brow down, a frown's lines between the brows)
    selected = placed_or_own(selected, placed.get(name), True)
    area = wdv_area_from_selection(unique_name(name, taken), name, rest, moved, selected,
                                   colour=colour)
    if area is not None and name in placed:
        # a brow lowerer and its mirror pull the skin between the brows apart and down
        # (a frown, both at once, straight down): lines there show for either and both
        area.cone_angles_deg = np.where(placed[name][0] & area.authored, PLACED_CONE,
                                        0.0).astype(np.float32)
    return area


def placed_or_own(own: Array, place: tuple[Array, Array] | None, on_lines: float | bool
                  ) -> Array:
    """A pose's own per-vertex values (what it moves or compresses) narrowed to where anatomy
    places its lines: ``on_lines`` on the lines, its own values inside their window, nothing
    outside. Its own values unchanged where anatomy places nothing (``place`` None) or where
    the window holds none of them: anatomy's places come from the face's frame, which the
    other poses loaded help find, and whether a pose gets a mask and vectors must depend on
    that pose alone (a brow lowerer squeezing the skin got no mask beside two poses and one
    beside fifty)."""
    if place is None:
        return own
    lines, window = (np.asarray(v, bool) for v in place)
    refined = np.where(lines, on_lines, np.where(window, own, 0)).astype(own.dtype)
    return refined if refined.any() else own


def narrow_cones(areas: Sequence[WdvArea], motions: Mapping[str, Array],
                 squeezed: Mapping[str, Array], lines: Mapping[str, Array] | None = None
                 ) -> None:
    """Keep each pose's motion out of the other poses' wrinkle vectors where it does not
    compress the skin: technique 2 shows an area's wrinkles wherever a motion falls inside its
    cones, so a frown that pushes the outer eye corners the way a squint does would show the
    squint's crow's feet there, and its scalp's pull the brow raise's forehead lines. Where
    another pose (``motions``: {pose: (W, 3)}), or two others at once (``_others``: an
    expression is a sum of poses, and a brow lowerer with a mouth frown pushes the temple the
    way a squint does where neither alone does), would show an area's wrinkles by
    ``CROSS_SHOWN`` at full weight (two at once: ``PAIR_SHOWN``) and compresses the skin by
    less than ``CROSS_SQUEEZED`` (``squeezed``: its compression weights), the vertex's cone is
    narrowed below that motion's angle (painted cones, ``WdvArea.cone_angles_deg``); the
    area's own pose, along its vectors, shows as before. ``lines``: {pose: (W,) bool} the
    vertices of the lines anatomy placed for a pose; on them only another pose whose own
    placed lines lie there too keeps the cone by squeezing the skin — a brow raise squeezes
    the skin between the inner eye and the nose, and showed a squint's lines under the eye
    there; a left brow lowerer squeezes the right one's line, and showed it. The areas are
    independent: narrowed on every core the process may use (``pose_workers``)."""
    with ThreadPoolExecutor(pose_workers()) as pool:
        list(pool.map(lambda area: _narrow_area(area, motions, squeezed, lines), areas))


def _narrow_area(area: WdvArea, motions: Mapping[str, Array], squeezed: Mapping[str, Array],
                 lines: Mapping[str, Array] | None) -> None:
    """``narrow_cones`` for one area: its cones, painted where they narrow."""
    index = np.flatnonzero(area.authored)
    direction = area.directions[index].astype(np.float64)
    length = area.lengths[index].astype(np.float64)
    full = area.vertex_cones_deg()[index].astype(np.float64)
    cone = full.copy()
    for at, delta, squeeze, least in _others(area, index, direction, length, full, motions,
                                             squeezed, lines):
        size = np.linalg.norm(delta, axis=1)
        cos = np.einsum("ij,ij->i", delta, direction[at]) / np.maximum(size, 1e-300)
        alpha = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        shown = size / np.maximum(length[at], 1e-300) * (1.0 - alpha / full[at])
        crosses = ((size > 0.0) & (alpha < full[at]) & (shown > least)
                   & (squeeze < CROSS_SQUEEZED))
        np.minimum.at(cone, at[crosses], np.maximum(CONE_SHRINK * alpha[crosses], LEAST_CONE))
    if (cone < full).any():
        painted = (np.zeros(len(area.lengths), np.float32) if area.cone_angles_deg is None
                   else area.cone_angles_deg.copy())
        painted[index] = np.where(cone < full, cone, painted[index])
        area.cone_angles_deg = painted


ALONG_MARGIN = 1e-6  # rounding room for ``_others``'s bound on a motion's reach along the vectors
WIDEST_BOUNDED = 90.0  # cones up to this wide (degrees): that bound holds (see ``_others``)


def _others(area: WdvArea, index: Array, direction: Array, length: Array, full: Array,
            motions: Mapping[str, Array], squeezed: Mapping[str, Array],
            lines: Mapping[str, Array] | None = None
            ) -> Iterator[tuple[Array, Array, Array, float]]:
    """(where, motion, compression weight, least shown) on the area's vertices (``index``;
    ``where`` indexes them, a vertex perhaps more than once) of each other pose, and of each
    two other poses at once (their motions summed, the larger weight) where together they
    move the skin by ``PAIR_SHOWN`` of the vectors' length (less cannot show its wrinkles)
    and neither squeezes it (else the pair keeps the cone anyway).
    Only where a motion can cross: one that shows an area's wrinkles by ``least``
    (``|δ|/L · (1 − α/θ) > least`` inside a cone θ ≤ 90°) reaches along the vectors by more
    than ``least`` (``δ·d/L = |δ|/L · cos α ≥ |δ|/L · (1 − α/θ)``: cos is concave), so the
    vertices and pairs that reach less along them (the sum of the two's reaches along them,
    a sum of linear terms: one product of the poses' motions with the vectors) are left out
    before any angle is taken — the cones come out the same, in a tenth of the time on the
    30 000-vertex head with 52 poses that each move most of the face (20 s before).
    ``lines`` (as for ``narrow_cones``): on the area's own placed lines, a pose whose own
    placed lines do not lie there too weighs nothing (a left brow lowerer squeezes the right
    one's line a quarter as much as its own, and showed it)."""
    own = None if lines is None else lines.get(area.pose)
    wide = full > WIDEST_BOUNDED  # the bound does not hold: every vertex stays
    reach_of = 1.0 / np.maximum(length, 1e-300)
    moving = []
    for pose, motion in motions.items():
        if pose == area.pose or pose not in squeezed:
            continue
        delta = motion[index].astype(np.float64)
        weight = np.asarray(squeezed[pose])[index]
        if own is not None:  # on the area's lines, only a pose whose own lines lie there
            theirs = lines.get(pose)
            mine = own[index] if theirs is None else own[index] & ~theirs[index]
            weight = np.where(mine, 0.0, weight)
        along = np.einsum("ij,ij->i", delta, direction) * reach_of
        at = np.flatnonzero((weight < CROSS_SQUEEZED)
                            & (wide | (along > CROSS_SHOWN * (1.0 - ALONG_MARGIN))))
        if at.size:
            yield at, delta[at], weight[at], CROSS_SHOWN
        reach = np.linalg.norm(delta, axis=1) * reach_of
        if reach.max(initial=0.0) > 0.5 * CROSS_SHOWN:
            moving.append((delta, weight, reach, along))
    if len(moving) < 2:
        return
    deltas, weights, reaches, alongs = (np.stack(v) for v in zip(*moving, strict=True))
    yield from _pairs(deltas, weights, reaches, alongs, wide)


def _pairs(deltas: Array, weights: Array, reaches: Array, alongs: Array, wide: Array
           ) -> Iterator[tuple[Array, Array, Array, float]]:
    """``_others``'s pairs: each pose with all the poses after it at once, on the vertices
    where neither squeezes the skin and the two can reach ``PAIR_SHOWN`` along the vectors
    (the pose's own reach along them and the most of any later pose's there)."""
    free = weights < CROSS_SQUEEZED
    bound = PAIR_SHOWN * (1.0 - ALONG_MARGIN)
    # per pose, the furthest any later free pose reaches along the vectors at each vertex
    later_best = np.full_like(alongs, -np.inf)
    later_best[:-1] = np.maximum.accumulate(np.where(free, alongs, -np.inf)[:0:-1],
                                            axis=0)[::-1]
    for i in range(len(deltas) - 1):
        cols = np.flatnonzero(free[i] & (wide | (alongs[i] + later_best[i] > bound)))
        if not cols.size:
            continue
        rest = slice(i + 1, None)
        later, at = np.nonzero((reaches[i, cols] + reaches[rest, cols] > PAIR_SHOWN)
                               & (np.maximum(weights[i, cols], weights[rest, cols])
                                  < CROSS_SQUEEZED)
                               & (wide[cols] | (alongs[i, cols] + alongs[rest, cols] > bound)))
        if at.size:  # (where either squeezes the skin, the pair keeps the cone anyway)
            later, at = later + i + 1, cols[at]
            yield (at, deltas[i, at] + deltas[later, at],
                   np.maximum(weights[i, at], weights[later, at]), PAIR_SHOWN)


def merged_links(current: Mapping[str, Mapping[str, float]],
                 added: Mapping[str, Mapping[str, float]]) -> dict[str, dict[str, float]]:
    """The project's links with the new ones added (new areas have new names: no clash)."""
    links = {pose: dict(gains) for pose, gains in current.items()}
    for pose, gains in added.items():
        links.setdefault(pose, {}).update(gains)
    return links


def apply_setup(project: Project, report: AutoSetupReport) -> None:
    """Add a suggestion's areas after the existing ones, and its links."""
    project.influence.areas.extend(report.influence_areas)
    project.influence.links = merged_links(project.influence.links, report.links)
    project.wdv.areas.extend(report.wdv_areas)


def areas_of_poses(project: Project, poses: Iterable[str]) -> list[InfluenceArea | WdvArea]:
    """The areas that follow these poses: technique-1 areas a pose links to with a positive
    gain, technique-2 areas made from one of them."""
    chosen = set(poses)
    linked = {area for pose, gains in project.influence.links.items() if pose in chosen
              for area, gain in gains.items() if gain > 0.0}
    return [*(a for a in project.influence.areas if a.name in linked),
            *(a for a in project.wdv.areas if a.pose in chosen)]


def auto_setup(project: Project, *, mask_size: int | None = None, **options) -> AutoSetupReport:
    """Give the project a starting point for both techniques from its key poses;
    ``options`` as for :func:`suggest_setup`. Returns what was added and what was skipped."""
    report = suggest_setup(project, mask_size=mask_size, **options)
    apply_setup(project, report)
    return report


def auto_start(project: Project, locate: Callable[[Array], str] | None = None,
               progress: Callable[[int, int], bool] | None = None,
               poses: Sequence[str] | None = None, frame=None) -> list[str] | None:
    """``wrinkle-studio new --auto``: the automatic setup and, for a face that came without a
    wrinkled normal map (a flat placeholder), maps synthesised from its key poses — several
    where poses' furrows cross, each pose's areas revealing its own — so that the imported face
    shows wrinkles at once. Returns what was done, a line each; None, with the project
    untouched, if ``progress`` (done, total: the synthesis's steps then the set-up's) returned
    False. ``poses``: the key poses to set up (default all), e.g. a rig's wrinkling ones.
    Where anatomy places a pose's lines (a frown's), its mask and vectors hold them whole, as
    Tools ▸ Auto Setup's do: both go through ``suggest_setup``. ``frame``: the face's frame
    (``face_frame.face_frame``), when the caller has found it: the synthesis and the set-up
    share it rather than find it again, a second each on the sample."""
    steps = len(project.poses) if poses is None else len(poses)
    textures = dict(project.textures.wrinkle_maps)

    def synth_progress(done: int, total: int) -> bool:
        return progress is None or progress(done, steps + total)

    def setup_progress(done: int, total: int) -> bool:  # after the synthesis's steps, if any
        before = steps if made else 0
        return progress is None or progress(before + done, before + total)

    with stage("synthesis"):
        made = fill_placeholder(project, progress=synth_progress, poses=poses, frame=frame)
    report = None if made is None else suggest_setup(
        project, locate=locate, progress=setup_progress, poses=poses, frame=frame)
    if made is None or report is None:
        project.textures.wrinkle_maps = textures
        return None
    apply_setup(project, report)
    with stage("synthesis"):
        add_tone_maps(project, made)
    lines = [f"auto setup: {report.summary()}",
             *(f"  {line}" for line in report.pose_lines())]
    overlap = uv_overlap_share(project)
    if overlap >= OVERLAP_WORTH_SAYING:
        lines.append(f"auto setup: parts marked not face overlap {overlap:.0%} of the skin in "
                     "UV (eyes or teeth on the skin's tile); masks, strain and furrows were "
                     "taken from the skin's triangles only")
    for map_name, poses in made.items():
        reveal_map(project, report, poses, map_name)
    if made:
        maps = ", ".join(f"'{m}' ({', '.join(p) or 'no furrows'})" for m, p in made.items())
        lines.append(f"auto setup: synthesised wrinkled normal maps from the key poses (the "
                     f"face came without one): {maps}")
    return lines


OVERLAP_WORTH_SAYING = 0.005  # of the skin's texels


def uv_overlap_share(project: Project, size: int = 256) -> float:
    """The share of the skin's UV texels that not-face triangles (eyes, teeth, lashes) cover
    too: where a UV-space tool that did not know skin from eye would have mixed them up."""
    skin = project.skin_triangles()
    if skin.all() or not skin.any():
        return 0.0
    mesh = project.mesh
    zero = np.zeros(mesh.n_vertices, np.float32)
    _, on_skin = mask_ops.rasterise_uv(mesh.uvs, mesh.triangles[skin], zero, size)
    _, on_other = mask_ops.rasterise_uv(mesh.uvs, mesh.triangles[~skin], zero, size)
    return float((on_skin & on_other).sum() / max(int(on_skin.sum()), 1))


def reveal_map(project: Project, report: AutoSetupReport, poses: Iterable[str],
               map_name: str) -> None:
    """Point the areas a setup made for these poses at one wrinkled map."""
    chosen = set(poses)
    masks = {area for pose in chosen for area in report.links.get(pose, {})}
    for area in report.influence_areas:
        if area.name in masks:
            area.wrinkle_map = map_name
    for wdv_area in report.wdv_areas:
        if wdv_area.pose in chosen:
            wdv_area.wrinkle_map = map_name


# --- the automatic (strain) mode's result, made editable -------------------------------

def active_poses(project: Project, pose_weights: Mapping[str, float]) -> dict[str, float]:
    """The key poses with a positive weight, strongest first."""
    known = {p.name for p in project.poses}
    active = {k: float(w) for k, w in pose_weights.items() if k in known and w > 0.0}
    return dict(sorted(active.items(), key=lambda kv: -kv[1]))


def posed_positions(project: Project, pose_weights: Mapping[str, float]) -> Array:
    """Welded positions of the face at these pose weights (a copy)."""
    blender = PoseBlender(project.mesh.rest, project.poses)
    return blender.blend(active_poses(project, pose_weights)).copy()


def strain_weights(project: Project, pose_weights: Mapping[str, float],
                   full_at: float = DEFAULT_FULL_AT) -> Array:
    """(W,) what the automatic mode shows at these pose weights, 0 on not-face vertices."""
    positions = posed_positions(project, pose_weights)
    return StrainField(project.mesh).weights(positions, full_at) * project.skin_weights()


def strain_area_name(project: Project, pose_weights: Mapping[str, float]) -> str:
    names = list(active_poses(project, pose_weights))
    return " + ".join(names[:3]) + (" …" if len(names) > 3 else "") + " strain"


def _need_active(project: Project, pose_weights: Mapping[str, float]) -> dict[str, float]:
    active = active_poses(project, pose_weights)
    if not active:
        raise StudioError("the face is in its neutral pose, where the automatic mode shows no "
                          "wrinkles: move a pose slider first")
    return active


def strain_mask(project: Project, pose_weights: Mapping[str, float], *,
                mask_size: int | None = None, full_at: float = DEFAULT_FULL_AT,
                softness: float = 0.0) -> tuple[InfluenceArea, dict[str, dict[str, float]]]:
    """The automatic mode's wrinkle weights at these pose weights as a technique-1 mask, and
    links that give it activation 1 at these weights (gain 1/Σw per active pose, at most
    ``MAX_LINK_GAIN``), so technique 1 then shows what the automatic mode showed.

    Raises StudioError in the neutral pose or where the pose compresses no skin.
    """
    active = _need_active(project, pose_weights)
    mask = mask_from_weights(project.skin_mesh(), strain_weights(project, active, full_at),
                             setup_mask_size(project, mask_size), softness)
    if not mask.any():
        raise StudioError("the automatic mode shows no wrinkles at these pose weights "
                          "(no skin is compressed)")
    name = unique_name(strain_area_name(project, active),
                       (a.name for a in project.influence.areas))
    gain = min(1.0 / sum(active.values()), MAX_LINK_GAIN)
    area = InfluenceArea(name, mask, colour=area_colour(len(project.influence.areas)))
    return area, {pose: {name: gain} for pose in active}


def strain_wdv_area(project: Project, pose_weights: Mapping[str, float], *,
                    threshold: float = STRAIN_THRESHOLD,
                    full_at: float = DEFAULT_FULL_AT) -> WdvArea:
    """A technique-2 area on the vertices whose automatic wrinkle weight exceeds ``threshold``
    at these pose weights, pointing along their displacement there; its pose is the strongest
    active one. Raises StudioError in the neutral pose or where no vertex qualifies."""
    active = _need_active(project, pose_weights)
    weights = strain_weights(project, active, full_at)
    target = skin_target(project, posed_positions(project, active))
    name = unique_name(strain_area_name(project, active), (a.name for a in project.wdv.areas))
    area = wdv_area_from_selection(name, next(iter(active)), project.mesh.rest, target,
                                   weights > threshold,
                                   colour=area_colour(len(project.wdv.areas)))
    if area is None:
        raise StudioError(f"no vertex has an automatic wrinkle weight above {threshold:g} at "
                          "these pose weights")
    return area
