"""Brush dabs and strokes on a mask, touching only the dab's bounding rectangle.

Why rectangles: a 4096² mask is 64 MB of float32; a dab must cost what its footprint costs, so
each dab slices the mask to its bounding box and works there (vectorised, no per-pixel loops).
The stroke records the tiles it touched (before its first change) so that undo stores only what
changed, and reports each touched rectangle so the GPU uploads only that.

Coordinates are mask pixels: x right, y down (row 0 = top = v 1); pixel (i, j) covers
[i, i+1) × [j, j+1), so its centre is (i + 0.5, j + 0.5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

Array = np.ndarray
Rect = tuple[int, int, int, int]  # x, y, w, h
TILE = 64


@dataclass
class Brush:
    radius: float = 24.0  # mask pixels
    hardness: float = 0.5  # fraction of the radius painted at full strength; the rest fades
    opacity: float = 1.0  # the most one stroke builds up to (paint) or removes (erase)
    flow: float = 0.5  # how much of the way to ``opacity`` each dab goes
    erase: bool = False
    spacing: float = 0.2  # distance between dabs, as a fraction of the radius


def falloff(distance: Array, radius: float, hardness: float) -> Array:
    """1 inside ``hardness·radius``, a smoothstep down to 0 at the radius (soft edges, [4.2.1])."""
    d = distance / max(radius, 1e-6)
    h = min(max(hardness, 0.0), 0.999)
    t = np.clip((1.0 - d) / (1.0 - h), 0.0, 1.0)
    return (t * t * (3.0 - 2.0 * t)).astype(np.float32)


def union(a: Rect | None, b: Rect | None) -> Rect | None:
    if a is None:
        return b
    if b is None:
        return a
    x0, y0 = min(a[0], b[0]), min(a[1], b[1])
    x1, y1 = max(a[0] + a[2], b[0] + b[2]), max(a[1] + a[3], b[1] + b[3])
    return (x0, y0, x1 - x0, y1 - y0)


def dab_rect(shape: tuple[int, int], x: float, y: float, radius: float) -> Rect | None:
    """Pixels whose centres may lie within ``radius`` of (x, y), clipped to the mask."""
    h, w = shape
    x0 = max(math.floor(x - radius - 0.5), 0)
    y0 = max(math.floor(y - radius - 0.5), 0)
    x1 = min(math.ceil(x + radius + 0.5), w)
    y1 = min(math.ceil(y + radius + 0.5), h)
    if x1 <= x0 or y1 <= y0:
        return None
    return (x0, y0, x1 - x0, y1 - y0)


def dab_weights(rect: Rect, x: float, y: float, brush: Brush) -> Array:
    """The dab's strength (0..1 falloff) over its rectangle."""
    x0, y0, w, h = rect
    px = np.arange(x0, x0 + w, dtype=np.float32) + np.float32(0.5 - x)
    py = np.arange(y0, y0 + h, dtype=np.float32) + np.float32(0.5 - y)
    dist = np.sqrt(py[:, None] ** 2 + px[None, :] ** 2)
    return falloff(dist, brush.radius, brush.hardness)


def stamp(mask: Array, x: float, y: float, brush: Brush, pressure: float = 1.0) -> Rect | None:
    """Apply one dab in place; returns the touched rectangle (None when off the mask).

    Paint moves each pixel ``flow·falloff·pressure`` of the way up to ``opacity`` (never down);
    erase moves it that far toward 0, scaled by ``opacity``.
    """
    rect = dab_rect(mask.shape, x, y, brush.radius)
    if rect is None:
        return None
    x0, y0, w, h = rect
    a = dab_weights(rect, x, y, brush) * np.float32(brush.flow * max(pressure, 0.0))
    region = mask[y0:y0 + h, x0:x0 + w]
    if brush.erase:
        region -= region * (a * np.float32(brush.opacity))
    else:
        target = np.float32(brush.opacity)
        region += np.maximum(target - region, 0.0) * a
    np.clip(region, 0.0, 1.0, out=region)
    return rect


class TileBackup:
    """The mask's tiles as they were before an edit first touched them: one undo step's data."""

    def __init__(self, mask: Array, tile: int = TILE) -> None:
        self.mask = mask
        self.tile = tile
        self.before: dict[tuple[int, int], Array] = {}

    def touch(self, rect: Rect) -> None:
        """Call before changing ``rect``: copies the tiles not saved yet."""
        x, y, w, h = rect
        t = self.tile
        for ty in range(y // t, (y + h - 1) // t + 1):
            for tx in range(x // t, (x + w - 1) // t + 1):
                if (ty, tx) not in self.before:
                    self.before[(ty, tx)] = self.mask[ty * t:(ty + 1) * t,
                                                      tx * t:(tx + 1) * t].copy()

    def changes(self) -> list[tuple[int, int, Array, Array]]:
        """(x, y, before, after) per touched tile that really changed."""
        t = self.tile
        out = []
        for (ty, tx), before in sorted(self.before.items()):
            after = self.mask[ty * t:ty * t + before.shape[0], tx * t:tx * t + before.shape[1]]
            if not np.array_equal(before, after):
                out.append((tx * t, ty * t, before, after.copy()))
        return out


def tile_changes(before: Array, after: Array, tile: int = TILE
                 ) -> list[tuple[int, int, Array, Array]]:
    """The tiles where two masks of one size differ, as (x, y, before, after) (whole-mask edits)."""
    h, w = before.shape
    ny, nx = -(-h // tile), -(-w // tile)
    pad = ((0, ny * tile - h), (0, nx * tile - w))
    diff = np.pad(before != after, pad).reshape(ny, tile, nx, tile).any(axis=(1, 3))
    out = []
    for ty, tx in zip(*np.nonzero(diff), strict=True):
        sl = np.s_[ty * tile:(ty + 1) * tile, tx * tile:(tx + 1) * tile]
        out.append((int(tx) * tile, int(ty) * tile, before[sl].copy(), after[sl].copy()))
    return out


class Mirror(Protocol):
    """Where a stroke's dabs are mirrored to: dab centres (N, 2) in mask pixels → (index of the
    source dab, mirrored centre, radius scale) per mirror image; a dab may have none or several
    (one per UV chart at a seam). Mirrors: ``UvMirror``, studio.core.wrinkles.surface_mirror's
    ``SurfaceMirror``."""

    def __call__(self, points: Array, shape: tuple[int, int], radius: float
                 ) -> tuple[Array, Array, Array]: ...


class UvMirror:
    """u → 1 − u: the face's mirror when its UV layout is symmetric about u = 0.5."""

    def __call__(self, points: Array, shape: tuple[int, int], radius: float
                 ) -> tuple[Array, Array, Array]:
        pts = np.asarray(points, np.float64).reshape(-1, 2)
        return np.arange(len(pts)), np.c_[shape[1] - pts[:, 0], pts[:, 1]], np.ones(len(pts))


class Stroke:
    """A drag of the brush: dabs spaced along the path, each also at its mirror images when the
    stroke has a mirror (``True``: u → 1 − u)."""

    def __init__(self, mask: Array, brush: Brush, mirror: bool | Mirror | None = False) -> None:
        self.mask = mask
        self.brush = brush
        self.mirror: Mirror | None = UvMirror() if mirror is True else (mirror or None)
        self.backup = TileBackup(mask)
        self.last: tuple[float, float, float] | None = None
        self.dabs = 0
        self._carry = 0.0  # path length since the last dab

    def _dabs(self, points: Array, pressures: Array) -> Rect | None:
        """Stamp dabs at points (N, 2) and their mirror images (all mirrored in one call)."""
        radii = np.full(len(points), self.brush.radius)
        if self.mirror is not None and len(points):
            owner, mirrored, scale = self.mirror(points, self.mask.shape, self.brush.radius)
            points = np.concatenate([points, mirrored])
            pressures = np.concatenate([pressures, pressures[owner]])
            radii = np.concatenate([radii, self.brush.radius * scale])
        touched = None
        for (x, y), pressure, radius in zip(points.tolist(), pressures.tolist(), radii.tolist(),
                                            strict=True):
            rect = dab_rect(self.mask.shape, x, y, radius)
            if rect is None:
                continue
            brush = self.brush if radius == self.brush.radius else replace(self.brush,
                                                                            radius=radius)
            self.backup.touch(rect)
            touched = union(touched, stamp(self.mask, x, y, brush, pressure))
        return touched

    def jump(self, x: float, y: float, pressure: float = 1.0) -> Rect | None:
        """Start (or restart, after crossing a UV seam) at a point: one dab there."""
        self.last = (x, y, pressure)
        self._carry = 0.0
        self.dabs += 1
        return self._dabs(np.array([[x, y]], np.float64), np.array([pressure], np.float64))

    def to(self, x: float, y: float, pressure: float = 1.0) -> Rect | None:
        """Continue to a point, laying dabs every ``spacing·radius`` along the way."""
        if self.last is None:
            return self.jump(x, y, pressure)
        x0, y0, p0 = self.last
        step = max(self.brush.spacing * self.brush.radius, 0.5)
        length = math.hypot(x - x0, y - y0)
        first = step - self._carry
        self.last = (x, y, pressure)
        if first > length:
            self._carry += length
            return None
        s = first + step * np.arange(int((length - first) // step) + 1)
        self._carry = length - float(s[-1])
        f = s / length if length > 0.0 else np.zeros_like(s)
        self.dabs += len(s)
        return self._dabs(np.c_[x0 + (x - x0) * f, y0 + (y - y0) * f], p0 + (pressure - p0) * f)
