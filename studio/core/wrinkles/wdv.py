"""Technique 2 data: wrinkle direction vectors per area.

Each area names the key pose whose motion creates its wrinkles. "Create wrinkle directions" sets
``d = normalize(P_target − P_rest)`` and the reference length ``|P_target − P_rest|`` for the
selected vertices. A vertex may belong to several areas; the renderer receives up to
``SLOTS`` (area) entries per vertex and shows the strongest one, so the result does not depend on
area order.
"""

from __future__ import annotations

from collections.abc import Callable
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
    wrinkle_map: str = ""  # the wrinkled normal map this area reveals ("" = the first one)
    # (W,) painted per-vertex cone half-angles in degrees; 0 (or None: all) = the area's angle
    cone_angles_deg: Array | None = None

    def __post_init__(self) -> None:
        self.directions = np.ascontiguousarray(self.directions, dtype=np.float32)
        self.lengths = np.ascontiguousarray(self.lengths, dtype=np.float32)
        if self.cone_angles_deg is not None:
            self.cone_angles_deg = np.ascontiguousarray(self.cone_angles_deg, dtype=np.float32)

    def vertex_cones_deg(self) -> Array:
        """(W,) cone half-angle of each vertex: painted where painted, else the area's."""
        area = np.float32(self.cone_angle_deg)
        if self.cone_angles_deg is None:
            return np.full(len(self.lengths), area, np.float32)
        return np.where(self.cone_angles_deg > 0.0, self.cone_angles_deg, area).astype(np.float32)

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
    expression_factor: float = 1.0  # k, the expression factor of the visibility formula
    scale_free: bool = True  # divide |δ| by the authored length, so w = k at the key pose

    def pack_slots(self, n_welded: int,
                   map_index: Callable[[str], int] | None = None) -> WdvSlots:
        """Per-vertex slots for the renderer (see ``WdvSlots``); unused slots are zero.

        A vertex in more than ``SLOTS`` areas keeps the areas with the longest authored motion
        (the ones whose wrinkles show most), whatever the list order. ``map_index`` turns an
        area's wrinkled-map name into the shader's map index.
        """
        slots = WdvSlots(np.zeros((n_welded, SLOTS, 4), dtype=np.float32),
                         np.zeros((n_welded, SLOTS), dtype=np.float32),
                         np.zeros((n_welded, SLOTS), dtype=np.float32))
        areas = [a for a in self.areas if a.enabled]
        if not areas:
            return slots
        lengths = np.stack([a.lengths for a in areas])  # (A, W)
        keep = min(SLOTS, len(areas))
        # per vertex, the areas with the longest motion first (stable: list order breaks ties)
        order = np.argsort(-lengths, axis=0, kind="stable")[:keep]  # (keep, W)
        for a_index, area in enumerate(areas):
            cones = np.radians(area.vertex_cones_deg())
            wrinkle_map = map_index(area.wrinkle_map) if map_index else 0
            for slot in range(keep):  # a handful of slots, each vectorised over every vertex
                idx = np.flatnonzero((order[slot] == a_index) & area.authored)
                slots.dirs[idx, slot, :3] = area.directions[idx]
                slots.dirs[idx, slot, 3] = area.lengths[idx]
                slots.cones[idx, slot] = cones[idx]
                slots.maps[idx, slot] = wrinkle_map
        return slots


@dataclass
class WdvSlots:
    """What the technique-2 vertex shader reads per vertex, for up to ``SLOTS`` areas."""

    dirs: Array  # (W, SLOTS, 4) direction xyz and authored length
    cones: Array  # (W, SLOTS) cone half-angle in radians
    maps: Array  # (W, SLOTS) index of the wrinkled normal map the slot's area reveals


def visibility(delta: Array, slots: WdvSlots, expression_factor: float = 1.0,
               scale_free: bool = True) -> Array:
    """The numpy reference of shaders/face.vert's ``wdv_visibility``: per vertex, for each
    wrinkled map, the strongest slot's ``clamp(m · (1 − α/θ) · k, 0, 1)`` where the motion
    ``delta`` lies inside the slot's cone (α < θ), m = |delta| (over the authored length when
    ``scale_free``), k the expression factor; (V, 4)."""
    delta = np.asarray(delta, np.float64)
    length = np.linalg.norm(delta, axis=1)
    out = np.zeros((len(delta), 4))
    for s in range(slots.dirs.shape[1]):
        d = slots.dirs[:, s, :3].astype(np.float64)
        authored = slots.dirs[:, s, 3].astype(np.float64)
        theta = slots.cones[:, s].astype(np.float64)
        used = (authored > 0) & (theta > 0) & (length > 0)
        cos = np.einsum("ij,ij->i", delta, d) / np.where(length > 0, length, 1.0)
        alpha = np.arccos(np.clip(cos, -1.0, 1.0))
        inside = used & (alpha < theta)
        magnitude = length / np.where(authored > 0, authored, 1.0) if scale_free else length
        w = np.clip(magnitude * (1.0 - alpha / np.where(theta > 0, theta, 1.0))
                    * expression_factor, 0.0, 1.0)
        w = np.where(inside, w, 0.0)
        maps = slots.maps[:, s].astype(np.int64)
        for m in range(4):
            out[:, m] = np.maximum(out[:, m], np.where(maps == m, w, 0.0))
    return out
