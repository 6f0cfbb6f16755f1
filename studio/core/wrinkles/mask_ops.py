"""Whole-mask operations for technique-1 authoring: fill, blur, invert, levels, resample, mirror,
the overlap analysis and the auto mask from a pose.

All return new arrays (the caller turns before/after into an undo step) and are vectorised.
Masks follow studio.core.wrinkles.influence: (H, W) float32 in [0, 1], row 0 = top = v 1.
"""

from __future__ import annotations

import numpy as np
from PIL import Image

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.skin_strain import SkinStrain, compression_weights

Array = np.ndarray
RESOLUTIONS = (512, 1024, 2048, 4096)


def fill(mask: Array, value: float = 1.0) -> Array:
    return np.full_like(mask, np.float32(np.clip(value, 0.0, 1.0)))


def invert(mask: Array) -> Array:
    return (np.float32(1.0) - mask).astype(np.float32)


def levels(mask: Array, black: float = 0.0, white: float = 1.0, gamma: float = 1.0) -> Array:
    """Map [black, white] to [0, 1] then apply gamma (>1 brightens mid-tones, as in GIMP)."""
    span = max(white - black, 1e-6)
    t = np.clip((mask - np.float32(black)) / np.float32(span), 0.0, 1.0)
    return np.power(t, np.float32(1.0 / max(gamma, 1e-3))).astype(np.float32)


def _box(a: Array, r: int, axis: int) -> Array:
    """Box filter of half-width r along an axis, edges clamped (cumulative sums: O(N))."""
    pad = [(0, 0)] * a.ndim
    pad[axis] = (r + 1, r)
    c = np.moveaxis(np.cumsum(np.pad(a, pad, mode="edge"), axis=axis, dtype=np.float64),
                    axis, -1)
    n = a.shape[axis]
    out = (c[..., 2 * r + 1:2 * r + 1 + n] - c[..., :n]) / (2 * r + 1)
    return np.moveaxis(out, -1, axis).astype(np.float32)


def blur(mask: Array, radius: float) -> Array:
    """Approximate Gaussian blur (three box passes per axis); ``radius`` ≈ σ·2 in pixels.

    A 2-D mask is blurred over the box of its non-zero pixels grown by the blur's reach only:
    outside that box the passes add zeros to zeros, so the result there is exactly 0 and
    inside it is bit for bit the whole image's (the passes' running sums start from exactly
    0 either way). A pose's mask covers a small part of the map: the set-up and the
    synthesis blur hundreds of them."""
    r = max(round(radius / 2.0), 0)
    if r == 0:
        return mask.copy()
    out = mask.astype(np.float32)
    if out.ndim != 2:
        for _ in range(3):
            out = _box(_box(out, r, 0), r, 1)
        return np.clip(out, 0.0, 1.0)
    box = _reach(out, 3 * r)
    if box is None:  # nothing to blur
        return np.clip(out, 0.0, 1.0)
    if box == (slice(0, out.shape[0]), slice(0, out.shape[1])):
        return _blur_2d(out, r)
    result = np.zeros_like(out)
    result[box] = _blur_2d(out[box], r)
    return result


def _reach(image: Array, reach: int) -> tuple[slice, slice] | None:
    """The rows and columns of ``image``'s non-zero pixels grown by ``reach`` (within the
    image); None when every pixel is 0."""
    rows = np.flatnonzero(image.any(axis=1))
    if not rows.size:
        return None
    cols = np.flatnonzero(image.any(axis=0))
    h, w = image.shape
    return (slice(max(rows[0] - reach, 0), min(rows[-1] + reach + 1, h)),
            slice(max(cols[0] - reach, 0), min(cols[-1] + reach + 1, w)))


def _blur_2d(image: Array, r: int) -> Array:
    """``blur``'s passes over a whole 2-D float32 image, clipped to [0, 1]."""
    # the passes along the rows, then along the rows of the transposed image: box filters on
    # the two axes commute, and numpy's cumulative sum down axis 0 steps a whole row at a time
    # through memory, several times slower (the sample's set-up blurs some 200 maps)
    out = image
    for _ in range(3):
        out = _box(out, r, 1)
    out = np.ascontiguousarray(out.T)
    for _ in range(3):
        out = _box(out, r, 1)
    return np.clip(np.ascontiguousarray(out.T), 0.0, 1.0)


def resample(mask: Array, size: int | tuple[int, int]) -> Array:
    """A mask at another resolution (w, h or a square size); area-averaged when shrinking."""
    w, h = (size, size) if isinstance(size, int) else size
    if mask.shape == (h, w):
        return mask.astype(np.float32, copy=True)
    image = Image.fromarray(np.ascontiguousarray(mask, dtype=np.float32), mode="F")
    shrink = w < mask.shape[1] or h < mask.shape[0]
    method = Image.Resampling.BOX if shrink else Image.Resampling.BILINEAR
    return np.clip(np.asarray(image.resize((w, h), method), dtype=np.float32), 0.0, 1.0)


def mirror_u(mask: Array, source: str = "left") -> Array:
    """Copy one half of the UV square onto the other across u = 0.5 (the face's symmetry).

    ``source``: "left" keeps the image's left half (u < 0.5) and mirrors it right, "right" the
    reverse, "max" keeps the stronger of each pixel and its mirror.
    """
    flipped = mask[:, ::-1]
    if source == "max":
        return np.maximum(mask, flipped)
    w = mask.shape[1]
    out = mask.copy()
    half = w // 2
    if source == "left":
        out[:, w - half:] = flipped[:, w - half:]
    else:
        out[:, :half] = flipped[:, :half]
    return out


# --- overlap analysis ----------------------------------------------------------------------------

def weighted_sum(masks: Array, activations: Array) -> Array:
    """Σ mask_i · a_i per pixel, before the shader's clamp."""
    if len(masks) == 0:
        return np.zeros((1, 1), np.float32)
    return np.tensordot(np.asarray(activations, np.float32), masks, axes=1).astype(np.float32)


def overlap(masks: Array, activations: Array, coverage: Array | None = None,
            limit: float = 1.0) -> tuple[Array, Array]:
    """(over, uncovered): where the weighted sum exceeds ``limit`` (the clamp hides a conflict),
    and where no area reaches at all (inside ``coverage``, the UV layout, when given)."""
    over = weighted_sum(masks, activations) > limit + 1e-4
    none = ~(masks > 0.0).any(axis=0) if len(masks) else np.ones_like(over)
    if coverage is not None:
        none &= coverage
    return over, none


# --- auto mask from a pose -----------------------------------------------------------------------

def mesh_edges(triangles: Array) -> Array:
    """Unique undirected edges (E, 2) of triangles over welded vertices."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    e = np.sort(e, axis=1)
    return np.unique(e, axis=0)


def vertex_compression(rest: Array, posed: Array, triangles: Array) -> Array:
    """Per-vertex skin compression: the mean shortening (−Δl/l, ≥ 0) of a vertex's edges."""
    edges = mesh_edges(triangles)
    a, b = edges[:, 0], edges[:, 1]
    l0 = np.linalg.norm(rest[a] - rest[b], axis=1).astype(np.float64)
    l1 = np.linalg.norm(posed[a] - posed[b], axis=1).astype(np.float64)
    shrink = np.maximum(-(l1 - l0) / np.maximum(l0, 1e-12), 0.0)
    n = len(rest)
    total = np.bincount(a, shrink, n) + np.bincount(b, shrink, n)
    count = np.bincount(a, minlength=n) + np.bincount(b, minlength=n)
    return (total / np.maximum(count, 1)).astype(np.float32)


def rasterise_uv(uvs: Array, triangles: Array, values: Array, size: int,
                 batch: int = 2048) -> tuple[Array, Array]:
    """Per-render-vertex values drawn into a (size, size) UV image, barycentrically interpolated.

    Returns (image, coverage). Vectorised per batch of triangles: each triangle's bounding box
    is padded to the batch's largest, every pixel centre in it gets barycentric coordinates and
    the inside ones are written.
    """
    img = np.zeros((size, size), np.float32)
    cov = np.zeros((size, size), bool)
    # pixel coordinates: x = u·size, y = (1 − v)·size
    p = np.c_[uvs[:, 0] * size, (1.0 - uvs[:, 1]) * size].astype(np.float64)
    tri = np.asarray(triangles)
    corners = p[tri]  # (F, 3, 2)
    lo = np.floor(corners.min(axis=1) - 0.5).astype(int)
    hi = np.ceil(corners.max(axis=1) - 0.5).astype(int)
    extent = hi - lo + 1
    order = np.argsort(extent.max(axis=1))  # similar sizes batch together: less padding
    for start in range(0, len(tri), batch):
        idx = order[start:start + batch]
        bw, bh = (int(v) for v in extent[idx].max(axis=0))
        if bw * bh * len(idx) > 8_000_000:  # keep a batch's grid modest
            idx_parts = np.array_split(idx, int(np.ceil(bw * bh * len(idx) / 8_000_000)))
        else:
            idx_parts = [idx]
        for part in idx_parts:
            gx = lo[part, 0, None, None] + np.arange(bw)[None, None, :]
            gy = lo[part, 1, None, None] + np.arange(bh)[None, :, None]
            cx, cy = gx + 0.5, gy + 0.5
            a, b, c = corners[part, 0], corners[part, 1], corners[part, 2]
            e1, e2 = b - a, c - a
            det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            ok = np.abs(det) > 1e-12
            inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)[:, None, None]
            dx, dy = cx - a[:, 0, None, None], cy - a[:, 1, None, None]
            w1 = (dx * e2[:, 1, None, None] - dy * e2[:, 0, None, None]) * inv
            w2 = (e1[:, 0, None, None] * dy - e1[:, 1, None, None] * dx) * inv
            w0 = 1.0 - w1 - w2
            eps = -1e-6
            inside = ((w0 >= eps) & (w1 >= eps) & (w2 >= eps) & ok[:, None, None]
                      & (gx >= 0) & (gx < size) & (gy >= 0) & (gy < size))
            vals = values[tri[part]]  # (n, 3)
            v = (w0 * vals[:, 0, None, None] + w1 * vals[:, 1, None, None]
                 + w2 * vals[:, 2, None, None])
            k, yy, xx = np.nonzero(inside)
            img[gy[k, yy, 0], gx[k, 0, xx]] = v[k, yy, xx]
            cov[gy[k, yy, 0], gx[k, 0, xx]] = True
    return img, cov


def uv_coverage(mesh: FaceMesh, size: int) -> Array:
    """Where the UV layout has triangles, (size, size) bool."""
    return rasterise_uv(mesh.uvs, mesh.triangles, np.zeros(mesh.n_vertices, np.float32),
                        size)[1]


def auto_mask(mesh: FaceMesh, posed_welded: Array, size: int, threshold: float = 0.1,
              softness: float = 4.0, work_size: int = 1024) -> Array:
    """A soft UV mask where the pose compresses the skin.

    Compression is the smallest principal stretch's shortfall (``skin_strain``: a sideways
    squeeze counts even where the area stays the same), normalised by its 98th percentile over
    compressed vertices; values below
    ``threshold`` of that drop to 0; the result is rasterised at ``work_size`` at most (the mask
    is smooth, so that loses nothing), blurred by ``softness`` pixels of the target size and
    resampled to ``size``.
    """
    strain = SkinStrain(mesh)
    compression = strain.of(np.asarray(posed_welded, np.float32)).compression
    strength = compression_weights(strain, compression, threshold)
    work = min(size, work_size)
    img = surface_image(mesh, strength, work, softness * work / size)
    img = blur(img, softness * work / size)
    out = resample(img, size)
    out[out < 1e-3] = 0.0
    return out


# --- smooth per-vertex fields on a coarse mesh ---------------------------------------------------

COARSE = 3.0  # UV edges this many blur radii long or more: triangles would show in a mask
COARSE_TEXELS = 8.0  # … and at least this many texels
KERNEL_EDGES = 1.0  # the kernel's reach on the surface, in the mesh's median edge lengths
_PAIRS = 1 << 22  # texel-vertex pairs per step of the kernel sums (~100 MB)


def surface_image(mesh: FaceMesh, welded: Array, size: int, blur_px: float) -> Array:
    """Per-welded-vertex values as a (size, size) UV image, interpolated over the triangles —
    or, on a mesh whose UV triangles are several blur radii across (a low-resolution face),
    as a smooth kernel average of the vertices around each texel's point on the surface.

    Why: a value interpolated across a triangle is linear there, so a region that ends at
    some vertices ends along triangle edges; on a coarse mesh the blur is far too small to hide
    that, and a mask shows the triangles. Weighing the vertices within ``KERNEL_EDGES`` median
    edges of the texel's 3D point (``(1 − d²/r²)³``) gives a field as smooth as the surface,
    whatever the triangulation; measured on the surface, so it never crosses a UV seam or
    bleeds into the chart packed beside it.
    """
    values = np.asarray(welded, np.float32)
    tri = mesh.triangles
    image, covered = rasterise_uv(mesh.uvs, tri, values[mesh.weld], size)
    active = np.flatnonzero(values > 0.0)
    if not coarse(mesh, size, blur_px) or len(active) == 0:
        return image
    rest = mesh.rest.astype(np.float64)
    welded_tris = mesh.welded_triangles
    edges = np.linalg.norm(rest[welded_tris] - rest[np.roll(welded_tris, 1, axis=1)], axis=2)
    reach = KERNEL_EDGES * float(np.median(edges))
    # each covered texel's point on the surface: positions are linear in a triangle too
    texels = np.flatnonzero(covered)
    points = np.stack([rasterise_uv(mesh.uvs, tri, rest[mesh.weld][:, k].astype(np.float32),
                                    size)[0].ravel()[texels] for k in range(3)], axis=1)
    # a texel weighs only the vertices of its own shell: an eyelid's value never reaches the
    # eyeball beneath it (a shell's label is exact in its triangles: their corners share it)
    shell = _shells(welded_tris, len(rest))
    texel_shell = np.rint(rasterise_uv(mesh.uvs, tri, shell[mesh.weld].astype(np.float32),
                                       size)[0].ravel()[texels]).astype(np.int64)
    # only texels near a vertex with a value can change, and only vertices near those count
    near_active = _within(points, rest[active], reach)
    candidates = np.flatnonzero(_within(rest, rest[active], 2.0 * reach))
    out = image.ravel().copy()
    todo = texels[near_active]
    pts = points[near_active]
    own = texel_shell[near_active]
    step = _chunk(len(candidates))
    for start in range(0, len(todo), step):
        p = pts[start:start + step]
        d2 = ((p[:, None, :] - rest[candidates][None]) ** 2).sum(-1) / reach ** 2
        w = np.clip(1.0 - d2, 0.0, None) ** 3
        w *= own[start:start + step, None] == shell[candidates][None]
        total = w.sum(axis=1)
        smooth = (w @ values[candidates].astype(np.float64)) / np.maximum(total, 1e-12)
        keep = total > 1e-6  # a texel no vertex reaches keeps its interpolated value
        out[todo[start:start + step][keep]] = smooth[keep]
    return out.reshape(size, size).astype(np.float32)


def _shells(triangles: Array, n: int) -> Array:
    """(n,) int: each vertex's connected shell, labelled by its smallest vertex index."""
    label = np.arange(n)
    edges = mesh_edges(triangles)
    while True:
        low = np.minimum(label[edges[:, 0]], label[edges[:, 1]])
        before = label.copy()
        np.minimum.at(label, edges[:, 0], low)
        np.minimum.at(label, edges[:, 1], low)
        label = label[label]  # jump to the label's own label: far fewer rounds
        if np.array_equal(label, before):
            return label


def coarse(mesh: FaceMesh, size: int, blur_px: float) -> bool:
    """Whether the mesh's UV triangles would show in a mask drawn at ``size`` and blurred by
    ``blur_px``: their median edge is ``COARSE`` blur radii and ``COARSE_TEXELS`` texels long
    or more (a 1,220-vertex face at 512 or more; the ICT head's 26,719 vertices never)."""
    uv = mesh.uvs[mesh.triangles].astype(np.float64)
    edge_px = float(np.median(np.linalg.norm(uv - np.roll(uv, 1, axis=1), axis=2))) * size
    return edge_px >= max(COARSE * max(blur_px, 1.0), COARSE_TEXELS)


def _within(points: Array, centres: Array, reach: float) -> Array:
    """(len(points),) bool: within ``reach`` of any centre (brute force, in chunks)."""
    found = np.zeros(len(points), bool)
    step = _chunk(len(centres))
    for start in range(0, len(points), step):
        p = points[start:start + step]
        d2 = ((p[:, None, :] - centres[None]) ** 2).sum(-1).min(axis=1)
        found[start:start + step] = d2 <= reach * reach
    return found


def _chunk(others: int) -> int:
    """Rows per step so that a step's (rows, others, 3) differences stay near 100 MB."""
    return max(1, _PAIRS // max(others, 1))
