"""Technique 2 data: wrinkle direction vectors per area (SPEC §5).

Each area names the key pose whose motion creates its wrinkles. "Create wrinkle directions" sets
``d = normalize(P_target − P_rest)`` and the reference length ``|P_target − P_rest|`` for the
selected vertices. A vertex may belong to several areas; the renderer receives up to
``SLOTS`` (area) entries per vertex and shows the strongest one, so the result does not depend on
area order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray

SLOTS = 4  # areas one vertex can belong to at once
STILL_EPSILON = 1e-6  # relative to the mesh size: below this a vertex "does not move"


@dataclass(eq=False)
class WdvArea:
    name: str
    pose: str
    directions: Array  # (W, 3) float32 unit vectors, zero where not authored
    lengths: Array  # (W,) float32 authored displacement lengths, zero where not authored
    colour: tuple[int, int, int] = (0, 170, 255)
    cone_angle_deg: float = 20.0
    enabled: bool = True

    def __post_init__(self) -> None:
        self.directions = np.ascontiguousarray(self.directions, dtype=np.float32)
        self.lengths = np.ascontiguousarray(self.lengths, dtype=np.float32)

    @classmethod
    def empty(cls, name: str, pose: str, n_welded: int, **kwargs) -> WdvArea:
        return cls(name, pose, np.zeros((n_welded, 3), np.float32), np.zeros(n_welded, np.float32),
                   **kwargs)

    @property
    def authored(self) -> Array:
        return self.lengths > 0.0


@dataclass
class WdvResult:
    directions: Array  # (W, 3)
    lengths: Array  # (W,)
    still: Array  # indices of selected vertices that do not move in the pose


def wrinkle_directions(rest: Array, target: Array, selected: Array) -> WdvResult:
    """Directions and reference lengths for the selected vertices; zero elsewhere.

    Vertices that do not move toward the target get no direction (and are reported in ``still``)
    instead of a NaN.
    """
    delta = (target - rest).astype(np.float32)
    length = np.linalg.norm(delta, axis=1)
    scale = float(np.ptp(rest, axis=0).max()) or 1.0
    selected = np.asarray(selected)
    mask = np.zeros(len(rest), dtype=bool)
    mask[selected] = True
    moving = length > STILL_EPSILON * scale
    use = mask & moving
    directions = np.zeros_like(delta)
    directions[use] = delta[use] / length[use, None]
    lengths = np.where(use, length, 0.0).astype(np.float32)
    return WdvResult(directions, lengths, np.flatnonzero(mask & ~moving))


@dataclass(eq=False)
class WdvSetup:
    areas: list[WdvArea] = field(default_factory=list)
    expression_factor: float = 1.0  # k in SPEC §5
    scale_free: bool = True  # divide |δ| by the authored length, so w = k at the key pose

    def pack_slots(self, n_welded: int) -> tuple[Array, Array]:
        """Per-vertex slots for the renderer.

        Returns ``dirs`` (W, SLOTS, 4) holding direction xyz and authored length, and ``cones``
        (W, SLOTS) holding each slot's cone half-angle in radians. Unused slots are zero.
        """
        dirs = np.zeros((n_welded, SLOTS, 4), dtype=np.float32)
        cones = np.zeros((n_welded, SLOTS), dtype=np.float32)
        used = np.zeros(n_welded, dtype=np.int32)
        for area in self.areas:
            if not area.enabled:
                continue
            idx = np.flatnonzero(area.authored & (used < SLOTS))
            slot = used[idx]
            dirs[idx, slot, :3] = area.directions[idx]
            dirs[idx, slot, 3] = area.lengths[idx]
            cones[idx, slot] = np.radians(area.cone_angle_deg)
            used[idx] += 1
        return dirs, cones
