"""A wrinkled normal map for a face that has none, synthesised from its key poses.

Where a pose compresses the skin, furrows are laid *across* the direction of compression: the
height varies along that direction (periodic valleys ``spacing`` texels apart) and stays constant
along the furrow. Steps:

1. **Strain in UV space**, per triangle: the Jacobians ``J = E · U⁻¹`` map UV offsets to 3-D
   edge offsets at rest and in the pose; their metrics ``G = JᵀJ`` give, through the 2×2
   generalised eigenproblem ``G_pose v = λ G_rest v``, the smallest stretch ``√λ_min`` (so the
   compression ``1 − √λ_min``) and its UV direction ``v``. Rigid motion changes neither metric,
   so a pose that only moves the face makes no furrows. The furrows' wave vector in the image is
   ``G_rest v`` — perpendicular, on the image, to the UV image of the furrow line even where
   the UV layout is not conformal.
2. **Fields on the UV layout**: compression and the direction (as the doubled-angle vector
   ``(cos 2θ, sin 2θ)``, so opposite directions add instead of cancelling) are rasterised per
   triangle at a work resolution, smoothed, and upsampled. The smoothed doubled-angle vector's
   length relative to its weight (the coherence) fades furrows where directions disagree.
3. **Furrows**: a *phase* per texel whose gradient is the wave vector (2π per spacing across
   the furrows), the least-squares potential of the oriented direction field of each
   compressed region (a Poisson equation, solved by FFT), shifted so a furrow's bottom lies
   where the region is compressed most. A valley profile of the phase gives few, long, smooth
   furrows that follow the direction field — parallel lines on a forehead, a fan at an eye's
   corner, one fold along a narrow band — never the crumples and rings of noise-based
   patterns. Along each furrow, noise on the surface (``surface_noise``, a fixed seed: the
   same input gives the same map) varies its depth and lets its phase wander a little, so no
   two lines are alike and none is ruled.
4. The **depth** grows as the square root of the compression's excess over a threshold
   (``grown_depth``); a furrow's cross-section is a soft valley with the skin bunched slightly
   between furrows (``furrow_profile``). The **height** is ``−depth × (the deepest furrow +
   the most bunched skin over poses)``, in texels; it becomes a tangent-space normal map whose
   slopes ease toward ``MAX_TILT`` and never past it (skin's walls stay under 35°), added to
   the neutral map by reoriented normal mapping (``over_base``): where a pose has no furrow
   the map is the neutral, exactly, and a head's own pores stay inside its furrows.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
from PIL import Image

from studio.core.files.cores import usable_cores
from studio.core.files.errors import StudioError
from studio.core.files.images import to_unit_float
from studio.core.files.naming import unique_name
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.setup import anatomy, anatomy_lower
from studio.core.setup.anatomy import FacePlaces
from studio.core.setup.face_frame import face_frame
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.furrow_controls import FurrowControls, SynthesisedMap, map_digest
from studio.core.wrinkles.normalmap import height_to_normal
from studio.core.wrinkles.skin_strain import (
    WRINKLING_COMPRESSION,
    TriangleStrain,
    UvStrain,
    triangle_areas,
)
from studio.core.wrinkles.strain import DEFAULT_FULL_AT
from studio.core.wrinkles.surface_noise import surface_noise
from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS, FaceTextures, resize_nearest

Array = np.ndarray
Progress = Callable[[int, int], bool]  # (done, total) -> keep going

WORK_SIZE = 256  # strain fields are smooth: rasterised at most this size, then upsampled
SHARPNESS = 1.5  # exponent of the valley profile: higher = narrower furrows between flat skin
BUNCH = 0.18  # skin bunched between neighbouring furrows, raised this share of their depth
PEAK_SHARE = 0.5  # a pose's furrows are at full depth from half its strong compression on
SMOOTH_PEAK_SHARE = 0.4  # … or from this share of its smoothed compression's peak, if less:
# a small region (an eye's lower lid) blurred at the face's furrow scale stays below full_at
FURROW_SPACING = 0.025  # between neighbouring furrows, as a share of the face's size …
DEPTH_PER_SPACING = 0.18  # … and their depth, as a share of the spacing: walls tilted about 25°
# at full depth, as skin's are (0.1–1 mm deep, 0.5–2 mm wide: ../shared/LOOK.md)
MAX_TILT = 35.0  # degrees: no furrow wall tilts further, however deep poses add up
GROW_SOFT = 0.25  # depth grows as √(excess compression), eased in over this share of it
VARY_DEPTH = 0.4  # furrows deepen and fade along their length by this much of their depth …
VARY_SPACINGS = 3.5  # … over about this many spacings (noise on the surface): no two alike
WIGGLE = 1.1  # radians of phase a furrow wanders by, over about …
WIGGLE_SPACINGS = 5.0  # … this many spacings: lines neither ruled nor evenly spaced (more
# variation, 0.6 over 2.5 and 1.4 over 4, tangled a coarse face's lines: test_no_uv_face) …
PLACED_VARY = (0.4, 3.5, 0.55, 5.0)  # anatomy's lines: depth, over spacings, wander, over
# spacings (a glabellar line or a fold is one stroke: bending more, it turned off its course)
FURROWS_EACH_SIDE = 4.0  # of the deepest furrow, before the others fade to a third
FURROWS_ACROSS = 4.0  # a region at least this many furrows across, …
MAX_FINER = 2.0  # … spacing them up to this much closer than the face's spacing
RING_SPACINGS = 2.0  # furrows curling tighter than rings this many spacings across are dropped
ORIENT_PASSES = 4  # neighbourhood votes that orient a region's wave vectors alike …
ORIENT_RADIUS = 6.0  # … over about this many work texels
FURROW_THRESHOLD = 0.08  # furrows where a pose's strength is at least this, fading in above it
MAX_PHASE_GAIN = 4.0  # at most this much steeper than the potential of a region's wave field
CROSSING_ANGLE = 30.0  # degrees: furrows of two poses this far apart do not share a map
CROSSING_SHARE = 0.05  # … when they cross on this share of the smaller pose's furrows
REVEAL_SHARE = 0.1  # a pose reveals its map where it compresses this share of its strongest
PLACED_GAIN = 1.8  # a frown's glabellar lines, the deepest an artist paints, this much deeper
PLACED_SHARPNESS = 1.0  # … and as wide as their spacing: a few close lines, no flat between
FOLD_SHARPNESS = 2.0  # a fold's walls ease into the skin beside it: no rim where they end
BARE_SOFTNESS = 0.006  # of the map's size: the soft edge where furrows give way to bare skin
MOVED_SHARE = 0.2  # … and where it moves the skin by this share of its largest motion
PLACED_WINDOW = 0.05  # anatomy's lines reach the vertices where their window is this much …
PLACED_SHARE = 0.3  # … and the pose compresses the skin by this share of its strongest there
WINDOW_RINGS = 3  # the pose wrinkles this many triangles around the window, its mask's edge
FOLD_RINGS = 2  # a fold's vertices: this many triangles around those it lies on, not cut by
# their edges where the fold is only a few triangles wide
MAX_POSE_WORKERS = 4  # threads synthesising poses at once (memory grows with them)


@dataclass
class SynthOptions:
    size: int = 1024  # of the map, texels
    spacing: float = 12.0  # texels between neighbouring furrows
    depth: float = 1.5  # of a furrow at full compression, texels (slopes are true to this)
    full_at: float = DEFAULT_FULL_AT  # compression at which furrows reach their full depth
    smoothing: float | None = None  # of the strain fields, texels; None: 1.5 × spacing

    def check(self) -> None:
        if not 16 <= self.size <= 8192:
            raise StudioError(f"the map size must be between 16 and 8192 texels, not {self.size}")
        if not 2.0 <= self.spacing <= self.size / 2:
            raise StudioError(f"the furrow spacing must be between 2 and {self.size // 2} texels,"
                              f" not {self.spacing:g}")
        if not self.depth > 0.0:
            raise StudioError(f"the furrow depth must be positive, not {self.depth:g}")


@dataclass
class SynthResult:
    height: Array  # (N, N) float32, texels, ≤ 0: the furrows
    normal: Array  # (N, N, 3) uint8 or uint16, tangent space, OpenGL convention


# --- rasterising onto the UV layout -------------------------------------------------------------

class UvRaster:
    """Which triangle, and where in it, each texel centre of a square UV image lies: found once
    (``mask_ops.rasterise_uv`` of the triangle index and two barycentric coordinates), so that
    per-vertex values of many poses become images by a gather instead of a rasterisation each.
    Where UV triangles overlap, the one drawn last wins, as in ``rasterise_uv``."""

    def __init__(self, mesh: FaceMesh, size: int) -> None:
        self.size = size
        n = mesh.n_triangles
        corners = mesh.uvs[mesh.triangles].reshape(-1, 2)  # each triangle's own three corners
        flat = np.arange(3 * n).reshape(n, 3)

        def draw(per_corner: Array) -> tuple[Array, Array]:
            return mask_ops.rasterise_uv(corners, flat, per_corner.astype(np.float32), size)

        ids, covered = draw(np.repeat(np.arange(1, n + 1, dtype=np.float64), 3))
        w0, _ = draw(np.tile([1.0, 0.0, 0.0], n))
        w1, _ = draw(np.tile([0.0, 1.0, 0.0], n))
        self.texels = np.flatnonzero(covered)  # flat indices of covered texels
        self.triangle = np.full((size, size), -1, np.int64)  # -1: no triangle there
        self.triangle.ravel()[self.texels] = np.rint(ids.ravel()[self.texels]).astype(np.int64) - 1
        self.corners = mesh.triangles[self.triangle.ravel()[self.texels]]  # (n, 3) render verts
        a, b = w0.ravel()[self.texels], w1.ravel()[self.texels]
        self.weights = np.stack([a, b, 1.0 - a - b], axis=1).astype(np.float32)

    def image(self, values: Array) -> Array:
        """(size, size) float32: per-render-vertex values interpolated, 0 off the layout."""
        out = np.zeros(self.size * self.size, np.float32)
        out[self.texels] = np.einsum("ij,ij->i", self.weights,
                                     np.asarray(values, np.float32)[self.corners])
        return out.reshape(self.size, self.size)


# --- 1. strain per triangle: studio.core.wrinkles.skin_strain ---------------------------------

# --- 2. fields on the UV layout ------------------------------------------------------------------

def _smooth_signed(values: Array, radius: float) -> Array:
    """Blur values in [−1, 1] with the masks' blur (which clips to [0, 1]): it is linear, so
    shifting into [0, 1] and back loses nothing."""
    return mask_ops.blur((values + 1.0) * 0.5, radius) * 2.0 - 1.0


@dataclass
class FurrowField:
    """Where one pose makes furrows, at the map's size, on the texels it touches only."""

    index: Array  # (n,) flat texel indices
    amount: Array  # (n,) furrow strength in (0, 1]
    angle: Array  # (n,) the wave vector's orientation, degrees in [0, 180)
    phase: Array  # (n,) radians: a furrow's bottom wherever it is a multiple of 2π
    # flat texel indices the pose reveals with no furrow of its own: skin it compresses or
    # moves where its furrows faded (or, for a frown, outside the glabella). A map shared with
    # a pose whose furrows lie there would show them in this pose's expression.
    bare: Array | None = None
    gain: float = 1.0  # depth relative to the map's: anatomy's signature lines run deeper …
    sharpness: float = SHARPNESS  # … and wider, their walls spanning the whole spacing
    placed: bool = False  # lines anatomy placed (``vertex_lines``)

    variation: Array | None = None  # (n,) depth along the furrows: ``surface_noise``

    def depth(self) -> Array:
        """Each texel's furrow height in depth units: positive down a furrow (1 at the bottom
        of the deepest at full strength), slightly negative on the skin bunched between
        furrows (``furrow_profile``). Its amount (already grown from the compression,
        ``grown_depth``) times the profile, deepest at the most compressed furrow and
        shallower the further a furrow lies from it (by ``FURROWS_EACH_SIDE`` furrows, a
        third as deep), deepening and fading along its length (``variation``)."""
        reach = np.float32(2.0 * np.pi * FURROWS_EACH_SIDE)
        falloff = np.exp(-(self.phase / reach) ** 2)
        vary = 1.0 if self.variation is None else self.variation
        return (self.gain * self.amount * falloff * vary
                * furrow_profile(self.phase, self.sharpness)).astype(np.float32)


def grown_depth(strength: Array, threshold: float) -> Array:
    """A furrow's depth from its strength (compression relative to full, in [0, 1]): nothing
    up to ``threshold``, then growing as the square root of the excess — as thin skin on
    soft tissue buckles — eased in over its first ``GROW_SOFT`` so a line's ends taper to
    nothing instead of starting at a step."""
    excess = np.clip((strength - threshold) / (1.0 - threshold), 0.0, 1.0)
    ease = np.clip(excess / GROW_SOFT, 0.0, 1.0)
    return (np.sqrt(excess) * ease * ease * (3.0 - 2.0 * ease)).astype(np.float32)


def pose_full_at(compression: Array, full_at: float) -> float:
    """The compression at which a pose's furrows reach full depth: ``full_at``, or less for a
    pose whose strong compression (the 98th percentile over compressed skin) stays below it —
    so every pose that wrinkles at all shows clear furrows at full weight, the way an artist's
    wrinkle map would, instead of faint ones for a face whose poses are subtle."""
    compressed = compression[compression >= WRINKLING_COMPRESSION]
    if compressed.size == 0:
        return full_at
    return float(min(full_at, max(PEAK_SHARE * np.percentile(compressed, 98),
                                  WRINKLING_COMPRESSION)))


def furrow_field(strain: TriangleStrain, ids: Array, skin: Array, size: int,
                 full_at: float, smoothing: float, spacing: float,
                 placed: tuple[Array, Array, float, bool] | None = None,
                 moved: Array | None = None, keep: Array | None = None,
                 area: Array | None = None) -> FurrowField:
    """Rasterise and smooth one pose's compression and direction fields, lay furrows across
    the direction (``furrow_phase``) and upsample to the map's size. ``placed``: a window and
    a phase at the work size that anatomy gives this pose's lines (a frown's, between the
    brows; a squint's crow's feet; a smile's nasolabial fold) and their depth relative to
    ``PLACED_GAIN``, and whether the pose's compression gates them texel by texel: the furrows
    then lie where the window and the pose's compression meet (or, ungated, where the window
    says: a fold's depth along it is the compression's already), along that phase. ``moved``: a
    work-size image of the pose's motion as a share of its largest: its technique-2 vectors
    reveal the map from ``MOVED_SHARE`` on. ``keep``:
    a work-size image in [0, 1], where on the face furrows may lie at all. ``area``: for
    placed lines, a work-size image of the pose's technique-2 area (its vertices 1, the rest
    0, interpolated over the triangles as the vertex shader does): the lines end inside it."""
    work = ids.shape[0]
    covered = ids >= 0
    tri = np.where(covered, ids, 0)
    compression = strain.compression * skin
    weight = np.minimum(compression, strain.anisotropy)  # no direction without anisotropy
    cos2 = strain.wave[:, 0] ** 2 - strain.wave[:, 1] ** 2
    sin2 = 2.0 * strain.wave[:, 0] * strain.wave[:, 1]
    radius = smoothing * work / size
    full_at = pose_full_at(compression, full_at)
    compressed = compression[compression >= WRINKLING_COMPRESSION]
    strong = float(np.percentile(compressed, 98)) if compressed.size else 1.0

    def layer(per_triangle: Array) -> Array:
        return np.where(covered, per_triangle[tri], 0.0).astype(np.float32)

    amount = mask_ops.blur(layer(compression), radius)
    full_at = min(full_at, max(SMOOTH_PEAK_SHARE * float(amount.max(initial=0.0)),
                               WRINKLING_COMPRESSION))
    total = mask_ops.blur(np.clip(layer(weight), 0.0, 1.0), radius)
    c = _smooth_signed(layer(np.clip(weight, 0.0, 1.0) * cos2), radius)
    s = _smooth_signed(layer(np.clip(weight, 0.0, 1.0) * sin2), radius)
    coherence = np.clip(np.hypot(c, s) / np.maximum(total, 1e-6), 0.0, 1.0)
    strength = np.clip(amount / max(full_at, 1e-6), 0.0, 1.0) * coherence
    if keep is not None:
        strength = strength * keep
    lines = None  # where the pose's lines may lie: anywhere it compresses, unless placed
    if placed is not None:
        strength, phase, c, s = _placed_furrows(amount, _fill_outside(placed[1], covered),
                                                placed[0])
        lines = _Upsampled(placed[0] > 0.0, size).index(placed[0], 1e-3)
        # a fold's window carries its depth along it, from the pose's compression: gated
        # again texel by texel, its edge would follow the compression's patchy border
        strength = strength * placed[0] if placed[3] else placed[0].astype(np.float32)
        if area is not None:  # ending inside the technique-2 area, not cut by its triangles
            inside = np.clip(2.0 * mask_ops.blur(area, 0.5 * radius) - 1.0, 0.0, 1.0)
            strength = strength * inside * inside * (3.0 - 2.0 * inside)
    else:
        angle = np.mod(0.5 * np.arctan2(s, c), np.pi)
        phase, straight = furrow_phase(strength, angle, 2.0 * np.pi * size / (work * spacing))
        # furrows only inside the regions the phase was laid out on, fading in from their edge
        strength = grown_depth(strength, FURROW_THRESHOLD) * straight
    # at the map's size only around the texels the pose wrinkles (``_Upsampled``)
    up = _Upsampled(strength > 0.0, size)
    index, amount_up = up.index(strength, 1e-3, values_too=True)
    c_up = up.values((c + 1.0) * 0.5, index) * 2.0 - 1.0
    s_up = up.values((s + 1.0) * 0.5, index) * 2.0 - 1.0
    degrees = np.degrees(np.mod(0.5 * np.arctan2(s_up, c_up), np.pi))
    lo, hi = float(phase.min()), float(phase.max())  # as ``_resample_unbounded``
    span = hi - lo or 1.0
    phase_up = up.values((phase - lo) / span, index) * span + lo
    # what the pose reveals: where it compresses the skin by a tenth of its strong compression
    # (as its technique-1 mask), or where anatomy placed its lines
    reveals = amount >= max(REVEAL_SHARE * strong, WRINKLING_COMPRESSION)
    if moved is not None:
        reveals = reveals | (moved >= MOVED_SHARE)
    revealed = _Upsampled(reveals, size).index(reveals.astype(np.float32), 0.5, strict=False)
    lines = index if lines is None else lines
    return FurrowField(index, amount_up, degrees.astype(np.float32), phase_up,
                       np.setdiff1d(revealed, lines, assume_unique=True),
                       *((1.0, SHARPNESS, False) if placed is None
                         else (PLACED_GAIN * placed[2],
                               PLACED_SHARPNESS if placed[3] else FOLD_SHARPNESS, True)))


class _Upsampled:
    """Work-size images brought to the map's size (``mask_ops.resample``'s bilinear filter)
    over the box of map texels around ``within`` (work texels) only: a pose wrinkles a small
    part of the face, and upsampling all of a 2048-texel map for it, five images a pose, took
    most of the synthesis's time and a map's memory per image. The box is widened by the
    filter's reach, so its texels are those of the whole image upsampled."""

    def __init__(self, within: Array, size: int) -> None:
        self.work, self.size = within.shape[0], size
        rows, cols = np.nonzero(within)
        scale = size / self.work
        if rows.size == 0:
            self.box = (0, 0, 0, 0)
            return
        self.box = (max(int(np.floor((cols.min() - 1) * scale)), 0),
                    max(int(np.floor((rows.min() - 1) * scale)), 0),
                    min(int(np.ceil((cols.max() + 2) * scale)), size),
                    min(int(np.ceil((rows.max() + 2) * scale)), size))

    def image(self, values: Array) -> Array:
        """The box of ``values`` (a work-size image in [0, 1]) at the map's size."""
        c0, r0, c1, r1 = self.box
        if c1 <= c0 or r1 <= r0:
            return np.zeros((0, 0), np.float32)
        if self.work == self.size:
            return np.asarray(values, np.float32)[r0:r1, c0:c1].copy()
        k = self.work / self.size
        image = Image.fromarray(np.ascontiguousarray(values, dtype=np.float32), mode="F")
        box = image.resize((c1 - c0, r1 - r0), Image.Resampling.BILINEAR,
                           box=(c0 * k, r0 * k, c1 * k, r1 * k))
        return np.clip(np.asarray(box, dtype=np.float32), 0.0, 1.0)

    def index(self, values: Array, above: float, values_too: bool = False,
              strict: bool = True) -> Array | tuple[Array, Array]:
        """Flat map indices (ascending) of the texels whose upsampled value is above
        ``above`` (``strict`` False: at least), and with ``values_too`` their values."""
        image = self.image(values)
        local = np.flatnonzero(image > above if strict else image >= above)
        index = self._flat(local, image.shape[1])
        return (index, image.ravel()[local]) if values_too else index

    def values(self, values: Array, index: Array) -> Array:
        """The upsampled ``values`` (work-size, in [0, 1]) at flat map indices in the box."""
        c0, r0 = self.box[:2]
        rows, cols = np.divmod(index, self.size)
        return self.image(values)[rows - r0, cols - c0]

    def _flat(self, local: Array, width: int) -> Array:
        c0, r0 = self.box[:2]
        rows, cols = np.divmod(local, max(width, 1))
        return ((rows + r0) * self.size + cols + c0).astype(np.int64)


def _fill_outside(values: Array, covered: Array, passes: int = 4) -> Array:
    """``values`` with the texels off the UV layout (not ``covered``) within ``passes`` texels
    of it given the mean of their covered (or filled) neighbours: resampled to the map's size,
    a phase must not mix with the meaningless values of a hole in the layout (the mouth's
    corner) — it would draw a furrow's bottom along the hole's edge."""
    out = np.where(covered, values, 0.0).astype(np.float64)
    known = covered.astype(np.float64)
    for _ in range(passes):
        total = np.zeros_like(out)
        count = np.zeros_like(out)
        for axis in (0, 1):
            for step in (1, -1):
                total += np.roll(out * known, step, axis)
                count += np.roll(known, step, axis)
        fill = (known == 0.0) & (count > 0.0)
        out = np.where(fill, total / np.maximum(count, 1.0), out)
        known = np.where(fill, 1.0, known)
    return out.astype(np.float32)


def _placed_furrows(amount: Array, phase: Array, window: Array
                    ) -> tuple[Array, Array, Array, Array]:
    """Strength, phase and doubled-angle direction (cos 2θ, sin 2θ) of furrows whose place
    and direction anatomy gives (``phase``): grown (``grown_depth``) from the pose's smoothed
    compression relative to its strong compression inside the lines' ``window`` (the 98th
    percentile), from ``PLACED_SHARE`` of it on: a pose's signature lines show however
    gently the rig squeezes that spot, deepest where it squeezes most, on the side a
    one-sided pose pulls (the other side of a brow lowerer is squeezed a quarter as much),
    tapering where its squeeze fades — across the phase's gradient."""
    inside = amount[window > PLACED_WINDOW]
    strong = max(float(np.percentile(inside, 98)) if inside.size else 0.0,
                 WRINKLING_COMPRESSION)
    strength = grown_depth(np.clip(amount / strong, 0.0, 1.0), PLACED_SHARE)
    gy, gx = np.gradient(phase.astype(np.float64))
    norm = np.maximum(gx * gx + gy * gy, 1e-12)
    c = ((gx * gx - gy * gy) / norm).astype(np.float32)
    s = (2.0 * gx * gy / norm).astype(np.float32)
    return strength, phase.astype(np.float32), c, s


# --- 3. furrows: a phase whose gradient is the wave vector ---------------------------------------

def _resample_unbounded(values: Array, size: int) -> Array:
    """``mask_ops.resample`` for values outside [0, 1] (a phase): scaled in and out."""
    lo, hi = float(values.min()), float(values.max())
    span = hi - lo or 1.0
    return mask_ops.resample((values - lo) / span, size) * span + lo


def label_regions(inside: Array) -> Array:
    """Connected (4-neighbour) regions of a bool image: each texel's label is the smallest flat
    index in its region, −1 outside. Labels spread to neighbours and jump along the chain of
    labels (pointer jumping), so it takes a few dozen vectorised passes, not one per texel."""
    h, w = inside.shape
    label = np.where(inside.ravel(), np.arange(h * w), h * w)
    big = h * w
    while True:
        grid = label.reshape(h, w)
        low = grid.copy()
        low[1:] = np.minimum(low[1:], np.where(inside[:-1], grid[:-1], big))
        low[:-1] = np.minimum(low[:-1], np.where(inside[1:], grid[1:], big))
        low[:, 1:] = np.minimum(low[:, 1:], np.where(inside[:, :-1], grid[:, :-1], big))
        low[:, :-1] = np.minimum(low[:, :-1], np.where(inside[:, 1:], grid[:, 1:], big))
        low = np.where(inside, low, big).ravel()
        here = low < big
        low[here] = np.minimum(low[here], low[low[here]])  # jump: my label's label
        if np.array_equal(low, label):
            return np.where(here, low, -1).reshape(h, w)
        label = low


def _oriented(inside: Array, on: Array, theta: Array, weight: Array, start: Array,
              passes: int = ORIENT_PASSES) -> Array:
    """±1 per texel of ``on``: which way along its line direction ``theta`` each texel's wave
    vector points, so that neighbours agree. Starts from ``start`` (agreement with the
    region's mean direction) and lets each texel follow the weighted mean of its
    neighbourhood's oriented vectors, a few times: a direction field that turns by more than
    a right angle across a region — a fan — stays oriented alike along the turn."""
    shape = inside.shape
    sign = np.where(start, 1.0, -1.0)
    cos, sin = np.cos(theta) * weight, np.sin(theta) * weight
    for _ in range(passes):
        vx = np.zeros(inside.size, np.float32)
        vy = np.zeros(inside.size, np.float32)
        vx[on], vy[on] = sign * cos, sign * sin
        # the blur clips to [0, 1]: shift the signed components in and out
        ax = _smooth_signed(vx.reshape(shape), ORIENT_RADIUS).ravel()[on]
        ay = _smooth_signed(vy.reshape(shape), ORIENT_RADIUS).ravel()[on]
        follow = ax * np.cos(theta) + ay * np.sin(theta)
        sign = np.where(np.abs(follow) > 1e-6, np.sign(follow), sign)
    return sign


def _potential(fx: Array, fy: Array) -> Array:
    """φ whose gradient is closest to the vector field (fx, fy) in least squares: the Poisson
    equation ∇²φ = ∇·f solved spectrally on a grid twice the size (zero beyond: no wrap)."""
    h, w = fx.shape
    ky = 2.0 * np.pi * np.fft.fftfreq(2 * h)[:, None]
    kx = 2.0 * np.pi * np.fft.rfftfreq(2 * w)[None, :]
    gx = np.fft.rfft2(fx, (2 * h, 2 * w))
    gy = np.fft.rfft2(fy, (2 * h, 2 * w))
    k2 = kx * kx + ky * ky
    k2[0, 0] = 1.0
    phi = np.fft.irfft2(-1j * (kx * gx + ky * gy) / k2, (2 * h, 2 * w))
    return phi[:h, :w].astype(np.float32)


def furrow_phase(strength: Array, angle: Array, wavenumber: float,
                 threshold: float = FURROW_THRESHOLD) -> tuple[Array, Array]:
    """(H, W) radians: a smooth phase that advances ``wavenumber`` per texel along the wave
    direction (across the furrows), so its valleys are few, long, parallel furrows that follow
    the skin's direction of compression — bending where it bends, fanning where it fans — with
    no breaks, rings or crossings. Per connected region of strength ≥ ``threshold``: the
    directions (lines, ±) are oriented alike (against the region's mean direction), the phase
    is the least-squares potential of that wave field, and it is shifted so that a furrow's
    bottom lies where the region is compressed most: a band narrower than the spacing — a
    nasolabial fold — gets one furrow along its middle. Also returns ``_straightness``."""
    inside = strength >= threshold
    labels = label_regions(inside)
    if not inside.any():
        return np.zeros(strength.shape, np.float32), np.ones(strength.shape, np.float32)
    flat = labels.ravel()
    on = np.flatnonzero(flat >= 0)
    region = flat[on]
    weight = strength.ravel()[on].astype(np.float64)
    doubled = 2.0 * angle.ravel()[on].astype(np.float64)
    _, which = np.unique(region, return_inverse=True)
    mean_c = np.bincount(which, weight * np.cos(doubled))
    mean_s = np.bincount(which, weight * np.sin(doubled))
    reference = 0.5 * np.arctan2(mean_s, mean_c)[which]
    theta = angle.ravel()[on].astype(np.float64)
    sign = _oriented(inside, on, theta, weight, np.cos(theta - reference) >= 0.0)
    gain = np.clip(strength.ravel()[on] / (3.0 * threshold), 0.0, 1.0)  # fade at the edges
    fx = np.zeros(strength.size)
    fy = np.zeros(strength.size)
    fx[on] = wavenumber * sign * gain * np.cos(theta)
    fy[on] = wavenumber * sign * gain * np.sin(theta)
    phase = _potential(fx.reshape(strength.shape), fy.reshape(strength.shape))
    # The potential of a field that stops at a region's edge is flatter than the field (most
    # where the region is short across the furrows): each region's phase is scaled back to
    # the wavenumber over its core, so the spacing is the one asked for.
    slope = np.hypot(*np.gradient(phase)).ravel()[on]
    core = gain >= 1.0
    typical = np.bincount(which[core], slope[core], minlength=len(mean_c)) / np.maximum(
        np.bincount(which[core], minlength=len(mean_c)), 1)
    # a small region (an eye's corner) gets finer furrows, so it holds a few of them too
    across = np.sqrt(np.bincount(which, minlength=len(mean_c)))  # texels, for its area
    wanted = np.clip(2.0 * np.pi * FURROWS_ACROSS / np.maximum(across, 1.0), wavenumber,
                     MAX_FINER * wavenumber)
    scale = np.clip(wanted / np.maximum(typical, 1e-9), 1.0, MAX_FINER * MAX_PHASE_GAIN)
    phase = phase.ravel()
    # shift each region so that its most compressed texel lies at a furrow's bottom
    order = np.lexsort((-weight, which))
    first = np.r_[0, np.flatnonzero(np.diff(which[order])) + 1]
    peak_phase = phase[on[order[first]]]
    out = np.zeros(strength.size, np.float32)
    out[on] = (phase[on] - peak_phase[which]) * scale[which]
    return out.reshape(strength.shape), _straightness(angle, wavenumber)


def _straightness(angle: Array, wavenumber: float) -> Array:
    """(H, W) in [0, 1]: 0 where furrows would curl into rings tighter than ``RING_SPACINGS``
    spacings across. A furrow's curvature is the turn of the wave direction θ along the furrow,
    |t · ∇θ| with t = (−sin θ, cos θ): 1/r for rings of radius r around a point the skin is
    squeezed toward, 0 for parallel lines and for a fan whose furrows radiate from a corner.
    Measured on the doubled angle, so it needs no orientation; skin does not crease in small
    rings."""
    c = _smooth_signed(np.cos(2.0 * angle), ORIENT_RADIUS)
    s = _smooth_signed(np.sin(2.0 * angle), ORIENT_RADIUS)
    norm = np.maximum(c * c + s * s, 1e-6)
    turn_x = (c * np.gradient(s, axis=1) - s * np.gradient(c, axis=1)) / norm
    turn_y = (c * np.gradient(s, axis=0) - s * np.gradient(c, axis=0)) / norm
    theta = 0.5 * np.arctan2(s, c)
    curvature = 0.5 * np.abs(-np.sin(theta) * turn_x + np.cos(theta) * turn_y)
    radius_in_spacings = wavenumber / (2.0 * np.pi * np.maximum(curvature, 1e-9))
    straight = np.clip(radius_in_spacings / RING_SPACINGS - 1.0, 0.0, 1.0)
    return np.where(norm > 0.01, straight, 0.0).astype(np.float32)  # no direction: no furrow


def furrow_profile(phase: Array, sharpness: float = SHARPNESS) -> Array:
    """A furrow's cross-section: the ``valley`` (1 at its bottom), less a soft rise of
    ``BUNCH`` midway between furrows, where compressed skin bunches up."""
    ridge = ((1.0 - np.cos(phase)) * 0.5) ** 4
    return valley(phase, sharpness) - BUNCH * ridge


def valley(phase: Array, sharpness: float = SHARPNESS) -> Array:
    """1 at the bottom of a furrow (phase 0), falling to 0 between furrows; even in the phase,
    so a field and its conjugate (the same orientation turned by 180°) give the same furrows."""
    return ((1.0 + np.cos(phase)) * 0.5) ** sharpness


def furrow_depths(fields: Sequence[FurrowField], size: int,
                  groups: Sequence[Sequence[int]] | None = None) -> Array | list[Array]:
    """(size, size) max over poses of amount × valley(phase). With ``groups`` (lists of field
    indices), one such image per group, where each pose's furrows give way, with a soft edge,
    to the skin another pose of its group reveals bare (``FurrowField.bare``): past the
    shader's four maps crossing poses share one, and a frown must not show a sneer's folds."""
    images = []
    for group in (groups if groups is not None else [range(len(fields))]):
        depth = np.zeros(size * size, np.float32)  # the deepest furrow over each texel …
        bunched = np.zeros(size * size, np.float32)  # … and the skin most bunched there
        bare = [_bare_image(fields[i], size) for i in group] if groups is not None else []
        for k, i in enumerate(group):
            index = fields[i].index  # each texel once: no ``ufunc.at`` needed
            furrows = fields[i].depth()
            # anatomy's lines give way to other poses' bare skin, but not to that of other
            # placed lines: those reveal all the skin they move around their small window (a
            # cheek squint the whole cheek, a mouth frown the mouth's corner), and would erase
            # the smile's fold where past the shader's four maps they share one
            others = [image for j, image in enumerate(bare) if j != k and image is not None
                      and not (fields[i].placed and fields[group[j]].placed)]
            if others:
                revealed = sum(image.at(index, size) for image in others)
                furrows = furrows * (1.0 - np.clip(revealed, 0.0, 1.0))
            depth[index] = np.maximum(depth[index], furrows)
            bunched[index] = np.minimum(bunched[index], furrows)
        images.append((depth + bunched).reshape(size, size))
    return images if groups is not None else images[0]


def controlled(fields: Sequence[FurrowField], controls: Sequence[FurrowControls]
               ) -> list[FurrowField]:
    """The fields with each pose's depth and sharpness factors (``FurrowControls``): what
    the controls change without laying the furrows out again (copies; the fields stay)."""
    return [replace(f, gain=f.gain * c.depth, sharpness=f.sharpness * c.sharpness)
            for f, c in zip(fields, controls, strict=True)]


def grouped_maps(fields: Sequence[FurrowField], controls: Sequence[FurrowControls],
                 options: SynthOptions, groups: Sequence[Sequence[int]], neutral: Array,
                 over_neutral: bool = True) -> list[Array]:
    """A wrinkled map per group of fields, over the neutral map (unless ``over_neutral`` is
    False), each pose's furrows as its controls shape them: what ``fill_placeholder`` and the
    Synthesise dialog make, and ``furrow_maps`` makes again when a control changes."""
    depths = furrow_depths(controlled(fields, controls), options.size, groups)
    return [height_to_map((-options.depth * depth).astype(np.float32), neutral, over_neutral)
            for depth in depths]


@dataclass
class _BareImage:
    """The skin a pose reveals bare, in [0, 1], over the box of the map it reaches only:
    a whole map's image per pose made the memory grow with the map times the poses."""

    image: Array  # (h, w) float32
    row: int  # the box's top left texel in the map
    col: int

    def at(self, index: Array, size: int) -> Array:
        """Its values at flat map indices, 0 outside its box."""
        rows, cols = np.divmod(index, size)
        rows, cols = rows - self.row, cols - self.col
        h, w = self.image.shape
        inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
        out = np.zeros(len(index), np.float32)
        out[inside] = self.image[rows[inside], cols[inside]]
        return out


def _bare_image(field: FurrowField, size: int) -> _BareImage | None:
    """The skin a pose reveals bare, its edge softened over a furrow spacing or so
    (``BARE_SOFTNESS`` of the map) so that furrows giving way to it fade."""
    if field.bare is None or field.bare.size == 0:
        return None
    rows, cols = np.divmod(field.bare, size)
    # blurred around the bare skin only, as far out as the blur reaches (three box passes of
    # its half-width): the same image, at a fraction of the cost of the whole map's
    # (the ICT head's 53 poses: 13.8 of a 33 s set-up)
    reach = 3 * max(round(BARE_SOFTNESS * size / 2.0), 0) + 1
    r0, r1 = max(int(rows.min()) - reach, 0), min(int(rows.max()) + reach + 1, size)
    c0, c1 = max(int(cols.min()) - reach, 0), min(int(cols.max()) + reach + 1, size)
    image = np.zeros((r1 - r0, c1 - c0), np.float32)
    image[rows - r0, cols - c0] = 1.0
    return _BareImage(mask_ops.blur(image, BARE_SOFTNESS * size), r0, c0)


# --- 4. the map ----------------------------------------------------------------------------------

def _encode(normals: Array, dtype: type) -> Array:
    top = np.iinfo(dtype).max
    return np.clip(np.floor((normals * 0.5 + 0.5) * top + 0.5), 0, top).astype(dtype)


def over_base(detail: Array, base: Array) -> Array:
    """The furrows' normals added to a base normal map's surface (reoriented normal mapping,
    Barré-Brisebois and Hill 2012: the furrows' normal rotated as the base turns the flat
    surface, ``t·(t·u)/t.z − u`` with ``t = b + (0, 0, 1)``, ``u = d·(−1, −1, 1)``) — a head's
    own pores and painted detail keep their shape inside a furrow; texels the furrows leave
    flat keep the base's exact values."""
    if base.shape[:2] != detail.shape[:2]:
        base = resize_nearest(base, *detail.shape[:2])
    out = base.astype(detail.dtype) if base.dtype == detail.dtype else _encode(
        to_unit_float(base) * 2.0 - 1.0, detail.dtype)
    flat_xy = np.iinfo(detail.dtype).max // 2 + 1
    touched = np.any(detail[..., :2] != flat_xy, axis=-1)
    d = to_unit_float(detail[touched]) * 2.0 - 1.0
    b = to_unit_float(out[touched]) * 2.0 - 1.0
    t = b + np.array([0.0, 0.0, 1.0], np.float32)
    u = d * np.array([-1.0, -1.0, 1.0], np.float32)
    n = t * (np.sum(t * u, axis=1) / np.maximum(t[:, 2], 1e-6))[:, None] - u
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    out[touched] = _encode(n, detail.dtype)
    return out


def furrow_fields(mesh: FaceMesh, targets: Sequence[Array], options: SynthOptions,
                  skin: Array | None = None, progress: Progress | None = None,
                  total: int = 0, places: FacePlaces | None = None,
                  spacings: Sequence[float] | None = None) -> list[FurrowField] | None:
    """Each pose's furrow field at the map's size; None if ``progress`` stopped. With
    ``places`` (where each vertex is on the face), a pose that lowers a brow gets its lines
    between the brows (``anatomy.glabella``). ``spacings``: a factor per target on the
    furrows' spacing (``FurrowControls.spacing``), for the lines the strain lays out and
    those anatomy places alike; the strain's smoothing and the noise along the lines keep
    the options' spacing, so only the lines' count changes, not where they lie."""
    options.check()
    size = options.size
    work = min(size, work_size(mesh))
    raster = UvRaster(mesh, work)
    ids = raster.triangle
    uv_strain = UvStrain(mesh)
    skin_tri = (np.ones(mesh.n_triangles, np.float32) if skin is None
                else np.asarray(skin, np.float32)[mesh.welded_triangles].min(axis=1))
    smoothing = 1.5 * options.spacing if options.smoothing is None else options.smoothing
    face_xyz = keep = None
    if places is not None:
        face_xyz = [raster.image(places.xyz[mesh.weld, k]) for k in (0, 1, 2)]
        keep = anatomy.on_face(raster.image(places.box_y[mesh.weld]))
    (vary, wiggle), placed_variation = _surface_variation(mesh, raster, skin, options)

    def one(i: int, target: Array) -> FurrowField:
        strain = uv_strain.of(target)
        motion = np.linalg.norm(np.asarray(target, np.float64) - mesh.rest, axis=1)
        if skin is not None:
            motion = motion * (np.asarray(skin) > 0)
        share = motion / max(float(motion.max()), 1e-300)
        moved = raster.image(share[mesh.weld])
        placed = area = lines = None
        if places is not None and face_xyz is not None:
            lines = vertex_lines(places, mesh, target, strain.compression * skin_tri)
        factor = 1.0 if spacings is None else float(spacings[i])
        if lines is not None and places is not None and face_xyz is not None:
            window, phase = lines.place(*face_xyz)
            placed = (np.where(ids >= 0, window, 0.0), phase / factor, lines.gain, lines.gated)
            area = raster.image(((share > MOVED_SHARE) | lines.region
                                 ).astype(np.float32)[mesh.weld])
        field = furrow_field(strain, ids, skin_tri, size, options.full_at, smoothing,
                             options.spacing * factor, placed, moved, keep, area)
        depth, wander = placed_variation if field.placed else (vary, wiggle)
        field.variation = depth.ravel()[field.index]
        field.phase = field.phase + wander.ravel()[field.index]
        return field

    # the poses are independent: on all the cores (numpy and PIL let go of the interpreter
    # while they work), reported and cancelled here, in the caller's thread, in pose order
    fields = []
    with ThreadPoolExecutor(pose_workers()) as pool:
        for i, field in enumerate(pool.map(one, range(len(targets)), targets)):
            fields.append(field)
            if progress is not None and not progress(i + 1, total or len(targets)):
                pool.shutdown(cancel_futures=True)  # the poses begun finish; no more begin
                return None
    return fields


def pose_workers() -> int:
    """Threads for the poses' fields: the cores this process may use, at most
    ``MAX_POSE_WORKERS`` (each holds a pose's work-size images and its Poisson grid)."""
    return usable_cores(MAX_POSE_WORKERS)


def _surface_variation(mesh: FaceMesh, raster: UvRaster, skin: Array | None,
                       options: SynthOptions) -> tuple[tuple[Array, Array], tuple[Array, Array]]:
    """(size, size) each, for the lines the strain lays out and for those anatomy places:
    how deep furrows run along their length (a share of their depth, between ``1 −
    VARY_DEPTH`` and 1: never deeper than asked) and how far their phase wanders (radians,
    about ``WIGGLE``), from noise on the surface (``surface_noise``) at the work size's
    texels' 3-D points — continuous across UV charts — over a few furrow spacings
    (``options.spacing`` on the surface). Anatomy's lines vary less and more slowly
    (``PLACED_VARY``): each is one stroke whose course anatomy gives."""
    density = texels_per_unit(mesh, skin, options.size) or float(options.size)
    spacing = options.spacing / density
    xyz = np.stack([raster.image(mesh.rest[mesh.weld, k]) for k in (0, 1, 2)], axis=-1)
    def variation(depth: float, depth_spacings: float, wiggle: float, wiggle_spacings: float
                  ) -> tuple[Array, Array]:
        low = 0.5 * (1.0 - np.tanh(surface_noise(xyz, depth_spacings * spacing)))
        wander = wiggle * surface_noise(xyz, wiggle_spacings * spacing, 1)
        return (_resample_unbounded(1.0 - depth * low, options.size).astype(np.float32),
                _resample_unbounded(wander, options.size).astype(np.float32))

    return (variation(VARY_DEPTH, VARY_SPACINGS, WIGGLE, WIGGLE_SPACINGS),
            variation(*PLACED_VARY))


def _grown(vertices: Array, triangles: Array, rings: int) -> Array:
    """(W,) bool: ``vertices`` and those ``rings`` triangles away from them."""
    grown = np.asarray(vertices, bool)
    for _ in range(rings):
        touched = grown[triangles].any(axis=1)
        grown = grown | (np.bincount(triangles[touched].ravel(), minlength=len(grown)) > 0)
    return grown


@dataclass
class VertexLines:
    """Lines anatomy places for one pose, per welded vertex."""

    # (window, phase) from images (or arrays) of face x, y and z: ``anatomy.glabella``,
    # ``anatomy.crows_feet`` or ``anatomy.fold`` for this head and pose
    place: Callable[[Array, Array, Array], tuple[Array, Array]]
    window: Array  # (W,) float: where anatomy lets its lines lie (``place``'s window)
    region: Array  # (W,) bool: the vertices they lie on (``placed_region``)
    gain: float = 1.0  # their depth, relative to a frown's lines (``PLACED_GAIN``)
    gated: bool = True  # the pose's compression texel by texel limits them (a fold's window
    # already holds its depth, from the compression along it)


def vertex_lines(places: FacePlaces, mesh: FaceMesh, target: Array, squeezed: Array
                 ) -> VertexLines | None:
    """The lines anatomy places for a pose that lowers a brow (a frown's, between the brows),
    squints (crow's feet at the outer corner of the eye), smiles (a nasolabial fold and the
    cheek bunching under the eye), pulls the mouth corner down (a marionette line), sneers
    (bunny lines on the side of the nose), purses the lips (short lines standing on their
    border: ``anatomy_lips``) or pushes the chin up (a crease under the lower lip:
    ``anatomy_lower``), from its
    compression on the skin per triangle (``squeezed``); None for any other pose. Per vertex
    only, so the set-up can find them without synthesising a map: the map's furrows and the
    areas that reveal them come from this one place."""
    corners = mesh.welded_triangles.ravel()
    total = np.bincount(corners, np.repeat(np.asarray(squeezed, np.float64), 3), mesh.n_welded)
    mean = total / np.maximum(np.bincount(corners, minlength=mesh.n_welded), 1)
    gain = 1.0
    if places.lowers_brow(mesh.rest, target, total):
        place = partial(anatomy.glabella, midline=places.midline,
                        sides=places.brow_sides(total),
                        **dict(zip(("bottom", "nose", "top"), places.squeezed_band(mean),
                                  strict=True)))
        gain = anatomy.GLABELLA_GAIN
    elif sides := places.squinting_sides(mesh.rest, target, total):
        place = partial(anatomy.crows_feet, midline=places.midline, sides=sides)
        gain = anatomy.FAN_GAIN
    elif sides := anatomy.mouth_sides(places, mesh.rest, target, total, anatomy.NASOLABIAL,
                                      up=True):
        place = partial(anatomy.fold, midline=places.midline, sides=sides,
                        line=anatomy.NASOLABIAL, bunch=True,
                        path=anatomy.fold_path(places, mean, sides, anatomy.NASOLABIAL))
        gain = anatomy.FOLD_GAIN
    elif sides := anatomy.mouth_sides(places, mesh.rest, target, total, anatomy.MARIONETTE,
                                      up=False):
        place = partial(anatomy.fold, midline=places.midline, sides=sides,
                        line=anatomy.MARIONETTE,
                        path=anatomy.fold_path(places, mean, sides, anatomy.MARIONETTE))
        gain = anatomy.MARIONETTE_GAIN
    elif lower := anatomy_lower.lower_face_lines(places, mesh.rest, target, mean):
        place = lower
    else:
        return None
    window = place(*places.xyz.T)[0]
    region = placed_region(window, mean)
    if place.func is anatomy.fold:  # a fold a few triangles wide: its area holds all of it,
        # ending past its edge (its window holds its depth from the pose's compression)
        region = _grown(window > PLACED_WINDOW, mesh.welded_triangles, FOLD_RINGS) & (
            window > 0.0)
    elif place.func is anatomy.crows_feet:  # a squint's lines show wherever the map draws them:
        # on skin it squeezes at all (``_placed_furrows``), however little beside the eye
        region = region | ((window > PLACED_WINDOW)
                           & (mean >= 0.25 * WRINKLING_COMPRESSION))
    return VertexLines(place, window, region, gain, place.func is not anatomy.fold)


def placed_lines(project: Project, poses: Sequence[str] | None = None, frame=None
                 ) -> dict[str, tuple[Array, Array]]:
    """{pose: ((W,) bool, (W,) bool)} for each pose (all, or ``poses``) whose lines anatomy
    places on a synthesised map (``vertex_lines``): the vertices its technique-2 area must
    hold to reveal them, and those where anatomy lets its lines lie and the pose draws them
    (those vertices grown by ``WINDOW_RINGS`` triangles inside the window, its mask's edge:
    not the side a one-sided pose leaves alone). ``frame``: the face's frame, if known. What
    ``auto_setup.suggest_setup`` uses, from ``new --auto`` and Tools ▸ Auto Setup alike."""
    names = [p.name for p in project.poses] if poses is None else list(poses)
    mesh = project.skin_mesh()
    skin = project.skin_weights()
    places = FacePlaces.of(frame if frame is not None else face_frame(project),
                           project.mesh.rest, skin)
    uv_strain = UvStrain(mesh)
    skin_tri = np.asarray(skin, np.float32)[mesh.welded_triangles].min(axis=1)
    out = {}
    for name in names:
        target = project.pose(name).positions
        lines = vertex_lines(places, mesh, target, uv_strain.of(target).compression * skin_tri)
        if lines is not None:
            out[name] = (lines.region, (lines.window > PLACED_WINDOW) & _grown(
                lines.region, mesh.welded_triangles, WINDOW_RINGS))
    return out


def placed_region(window: Array, compression: Array) -> Array:
    """(W,) bool: the vertices anatomy's lines lie on, from their window (``anatomy.glabella``
    per vertex) and the pose's mean compression around each: inside the window, where the
    pose compresses the skin by ``PLACED_SHARE`` of its strong compression there (the 98th
    percentile), and at least by ``WRINKLING_COMPRESSION`` — every line inside the skin the
    pose squeezes, most on the side a one-sided brow lowerer pulls."""
    inside = window > PLACED_WINDOW
    squeezed = compression[inside & (compression > 0.0)]
    if squeezed.size == 0:
        return np.zeros(len(window), bool)
    least = max(PLACED_SHARE * float(np.percentile(squeezed, 98)), WRINKLING_COMPRESSION)
    return inside & (compression >= least)


def work_size(mesh: FaceMesh) -> int:
    """Strain fields are smooth: rasterised at ``WORK_SIZE`` across the UV square's used
    part — more when the layout is an atlas of tiles whose cells are smaller."""
    uv = mesh.uvs
    extent = float(max(np.ptp(uv[:, 0]), np.ptp(uv[:, 1]), 1e-6))
    return int(min(4 * WORK_SIZE, WORK_SIZE / min(extent, 1.0)))


def synthesise_height(mesh: FaceMesh, targets: Sequence[Array], options: SynthOptions,
                      skin: Array | None = None, progress: Progress | None = None
                      ) -> Array | None:
    """(size, size) float32 furrow height in texels (≤ 0) for these pose shapes; None if
    ``progress`` returned False."""
    fields = furrow_fields(mesh, targets, options, skin, progress)
    if fields is None:
        return None
    return (-options.depth * furrow_depths(fields, options.size)).astype(np.float32)


class _GroupFurrows:
    """A map's furrows so far: each texel's strongest orientation (degrees), for checking a
    further pose against all the map's poses in one pass over its own texels."""

    def __init__(self, size: int) -> None:
        self.angle = np.full(size * size, np.nan, np.float32)
        self.amount = np.zeros(size * size, np.float32)
        self.bare = np.zeros(size * size, bool)  # revealed by one of its poses, no furrow

    def crosses(self, f: FurrowField, strong: float) -> int:
        """How many of the pose's strong texels meet strong furrows of this map more than
        ``CROSSING_ANGLE`` apart."""
        mine = f.amount > strong
        index = f.index[mine]
        theirs = self.amount[index] > strong
        diff = np.abs(f.angle[mine][theirs] - self.angle[index[theirs]]) % 180.0
        diff = np.minimum(diff, 180.0 - diff)
        shown = 0 if f.bare is None else int((self.amount[f.bare] > strong).sum())
        return int((diff > CROSSING_ANGLE).sum()) + int(self.bare[index].sum()) + shown

    def add(self, f: FurrowField) -> None:
        stronger = f.amount > self.amount[f.index]
        self.angle[f.index[stronger]] = f.angle[stronger]
        self.amount[f.index[stronger]] = f.amount[stronger]
        if f.bare is not None:
            self.bare[f.bare] = True


def crossing_groups(fields: Sequence[FurrowField], most: int, size: int,
                    strong: float = 0.25) -> list[list[int]]:
    """Poses (by index) grouped so that no two in a group have crossing furrows — where both
    are strong, orientations more than ``CROSSING_ANGLE`` apart on more than
    ``CROSSING_SHARE`` of the pose's strong texels: one map cannot hold both, either pose would
    reveal the other's furrows too. Greedy in pose order, at most ``most`` groups (past that a
    pose joins the group it crosses least); poses without furrows are left out."""
    groups: list[list[int]] = []
    state: list[_GroupFurrows] = []
    for i, f in enumerate(fields):
        if f.index.size == 0:
            continue
        allowed = CROSSING_SHARE * max(int((f.amount > strong).sum()), 1)
        clashes = [g.crosses(f, strong) for g in state]
        free = [k for k, c in enumerate(clashes) if c <= allowed]
        if free:
            k = free[0]
        elif len(groups) < most:
            groups.append([])
            state.append(_GroupFurrows(size))
            k = len(groups) - 1
        else:
            k = int(np.argmin(clashes))
        groups[k].append(i)
        state[k].add(f)
    return groups or [[]]


def texels_per_unit(mesh: FaceMesh, skin: Array | None, size: int) -> float | None:
    """Texels of a ``size`` map per model unit on the skin (``skin`` per welded vertex; None:
    all): the square root of the UV area over the 3-D area of its triangles. None for a
    layout without area."""
    ok = np.ones(mesh.n_triangles, bool) if skin is None else (
        np.asarray(skin)[mesh.welded_triangles].min(axis=1) > 0)
    area_3d = triangle_areas(mesh.rest, mesh.welded_triangles)
    uv = mesh.uvs[mesh.triangles].astype(np.float64)
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    area_uv = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    ok = ok & (area_3d > 0) & (area_uv > 0)
    if not ok.any():
        return None
    return float(size * np.sqrt(area_uv[ok].sum() / area_3d[ok].sum()))


def face_options(project: Project, size: int) -> SynthOptions:
    """Furrow spacing and depth for this face: a share of its size (``FURROW_SPACING``) turned
    into texels by the skin's UV density, so a face in millimetres or metres, with UVs spread
    over one tile or packed into an atlas cell, gets the same furrows on its skin."""
    mesh = project.mesh
    density = texels_per_unit(mesh, project.skin_weights(), size)
    if density is None:
        return SynthOptions(size=size)
    points = mesh.rest[project.skin_weights() > 0]
    face = float(np.linalg.norm(np.ptp(points, axis=0)))
    spacing = float(np.clip(FURROW_SPACING * face * density, 3.0, size / 8))
    return SynthOptions(size=size, spacing=spacing, depth=DEPTH_PER_SPACING * spacing)


def synthesise_wrinkle_map(project: Project, poses: Sequence[str] | None = None,
                           options: SynthOptions | None = None, *, over_neutral: bool = True,
                           progress: Progress | None = None) -> SynthResult | None:
    """A wrinkled normal map from the project's key poses (all, or ``poses``), laid over the
    neutral normal map unless ``over_neutral`` is False. None if ``progress`` stopped it."""
    options = options or SynthOptions()
    names = [p.name for p in project.poses] if poses is None else list(poses)
    if not names:
        raise StudioError("a wrinkled map is synthesised from key poses, and none was chosen")
    targets = [project.pose(name).positions for name in names]
    height = synthesise_height(project.skin_mesh(), targets, options, project.skin_weights(),
                               progress)
    if height is None:
        return None
    return SynthResult(height, height_to_map(height, project.textures.normal_neutral,
                                             over_neutral))


def height_to_map(height: Array, neutral: Array, over_neutral: bool = True) -> Array:
    """Furrow heights as a tangent-space normal map at the neutral map's bit depth, laid over
    its detail unless ``over_neutral`` is False."""
    bits = 16 if neutral.dtype == np.uint16 else 8
    normal = height_to_normal(height, 0.5, bits=bits,  # central differences span 2 texels
                              max_tilt=MAX_TILT)
    return over_base(normal, neutral) if over_neutral else normal


# --- for a face that has no wrinkled map ---------------------------------------------------------

def is_flat(image: Array) -> bool:
    """A normal map with one value everywhere: a placeholder, not an authored map."""
    return bool((image == image[0, 0]).all())


def default_size(textures: FaceTextures, least: int = 1024) -> int:
    """A map size that does the face's other maps justice: their largest, at least ``least``."""
    images = [textures.diffuse, textures.normal_neutral, *textures.wrinkle_maps.values()]
    return max(least, *(max(image.shape[:2]) for image in images))


def fill_placeholder(project: Project, options: SynthOptions | None = None,
                     progress: Progress | None = None, poses: Sequence[str] | None = None,
                     frame=None) -> dict[str, list[str]] | None:
    """Synthesise the first flat (placeholder) wrinkled map from all key poses, in place, so an
    imported face without one shows wrinkles. Poses whose furrows cross (a frown's vertical
    lines over a brow raise's horizontal ones) go to separate maps, added after it (up to the
    shader's four). Returns {map name: its poses}; empty if every map is authored or the face
    has no key poses; None if ``progress`` (called with done, total) returned False. Where
    anatomy placed a pose's lines, ``placed_lines`` gives the set-up their vertices.
    ``frame``: the face's frame, if known (found otherwise)."""
    textures = project.textures
    name = next((n for n, image in textures.wrinkle_maps.items() if is_flat(image)), None)
    if name is None or not project.poses:
        return {}
    if options is None:
        options = face_options(project, _default_map_size(project))
    names = [p.name for p in project.poses] if poses is None else list(poses)
    controls = [project.furrows.of(n) for n in names]
    places = None if frame is None else FacePlaces.of(frame, project.mesh.rest,
                                                      project.skin_weights())
    fields = pose_fields(project, names, options, controls, progress, places)
    if fields is None:
        return None
    room = MAX_WRINKLE_MAPS - len(textures.wrinkle_maps) + 1
    groups = crossing_groups(fields, room, options.size)
    made: dict[str, list[str]] = {}
    maps = grouped_maps(fields, controls, options, groups, textures.normal_neutral)
    for k, (group, normal) in enumerate(zip(groups, maps, strict=True)):
        map_name = name if k == 0 else unique_name(f"{name} {k + 1}", textures.wrinkle_maps)
        textures.set_wrinkle_map(map_name, normal)
        made[map_name] = [names[i] for i in group]
        # remembered, so that the furrow controls can make it again (``furrow_maps``)
        project.furrows.maps[map_name] = SynthesisedMap(
            tuple(made[map_name]), options.spacing, options.depth, True, map_digest(normal))
    return made


def pose_fields(project: Project, names: Sequence[str], options: SynthOptions,
                controls: Sequence[FurrowControls], progress: Progress | None = None,
                places: FacePlaces | None = None, anatomy: bool = True
                ) -> list[FurrowField] | None:
    """The furrow fields of these poses as ``new --auto`` lays them out (anatomy placing the
    primary lines; without ``anatomy``, as the Synthesise dialog does, the strain alone), at
    each pose's spacing; None if ``progress`` stopped. ``places``: the face's
    (``face_places``), if known."""
    return furrow_fields(project.skin_mesh(), [project.pose(n).positions for n in names],
                         options, project.skin_weights(), progress,
                         places=(places or face_places(project)) if anatomy else None,
                         spacings=[c.spacing for c in controls])


def face_places(project: Project) -> FacePlaces:
    """Where each vertex is on the face, for anatomy's lines (finding the face's frame takes
    a good part of a second: ``furrow_maps`` keeps it)."""
    return FacePlaces.of(face_frame(project), project.mesh.rest, project.skin_weights())


def _default_map_size(project: Project) -> int:
    """A power of two that does the face's other maps justice, and keeps about 1024 texels
    across a skin tile of an atlas; at most 2048 (a map per group of poses is made)."""
    size = default_size(project.textures)
    if project.uv_tiles is not None:
        size = max(size, round(1024 / project.uv_tiles.layout.largest_cell()))
    return min(_power_of_two(size), 2048)


def _power_of_two(size: int) -> int:
    return 1 << max(int(size) - 1, 1).bit_length()
