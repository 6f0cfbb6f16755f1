"""A wrinkled normal map for a face that has none, synthesised from its key poses (issue 10).

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

from studio.core import mask_ops
from studio.core.errors import StudioError
from studio.core.images import to_unit_float
from studio.core.mesh import FaceMesh
from studio.core.normalmap import height_to_normal
from studio.core.project import Project
from studio.core.strain import DEFAULT_FULL_AT
from studio.core.textures import FaceTextures, resize_nearest

Array = np.ndarray
Progress = Callable[[int, int], bool]  # (done, total) -> keep going

BINS = 32  # orientations in the filter bank over 180°: 5.6° apart, well inside one kernel's
WORK_SIZE = 256  # strain fields are smooth: rasterised at most this size, then upsampled
SHARPNESS = 4.0  # exponent of the valley profile: higher = narrower furrows between flat skin
SEED = 2010


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


# --- 1. strain per triangle ----------------------------------------------------------------------

@dataclass
class TriangleStrain:
    compression: Array  # (F,) 1 − smallest stretch, ≥ 0
    wave: Array  # (F, 2) unit vector in image coordinates (x = u, y = 1 − v), across the furrows
    anisotropy: Array  # (F,) largest minus smallest stretch


Metric = tuple[Array, Array, Array]  # (g00, g01, g11) per triangle: a symmetric 2×2 tensor


class UvStrain:
    """Strain in the UV parametrisation, with what depends only on the neutral face (the UV
    edge inverses and the rest metric) prepared once for any number of poses."""

    def __init__(self, mesh: FaceMesh) -> None:
        tri = mesh.triangles
        img = np.c_[mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]].astype(np.float64)
        d1, d2 = img[tri[:, 1]] - img[tri[:, 0]], img[tri[:, 2]] - img[tri[:, 0]]
        det_u = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
        ok = np.abs(det_u) > 1e-14
        inv = np.where(ok, 1.0 / np.where(ok, det_u, 1.0), 0.0)
        # U = [d1 d2] (columns); U⁻¹ = [[d2y, −d2x], [−d1y, d1x]] / det
        self._u_inv = (d2[:, 1] * inv, -d2[:, 0] * inv, -d1[:, 1] * inv, d1[:, 0] * inv)
        self._welded = mesh.welded_triangles
        self.rest = self.metric(mesh.rest)
        b00, b01, b11 = self.rest
        self._det_b = b00 * b11 - b01 * b01
        self._ok = ok & (self._det_b > 1e-12 * np.maximum(b00 + b11, 1e-300) ** 2)
        self._det_b = np.where(self._ok, self._det_b, 1.0)

    def metric(self, points: Array) -> Metric:
        """JᵀJ of the map from image offsets to 3-D offsets, J = E · U⁻¹ (E: edge vectors)."""
        p = np.asarray(points, np.float64)[self._welded]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        i00, i01, i10, i11 = self._u_inv
        j0 = e1 * i00[:, None] + e2 * i10[:, None]
        j1 = e1 * i01[:, None] + e2 * i11[:, None]
        return ((j0 * j0).sum(1), (j0 * j1).sum(1), (j1 * j1).sum(1))

    def of(self, target: Array) -> TriangleStrain:
        """Per-triangle compression and its direction for one pose: the generalised
        eigenproblem ``A v = λ B v`` of the pose metric A against the rest metric B."""
        a00, a01, a11 = self.metric(target)
        b00, b01, b11 = self.rest
        det_b, ok = self._det_b, self._ok
        det_a = a00 * a11 - a01 * a01
        trace = a00 * b11 + a11 * b00 - 2.0 * a01 * b01
        root = np.sqrt(np.maximum(trace * trace - 4.0 * det_b * det_a, 0.0))
        lam_min = np.maximum((trace - root) / (2.0 * det_b), 0.0)
        lam_max = np.maximum((trace + root) / (2.0 * det_b), 0.0)
        # M = A − λ_min B is singular; v spans its null space (from its larger row)
        m00, m01, m11 = a00 - lam_min * b00, a01 - lam_min * b01, a11 - lam_min * b11
        first = m00 * m00 + m01 * m01 >= m01 * m01 + m11 * m11
        vx, vy = np.where(first, -m01, -m11), np.where(first, m00, m01)
        wave = np.stack([b00 * vx + b01 * vy, b01 * vx + b11 * vy], axis=1)  # B v
        norm = np.linalg.norm(wave, axis=1)
        wave /= np.where(norm > 0, norm, 1.0)[:, None]
        s_min, s_max = np.sqrt(lam_min), np.sqrt(lam_max)
        compression = np.where(ok, np.clip(1.0 - s_min, 0.0, 1.0), 0.0)
        anisotropy = np.where(ok, s_max - s_min, 0.0)
        return TriangleStrain(compression.astype(np.float32), wave.astype(np.float32),
                              anisotropy.astype(np.float32))


def triangle_strain(mesh: FaceMesh, target: Array) -> TriangleStrain:
    """Per-triangle compression and its direction, measured in the UV parametrisation."""
    return UvStrain(mesh).of(target)


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
                  progress: Progress | None = None, done: int = 0, total: int = 0
                  ) -> Array | None:
    """(size, size) max over poses of amount × valley(phase); None if ``progress`` stopped."""
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
    depth = np.zeros(size * size, np.float32)
    for f, acc in zip(fields, sums, strict=True):
        np.maximum.at(depth, f.index, f.amount * valley(np.angle(acc)).astype(np.float32))
    return depth.reshape(size, size)


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


def synthesise_height(mesh: FaceMesh, targets: Sequence[Array], options: SynthOptions,
                      skin: Array | None = None, progress: Progress | None = None
                      ) -> Array | None:
    """(size, size) float32 furrow height in texels (≤ 0) for these pose shapes; None if
    ``progress`` returned False."""
    options.check()
    size = options.size
    work = min(size, WORK_SIZE)
    ids = UvRaster(mesh, work).triangle
    uv_strain = UvStrain(mesh)
    skin_tri = (np.ones(mesh.n_triangles, np.float32) if skin is None
                else np.asarray(skin, np.float32)[mesh.welded_triangles].min(axis=1))
    smoothing = 1.5 * options.spacing if options.smoothing is None else options.smoothing
    total = len(targets) + BINS
    fields = []
    for i, target in enumerate(targets):
        fields.append(furrow_field(uv_strain.of(target), ids, skin_tri, size, options.full_at,
                                   smoothing))
        if progress is not None and not progress(i + 1, total):
            return None
    depth = furrow_depths(fields, size, options.spacing, options.seed, progress, len(targets),
                          total)
    return None if depth is None else (-options.depth * depth).astype(np.float32)


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
    height = synthesise_height(project.mesh, targets, options, project.skin_weights(), progress)
    if height is None:
        return None
    neutral = project.textures.normal_neutral
    bits = 16 if neutral.dtype == np.uint16 else 8
    normal = height_to_normal(height, 0.5, bits=bits)  # central differences span 2 texels
    if over_neutral:
        normal = over_base(normal, neutral)
    return SynthResult(height, normal)


# --- for a face that has no wrinkled map ---------------------------------------------------------

def is_flat(image: Array) -> bool:
    """A normal map with one value everywhere: a placeholder, not an authored map."""
    return bool((image == image[0, 0]).all())


def default_size(textures: FaceTextures, least: int = 1024) -> int:
    """A map size that does the face's other maps justice: their largest, at least ``least``."""
    images = [textures.diffuse, textures.normal_neutral, *textures.wrinkle_maps.values()]
    return max(least, *(max(image.shape[:2]) for image in images))


def fill_placeholder(project: Project, options: SynthOptions | None = None) -> str | None:
    """Synthesise the first flat (placeholder) wrinkled map from all key poses, in place, so an
    imported face without one shows wrinkles; its name, or None if every map is authored or the
    face has no key poses."""
    textures = project.textures
    name = next((n for n, image in textures.wrinkle_maps.items() if is_flat(image)), None)
    if name is None or not project.poses:
        return None
    options = options or SynthOptions(size=min(_power_of_two(default_size(textures)), 2048))
    textures.set_wrinkle_map(name, synthesise_wrinkle_map(project, None, options).normal)
    return name


def _power_of_two(size: int) -> int:
    return 1 << max(int(size) - 1, 1).bit_length()
