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
3. **Furrows**: *phasor noise* (Tricard et al. 2019). White noise filtered by a complex Gabor
   kernel tuned to a frequency ``1/spacing`` along one orientation gives a field whose *phase*
   advances by 2π per spacing along that orientation; a bank of orientations is filtered once
   (FFT), each texel blends the two nearest, and a valley profile of the phase gives furrows
   of even depth that follow any direction field — fans like crow's feet included — with the
   natural breaks of real wrinkles. Fixed seed: the same input gives the same map.
4. The **height** is ``−depth × max over poses (amount × valley)``, in texels, and becomes a
   tangent-space normal map (``normalmap.height_to_normal``), laid over the neutral map's
   detail so pores stay where the furrows show.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from studio.core.files.errors import StudioError
from studio.core.files.images import to_unit_float
from studio.core.files.naming import unique_name
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.normalmap import height_to_normal
from studio.core.wrinkles.skin_strain import (
    WRINKLING_COMPRESSION,
    TriangleStrain,
    UvStrain,
    triangle_areas,
)
from studio.core.wrinkles.strain import DEFAULT_FULL_AT
from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS, FaceTextures, resize_nearest

Array = np.ndarray
Progress = Callable[[int, int], bool]  # (done, total) -> keep going

BINS = 32  # orientations in the filter bank over 180°: 5.6° apart, well inside one kernel's
WORK_SIZE = 256  # strain fields are smooth: rasterised at most this size, then upsampled
SHARPNESS = 4.0  # exponent of the valley profile: higher = narrower furrows between flat skin
SEED = 2010
PEAK_SHARE = 0.7  # a pose's furrows are at full depth from 70 % of its strong compression on
FURROW_SPACING = 0.02  # between neighbouring furrows, as a share of the face's size …
DEPTH_PER_SPACING = 0.125  # … and their depth, as a share of the spacing (1.5 texels in 12)
CROSSING_ANGLE = 30.0  # degrees: furrows of two poses this far apart do not share a map
CROSSING_SHARE = 0.05  # … when they cross on this share of the smaller pose's furrows


@dataclass
class SynthOptions:
    size: int = 1024  # of the map, texels
    spacing: float = 12.0  # texels between neighbouring furrows
    depth: float = 1.5  # of a furrow at full compression, texels (slopes are true to this)
    full_at: float = DEFAULT_FULL_AT  # compression at which furrows reach their full depth
    smoothing: float | None = None  # of the strain fields, texels; None: 1.5 × spacing
    seed: int = SEED

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
    """Where one pose makes furrows, at the map's size, on the texels it touches only; the
    texels are sorted by the lower of the two bank orientations they blend, so that each
    orientation's texels are one slice."""

    index: Array  # (n,) flat texel indices
    amount: Array  # (n,) furrow strength in (0, 1]
    lower: Array  # (n,) bank orientation just below the wave vector's, 0 … BINS − 1
    frac: Array  # (n,) how far toward the next orientation, in [0, 1)
    bounds: Array  # (BINS + 1,) texels of orientation k: [bounds[k], bounds[k + 1])

    @classmethod
    def of(cls, index: Array, amount: Array, angle: Array) -> FurrowField:
        """From the wave vector's orientation in [0, π) per texel."""
        position = np.asarray(angle, np.float64) / (np.pi / BINS)
        lower = np.clip(np.floor(position), 0, BINS - 1).astype(np.int64)
        frac = np.clip(position - lower, 0.0, 1.0).astype(np.float32)
        order = np.argsort(lower, kind="stable")
        lower = lower[order]
        return cls(index[order], amount[order], lower, frac[order],
                   np.searchsorted(lower, np.arange(BINS + 1)))

    def span(self, k: int) -> slice:
        return slice(int(self.bounds[k]), int(self.bounds[k + 1]))

    def bins(self) -> set[int]:
        """The bank orientations this field reads: its lower ones and the next of each."""
        used = np.flatnonzero(np.diff(self.bounds) > 0)
        return {int(k) for k in used} | {int(k + 1) % BINS for k in used}


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
                 full_at: float, smoothing: float) -> FurrowField:
    """Rasterise, smooth and upsample one pose's compression and direction fields."""
    work = ids.shape[0]
    covered = ids >= 0
    tri = np.where(covered, ids, 0)
    compression = strain.compression * skin
    weight = np.minimum(compression, strain.anisotropy)  # no direction without anisotropy
    cos2 = strain.wave[:, 0] ** 2 - strain.wave[:, 1] ** 2
    sin2 = 2.0 * strain.wave[:, 0] * strain.wave[:, 1]
    radius = smoothing * work / size
    full_at = pose_full_at(compression, full_at)

    def layer(per_triangle: Array) -> Array:
        return np.where(covered, per_triangle[tri], 0.0).astype(np.float32)

    amount = mask_ops.blur(layer(compression), radius)
    total = mask_ops.blur(np.clip(layer(weight), 0.0, 1.0), radius)
    c = _smooth_signed(layer(np.clip(weight, 0.0, 1.0) * cos2), radius)
    s = _smooth_signed(layer(np.clip(weight, 0.0, 1.0) * sin2), radius)
    coherence = np.clip(np.hypot(c, s) / np.maximum(total, 1e-6), 0.0, 1.0)
    strength = np.clip(amount / max(full_at, 1e-6), 0.0, 1.0) * coherence
    strength = mask_ops.resample(strength, size)
    index = np.flatnonzero(strength > 1e-3)
    c_up = mask_ops.resample((c + 1.0) * 0.5, size).ravel()[index] * 2.0 - 1.0
    s_up = mask_ops.resample((s + 1.0) * 0.5, size).ravel()[index] * 2.0 - 1.0
    angle = np.mod(0.5 * np.arctan2(s_up, c_up), np.pi)
    return FurrowField.of(index, strength.ravel()[index], angle)


# --- 3. furrows: a bank of oriented phasor-noise fields ------------------------------------------

class PhasorBank:
    """White noise filtered by complex Gabor kernels of one frequency at ``BINS`` orientations;
    each orientation's field is computed (one inverse FFT) only when asked for."""

    def __init__(self, size: int, spacing: float, seed: int) -> None:
        noise = np.random.default_rng(seed).standard_normal((size, size), dtype=np.float32)
        self.spectrum = np.fft.fft2(noise)
        fy = np.fft.fftfreq(size).astype(np.float32)[:, None]
        fx = np.fft.fftfreq(size).astype(np.float32)[None, :]
        self.fx, self.fy = fx, fy
        self.frequency = 1.0 / spacing
        # the kernel's envelope: σ texels across the furrows, twice that along them
        self.sigma_across, self.sigma_along = 0.8 * spacing, 1.6 * spacing

    def field(self, k: int) -> Array:
        theta = k * np.pi / BINS
        c, s = np.float32(np.cos(theta)), np.float32(np.sin(theta))
        across = self.fx * c + self.fy * s - np.float32(self.frequency)
        along = -self.fx * s + self.fy * c
        gain = np.exp(np.float32(-2.0 * np.pi ** 2) * (
            np.float32(self.sigma_across ** 2) * across * across
            + np.float32(self.sigma_along ** 2) * along * along))
        return np.fft.ifft2(self.spectrum * gain).astype(np.complex64).ravel()


def valley(phase: Array) -> Array:
    """1 at the bottom of a furrow (phase 0), falling to 0 between furrows; even in the phase,
    so a field and its conjugate (the same orientation turned by 180°) give the same furrows."""
    return ((1.0 + np.cos(phase)) * 0.5) ** SHARPNESS


def furrow_depths(fields: Sequence[FurrowField], size: int, spacing: float, seed: int,
                  progress: Progress | None = None, done: int = 0, total: int = 0,
                  groups: Sequence[Sequence[int]] | None = None) -> Array | list[Array] | None:
    """(size, size) max over poses of amount × valley(phase); None if ``progress`` stopped.
    With ``groups`` (lists of field indices), one such image per group, from one pass over
    the filter bank (its inverse FFTs are the cost)."""
    needed = sorted(set().union(*(f.bins() for f in fields)))
    bank = PhasorBank(size, spacing, seed) if needed else None
    sums = [np.zeros(len(f.index), np.complex64) for f in fields]
    for n, k in enumerate(needed):
        z = bank.field(k)
        for f, acc in zip(fields, sums, strict=True):
            here = f.span(k)  # orientation k is their lower one
            acc[here] += (1.0 - f.frac[here]) * z[f.index[here]]
            # … and the upper one of k − 1's; 180° (past the last) is 0° with the wave vector
            # turned, whose field is the conjugate
            up = f.span((k - 1) % BINS)
            acc[up] += f.frac[up] * (np.conj(z[f.index[up]]) if k == 0 else z[f.index[up]])
        if progress is not None and not progress(done + n + 1, total):
            return None
    images = []
    for group in (groups if groups is not None else [range(len(fields))]):
        depth = np.zeros(size * size, np.float32)
        for i in group:
            f = fields[i]
            np.maximum.at(depth, f.index, f.amount * valley(np.angle(sums[i])).astype(np.float32))
        images.append(depth.reshape(size, size))
    return images if groups is not None else images[0]


# --- 4. the map ----------------------------------------------------------------------------------

def _encode(normals: Array, dtype: type) -> Array:
    top = np.iinfo(dtype).max
    return np.clip(np.floor((normals * 0.5 + 0.5) * top + 0.5), 0, top).astype(dtype)


def over_base(detail: Array, base: Array) -> Array:
    """The furrows' normals laid over a base normal map's detail (whiteout blend:
    ``(b.xy + d.xy, b.z·d.z)``); texels the furrows leave flat keep the base's exact values."""
    if base.shape[:2] != detail.shape[:2]:
        base = resize_nearest(base, *detail.shape[:2])
    out = base.astype(detail.dtype) if base.dtype == detail.dtype else _encode(
        to_unit_float(base) * 2.0 - 1.0, detail.dtype)
    flat_xy = np.iinfo(detail.dtype).max // 2 + 1
    touched = np.any(detail[..., :2] != flat_xy, axis=-1)
    d = to_unit_float(detail[touched]) * 2.0 - 1.0
    b = to_unit_float(out[touched]) * 2.0 - 1.0
    n = np.c_[b[:, 0] + d[:, 0], b[:, 1] + d[:, 1], b[:, 2] * d[:, 2]]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    out[touched] = _encode(n, detail.dtype)
    return out


def furrow_fields(mesh: FaceMesh, targets: Sequence[Array], options: SynthOptions,
                  skin: Array | None = None, progress: Progress | None = None,
                  total: int = 0) -> list[FurrowField] | None:
    """Each pose's furrow field at the map's size; None if ``progress`` stopped."""
    options.check()
    size = options.size
    work = min(size, work_size(mesh))
    ids = UvRaster(mesh, work).triangle
    uv_strain = UvStrain(mesh)
    skin_tri = (np.ones(mesh.n_triangles, np.float32) if skin is None
                else np.asarray(skin, np.float32)[mesh.welded_triangles].min(axis=1))
    smoothing = 1.5 * options.spacing if options.smoothing is None else options.smoothing
    fields = []
    for i, target in enumerate(targets):
        fields.append(furrow_field(uv_strain.of(target), ids, skin_tri, size, options.full_at,
                                   smoothing))
        if progress is not None and not progress(i + 1, total or len(targets)):
            return None
    return fields


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
    total = len(targets) + BINS
    fields = furrow_fields(mesh, targets, options, skin, progress, total)
    if fields is None:
        return None
    depth = furrow_depths(fields, options.size, options.spacing, options.seed, progress,
                          len(targets), total)
    return None if depth is None else (-options.depth * depth).astype(np.float32)


class _GroupFurrows:
    """A map's furrows so far: each texel's strongest orientation (degrees), for checking a
    further pose against all the map's poses in one pass over its own texels."""

    def __init__(self, size: int) -> None:
        self.angle = np.full(size * size, np.nan, np.float32)
        self.amount = np.zeros(size * size, np.float32)

    def crosses(self, f: FurrowField, strong: float) -> int:
        """How many of the pose's strong texels meet strong furrows of this map more than
        ``CROSSING_ANGLE`` apart."""
        mine = f.amount > strong
        index = f.index[mine]
        theirs = self.amount[index] > strong
        diff = np.abs(_degrees(f)[mine][theirs] - self.angle[index[theirs]]) % 180.0
        diff = np.minimum(diff, 180.0 - diff)
        return int((diff > CROSSING_ANGLE).sum())

    def add(self, f: FurrowField) -> None:
        stronger = f.amount > self.amount[f.index]
        self.angle[f.index[stronger]] = _degrees(f)[stronger]
        self.amount[f.index[stronger]] = f.amount[stronger]


def _degrees(f: FurrowField) -> Array:
    return ((f.lower + f.frac) * (180.0 / BINS)).astype(np.float32)


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


def face_options(project: Project, size: int) -> SynthOptions:
    """Furrow spacing and depth for this face: a share of its size (``FURROW_SPACING``) turned
    into texels by the skin's UV density, so a face in millimetres or metres, with UVs spread
    over one tile or packed into an atlas cell, gets the same furrows on its skin."""
    mesh = project.mesh
    skin = project.skin_weights()[mesh.welded_triangles].min(axis=1) > 0
    area_3d = triangle_areas(mesh.rest, mesh.welded_triangles)
    uv = mesh.uvs[mesh.triangles].astype(np.float64)
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    area_uv = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    ok = skin & (area_3d > 0) & (area_uv > 0)
    if not ok.any():
        return SynthOptions(size=size)
    texels_per_unit = size * np.sqrt(area_uv[ok].sum() / area_3d[ok].sum())
    points = mesh.rest[project.skin_weights() > 0]
    face = float(np.linalg.norm(np.ptp(points, axis=0)))
    spacing = float(np.clip(FURROW_SPACING * face * texels_per_unit, 3.0, size / 8))
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
    normal = height_to_normal(height, 0.5, bits=bits)  # central differences span 2 texels
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
                     progress: Progress | None = None) -> dict[str, list[str]] | None:
    """Synthesise the first flat (placeholder) wrinkled map from all key poses, in place, so an
    imported face without one shows wrinkles. Poses whose furrows cross (a frown's vertical
    lines over a brow raise's horizontal ones) go to separate maps, added after it (up to the
    shader's four). Returns {map name: its poses}; empty if every map is authored or the face
    has no key poses; None if ``progress`` (called with done, total) returned False."""
    textures = project.textures
    name = next((n for n, image in textures.wrinkle_maps.items() if is_flat(image)), None)
    if name is None or not project.poses:
        return {}
    if options is None:
        options = face_options(project, _default_map_size(project))
    names = [p.name for p in project.poses]
    targets = [p.positions for p in project.poses]
    total = len(targets) + BINS
    fields = furrow_fields(project.skin_mesh(), targets, options, project.skin_weights(), progress,
                           total)
    if fields is None:
        return None
    room = MAX_WRINKLE_MAPS - len(textures.wrinkle_maps) + 1
    groups = crossing_groups(fields, room, options.size)
    neutral = textures.normal_neutral
    made: dict[str, list[str]] = {}
    depths = furrow_depths(fields, options.size, options.spacing, options.seed, progress,
                           len(targets), total, groups)
    if depths is None:
        return None
    for k, (group, depth) in enumerate(zip(groups, depths, strict=True)):
        normal = height_to_map((-options.depth * depth).astype(np.float32), neutral)
        map_name = name if k == 0 else unique_name(f"{name} {k + 1}", textures.wrinkle_maps)
        textures.set_wrinkle_map(map_name, normal)
        made[map_name] = [names[i] for i in group]
    return made


def _default_map_size(project: Project) -> int:
    """A power of two that does the face's other maps justice, and keeps about 1024 texels
    across a skin tile of an atlas; at most 2048 (a map per group of poses is made)."""
    size = default_size(project.textures)
    if project.uv_tiles is not None:
        size = max(size, round(1024 / project.uv_tiles.layout.largest_cell()))
    return min(_power_of_two(size), 2048)


def _power_of_two(size: int) -> int:
    return 1 << max(int(size) - 1, 1).bit_length()
