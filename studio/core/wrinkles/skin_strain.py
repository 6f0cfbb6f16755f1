"""How a key pose compresses the skin: principal strains per triangle, in the surface itself.

Wrinkles form where skin shortens along some direction — even where its area stays the same:
a frown squeezes the skin between the brows sideways while it bulges up, a smile folds the
nasolabial region along the pull of the mouth corner, a squint bunches the crow's feet toward the
eye. Mean edge shortening averages such a squeeze against the stretch across it and misses it;
the smallest *principal stretch* does not.

Per triangle, the map from the neutral surface to the posed one has a metric tensor; its
eigenvalues relative to the neutral metric are the squared principal stretches
``s_min ≤ s_max``. Compression is ``1 − s_min`` (≥ 0), a pure number: the same for a face in
millimetres or metres, moved or turned (rigid motion changes neither metric), which is what makes
every threshold here free of the face's units and placement. The tensors are written in the UV
parametrisation, so the direction of compression also comes out as an image direction for laying
furrows (``wave``); the eigenvalues themselves do not depend on the parametrisation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh

Array = np.ndarray
Metric = tuple[Array, Array, Array]  # (g00, g01, g11) per triangle: a symmetric 2×2 tensor

WRINKLING_COMPRESSION = 0.02  # skin shortened by less than 2 % along every direction: no wrinkle


@dataclass
class TriangleStrain:
    compression: Array  # (F,) 1 − smallest stretch, ≥ 0
    wave: Array  # (F, 2) unit vector in image coordinates (x = u, y = 1 − v), across the furrows
    anisotropy: Array  # (F,) largest minus smallest stretch
    stretch: Array  # (F,) largest stretch − 1 (negative where the skin shrinks every way)


class UvStrain:
    """Strain in the UV parametrisation, with what depends only on the neutral face (the UV
    edge inverses, the rest metric and the neutral face's own strain) prepared once for any
    number of poses. A pose is measured only on the triangles it moves: every quantity is
    per triangle, so a still triangle's is the neutral face's, bit for bit — a pose that
    moves the brows costs the brows, not the head."""

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
        self._rest_points = np.asarray(mesh.rest)
        self.rest = self.metric(mesh.rest)
        b00, b01, b11 = self.rest
        self._det_b = b00 * b11 - b01 * b01
        self._ok = ok & (self._det_b > 1e-12 * np.maximum(b00 + b11, 1e-300) ** 2)
        self._det_b = np.where(self._ok, self._det_b, 1.0)
        self._neutral = self._strain(mesh.rest, slice(None))

    def metric(self, points: Array, where: Array | slice = slice(None)) -> Metric:
        """JᵀJ of the map from image offsets to 3-D offsets, J = E · U⁻¹ (E: edge vectors),
        of the triangles ``where`` (all by default)."""
        p = np.asarray(points, np.float64)[self._welded[where]]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        i00, i01, i10, i11 = (part[where] for part in self._u_inv)
        j0 = e1 * i00[:, None] + e2 * i10[:, None]
        j1 = e1 * i01[:, None] + e2 * i11[:, None]
        return ((j0 * j0).sum(1), (j0 * j1).sum(1), (j1 * j1).sum(1))

    def moved(self, target: Array) -> Array:
        """(F,) bool: the triangles with a corner the pose moves."""
        shifted = (np.asarray(target) != self._rest_points).any(axis=1)
        return shifted[self._welded].any(axis=1)

    def of(self, target: Array) -> TriangleStrain:
        """Per-triangle compression and its direction for one pose (the neutral face's on the
        triangles it does not move)."""
        where = np.flatnonzero(self.moved(target))
        neutral = self._neutral
        out = TriangleStrain(neutral.compression.copy(), neutral.wave.copy(),
                             neutral.anisotropy.copy(), neutral.stretch.copy())
        if where.size:
            strain = self._strain(target, where)
            out.compression[where] = strain.compression
            out.wave[where] = strain.wave
            out.anisotropy[where] = strain.anisotropy
            out.stretch[where] = strain.stretch
        return out

    def _strain(self, target: Array, where: Array | slice) -> TriangleStrain:
        """The triangles ``where``'s strain: the generalised eigenproblem ``A v = λ B v`` of
        the pose metric A against the rest metric B."""
        a00, a01, a11 = self.metric(target, where)
        b00, b01, b11 = (part[where] for part in self.rest)
        det_b, ok = self._det_b[where], self._ok[where]
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
        stretch = np.where(ok, s_max - 1.0, 0.0)
        return TriangleStrain(compression.astype(np.float32), wave.astype(np.float32),
                              anisotropy.astype(np.float32), stretch.astype(np.float32))


def triangle_strain(mesh: FaceMesh, target: Array) -> TriangleStrain:
    """Per-triangle compression and its direction, measured in the UV parametrisation."""
    return UvStrain(mesh).of(target)


def triangle_areas(positions: Array, welded_triangles: Array) -> Array:
    p = np.asarray(positions, np.float64)[welded_triangles]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


class SkinStrain:
    """Per-pose skin compression of one face: per triangle, per welded vertex, and summed up
    for a report — with the neutral face's parts prepared once for all its poses."""

    def __init__(self, mesh: FaceMesh, skin: Array | None = None) -> None:
        self.mesh = mesh
        self.uv = UvStrain(mesh)
        self.areas = triangle_areas(mesh.rest, mesh.welded_triangles)
        skin = np.ones(mesh.n_welded, bool) if skin is None else np.asarray(skin) > 0
        # a triangle is skin when all its corners are: eyelid rims next to an eyeball stay skin
        self.skin_triangle = skin[mesh.welded_triangles].all(axis=1)
        corner_area = np.repeat(np.where(self.skin_triangle, self.areas, 0.0), 3)
        self._corners = mesh.welded_triangles.ravel()
        self._vertex_area = np.bincount(self._corners, corner_area, mesh.n_welded)
        self.skin_area = float(self.areas[self.skin_triangle].sum())

    def of(self, target: Array) -> TriangleStrain:
        """The pose's triangle strain with everything off the skin set to 0."""
        strain = self.uv.of(target)
        off = ~self.skin_triangle
        strain.compression[off] = 0.0
        strain.anisotropy[off] = 0.0
        strain.stretch[off] = 0.0
        return strain

    def per_vertex(self, per_triangle: Array) -> Array:
        """(W,) area-weighted mean over each welded vertex's skin triangles (0 off the skin)."""
        weighted = np.repeat(np.where(self.skin_triangle, per_triangle * self.areas, 0.0), 3)
        total = np.bincount(self._corners, weighted, self.mesh.n_welded)
        return np.divide(total, self._vertex_area, out=np.zeros_like(total),
                         where=self._vertex_area > 0).astype(np.float32)

    def summary(self, strain: TriangleStrain, moved: float) -> PoseStrain:
        """What a pose does to the skin, for the auto-setup report."""
        compressed = strain.compression >= WRINKLING_COMPRESSION
        weights = np.where(compressed, strain.compression * self.areas, 0.0)
        centroids = self.mesh.rest[self.mesh.welded_triangles].mean(axis=1)
        where = (weights @ centroids / weights.sum()) if weights.sum() > 0 else None
        return PoseStrain(
            peak_compression=float(strain.compression.max(initial=0.0)),
            peak_stretch=float(strain.stretch.max(initial=0.0)),
            compressed_share=float(self.areas[compressed].sum() / max(self.skin_area, 1e-300)),
            centre=where, moved=moved)


def compression_weights(strain: SkinStrain, per_triangle: Array, threshold: float = 0.1
                        ) -> Array:
    """(W,) soft weights in [0, 1] where a pose compresses the skin: each vertex's principal
    compression (``per_triangle``, from :meth:`SkinStrain.of`) over the pose's strong
    compression (the 98th percentile over compressed vertices), below ``threshold`` of that 0,
    eased out (``w·(2 − w)``: a mask an artist paints is near full over most of the area that
    wrinkles and falls off at its edge, not a ramp that shows the furrows half-strength);
    all 0 for a pose that compresses no skin by ``WRINKLING_COMPRESSION`` anywhere (a stretch,
    a rotation, float noise)."""
    if per_triangle.max(initial=0.0) < WRINKLING_COMPRESSION:
        return np.zeros(strain.mesh.n_welded, np.float32)
    comp = strain.per_vertex(per_triangle)
    scale = max(float(np.percentile(comp[comp > 0.0], 98)), 1e-12)
    w = np.clip((comp / scale - threshold) / (1.0 - threshold), 0.0, 1.0)
    return (w * (2.0 - w)).astype(np.float32)


@dataclass
class PoseStrain:
    """One pose's effect on the skin: peak principal compression and stretch (fractions),
    the share of the skin's area compressed enough to wrinkle, where (the compression-weighted
    centre, neutral positions; None without compression) and its largest skin motion relative
    to the face's size."""

    peak_compression: float
    peak_stretch: float
    compressed_share: float
    centre: Array | None
    moved: float

    @property
    def compresses(self) -> bool:
        return self.compressed_share > 0.0

    def describe(self) -> str:
        """Why a pose got no mask, in words."""
        if self.moved <= 0.0:
            return "moves no skin"
        if self.peak_stretch > WRINKLING_COMPRESSION:
            return (f"only stretches the skin (up to {100 * self.peak_stretch:.0f} %; "
                    f"compression at most {100 * self.peak_compression:.1f} %)")
        return (f"moves the skin without deforming it (a rotation or translation; "
                f"compression at most {100 * self.peak_compression:.1f} %)")
