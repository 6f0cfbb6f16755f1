"""Technique 1 data: influence-area masks, the activation vector, and links from poses.

Masks are UV-space greyscale images with 1 = full influence, all of one resolution so they pack
into one texture array. Image row 0 is the top of the UV square (v = 1), as in any image editor.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray


class _Edits:
    """How many times any area's name, activation or visibility was set: the cheap version
    stamp that tells ``InfluenceSetup.activations`` its derived gains may be stale."""

    count = 0


_STAMPED = frozenset({"name", "activation", "visible"})


@dataclass(eq=False)
class InfluenceArea:
    name: str
    mask: Array  # (H, W) float32 in [0, 1]
    colour: tuple[int, int, int] = (255, 128, 0)
    activation: float = 0.0  # the user's own slider, added to what linked poses give
    visible: bool = True
    wrinkle_map: str = ""  # the wrinkled normal map this area reveals ("" = the first one)

    def __post_init__(self) -> None:
        self.mask = np.clip(np.ascontiguousarray(self.mask, dtype=np.float32), 0.0, 1.0)

    def __setattr__(self, name: str, value: object) -> None:
        object.__setattr__(self, name, value)
        if name in _STAMPED:
            _Edits.count += 1


@dataclass(eq=False)
class _Gains:
    """What ``activations`` derives from the areas and links, kept until either changes."""

    areas: list[InfluenceArea]  # the list it was built from (its items compared by identity)
    edits: int  # ``_Edits.count`` when it was built
    links: dict[str, dict[str, float]]  # a copy of the links it was built from
    base: Array  # (N,) float64: each area's own activation
    hidden: Array  # (N,) bool
    rows: dict[str, int]  # linked pose -> its row of ``gains``
    gains: Array  # (P, N) float64: gain of each linked pose for each area

    @classmethod
    def build(cls, areas: list[InfluenceArea], links: Mapping[str, Mapping[str, float]]) -> _Gains:
        column = {a.name: i for i, a in enumerate(areas)}  # a repeated name: its last area
        rows = {pose: r for r, pose in enumerate(links)}
        gains = np.zeros((len(rows), len(areas)))
        for r, pose_gains in enumerate(links.values()):
            for area, gain in pose_gains.items():
                if area in column:
                    gains[r, column[area]] += gain
        return cls(list(areas), _Edits.count, {p: dict(g) for p, g in links.items()},
                   np.array([a.activation for a in areas], dtype=np.float64),
                   np.array([not a.visible for a in areas], dtype=bool), rows, gains)

    def current(self, areas: list[InfluenceArea], links: Mapping) -> bool:
        """Still valid: no area edited, the same areas in the same order, equal links (a
        C-level comparison, so any way of editing the links is noticed)."""
        return self.edits == _Edits.count and self.areas == areas and self.links == links


@dataclass(eq=False)
class InfluenceSetup:
    areas: list[InfluenceArea] = field(default_factory=list)
    # pose name -> {area name: gain}: moving toward the pose raises those areas' activations
    links: dict[str, dict[str, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._gains: _Gains | None = None  # derived by ``activations``, checked before each use

    @property
    def resolution(self) -> tuple[int, int] | None:
        return self.areas[0].mask.shape if self.areas else None

    def mask_stack(self) -> Array:
        """(N, H, W) float32 masks in area order, for the texture array."""
        if not self.areas:
            return np.zeros((0, 1, 1), dtype=np.float32)
        return np.stack([a.mask for a in self.areas])

    def activations(self, pose_weights: Mapping[str, float] | None = None) -> Array:
        """Each area's own value plus ``Σ gain·weight`` of its linked poses, clamped to [0, 1].

        A frame costs one small product of the pose weights with a (poses × areas) gain matrix,
        built again only after the areas or links changed — not a walk over every link.
        """
        gains = self._gains
        if gains is None or not gains.current(self.areas, self.links):
            gains = self._gains = _Gains.build(self.areas, self.links)
        values = gains.base.copy()
        if pose_weights and gains.rows:
            weights = np.zeros(len(gains.rows))
            for pose, weight in pose_weights.items():
                row = gains.rows.get(pose)
                if row is not None:
                    weights[row] = weight
            values += weights @ gains.gains
        values[gains.hidden] = 0.0
        return np.clip(values, 0.0, 1.0).astype(np.float32)
