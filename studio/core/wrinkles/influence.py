"""Technique 1 data: influence-area masks, the activation vector, and links from poses.

Masks are UV-space greyscale images with 1 = full influence, all of one resolution so they pack
into one texture array. Image row 0 is the top of the UV square (v = 1), as in any image editor.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from studio.core.wrinkles.response import CurveBank, CurveTable, ResponseCurve

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
    """What ``activations`` derives from the areas, links and curves, kept until one changes."""

    areas: list[InfluenceArea]  # the list it was built from (its items compared by identity)
    edits: int  # ``_Edits.count`` when it was built
    links: dict[str, dict[str, float]]  # a copy of the links it was built from
    curves: dict[str, dict[str, ResponseCurve]]  # and of their curves
    base: Array  # (N,) float64: each area's own activation
    hidden: Array  # (N,) bool
    rows: dict[str, int]  # linked pose -> its row of ``gains``
    gains: Array  # (P, N) float64: gain of each linked pose for each area (linear links)
    # the links with another curve, one entry each: their pose rows, the bank that evaluates
    # all their curves at once, and where each response goes (its gain in its area's column)
    curved_rows: Array  # (L,) intp
    bank: CurveBank
    curved_gains: Array  # (L, N) float64

    @classmethod
    def build(cls, areas: list[InfluenceArea], links: Mapping[str, Mapping[str, float]],
              curves: CurveTable) -> _Gains:
        """Linear links go into the gain matrix (the product is exactly the one made before
        curves existed); the others into flat per-link arrays for one vectorised pass."""
        column = {a.name: i for i, a in enumerate(areas)}  # a repeated name: its last area
        rows = {pose: r for r, pose in enumerate(links)}
        gains = np.zeros((len(rows), len(areas)))
        curved: list[tuple[int, int, float, ResponseCurve]] = []
        for r, (pose, pose_gains) in enumerate(links.items()):
            pose_curves = curves.get(pose, {})
            for area, gain in pose_gains.items():
                if area not in column:
                    continue
                curve = pose_curves.get(area)
                if curve is None or curve.linear:
                    gains[r, column[area]] += gain
                else:
                    curved.append((r, column[area], gain, curve))
        return cls(list(areas), _Edits.count, {p: dict(g) for p, g in links.items()},
                   {p: dict(c) for p, c in curves.items()},
                   np.array([a.activation for a in areas], dtype=np.float64),
                   np.array([not a.visible for a in areas], dtype=bool), rows, gains,
                   np.array([c[0] for c in curved], dtype=np.intp),
                   CurveBank([c[3] for c in curved]), cls._scatter(curved, len(areas)))

    @staticmethod
    def _scatter(curved: list[tuple[int, int, float, ResponseCurve]], n_areas: int) -> Array:
        matrix = np.zeros((len(curved), n_areas))
        for i, (_, column, gain, _) in enumerate(curved):
            matrix[i, column] = gain
        return matrix

    def current(self, areas: list[InfluenceArea], links: Mapping, curves: Mapping) -> bool:
        """Still valid: no area edited, the same areas in the same order, equal links and
        curves (C-level comparisons, so any way of editing them is noticed)."""
        return (self.edits == _Edits.count and self.areas == areas and self.links == links
                and self.curves == curves)

    def add_links(self, values: Array, weights: Array) -> None:
        """Add every link's ``gain · curve(weight)`` to ``values`` (..., N), in place, for pose
        weights (..., P) in the rows' order (leading axes: one frame or many)."""
        values += weights @ self.gains
        if self.bank.size:
            values += self.bank.evaluate(weights[..., self.curved_rows]) @ self.curved_gains


@dataclass(eq=False)
class InfluenceSetup:
    areas: list[InfluenceArea] = field(default_factory=list)
    # pose name -> {area name: gain}: moving toward the pose raises those areas' activations
    links: dict[str, dict[str, float]] = field(default_factory=dict)
    # pose name -> {area name: curve}: how the pose's weight shapes that link (absent = linear).
    # Kept beside ``links`` rather than in it so every reader of the gains works unchanged; a
    # curve outlives its link's removal (a gain set to 0 and back keeps the curve).
    curves: dict[str, dict[str, ResponseCurve]] = field(default_factory=dict)

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
        """Each area's own value plus ``Σ gain·curve(weight)`` of its linked poses, clamped to
        [0, 1] (the curve is linear unless ``curves`` gives the link another).

        A frame costs one small product of the pose weights with a (poses × areas) gain matrix
        and one vectorised pass over the curved links, built again only after the areas, links
        or curves changed — not a walk over every link.
        """
        gains = self._derived()
        values = gains.base.copy()
        if pose_weights and gains.rows:
            weights = np.zeros(len(gains.rows))
            for pose, weight in pose_weights.items():
                row = gains.rows.get(pose)
                if row is not None:
                    weights[row] = weight
            gains.add_links(values, weights)
        values[gains.hidden] = 0.0
        return np.clip(values, 0.0, 1.0).astype(np.float32)

    def activations_over(self, poses: Sequence[str], weights: Array) -> Array:
        """(F, N) float64 activations for F frames at once: ``weights`` (F, len(poses)) holds
        each frame's pose weights — what the timeline draws, without a call per frame."""
        gains = self._derived()
        weights = np.asarray(weights, dtype=np.float64)
        values = np.repeat(gains.base[None, :], len(weights), axis=0)
        rows = np.zeros((len(weights), len(gains.rows)))
        for column, pose in enumerate(poses):
            row = gains.rows.get(pose)
            if row is not None:
                rows[:, row] = weights[:, column]
        gains.add_links(values, rows)
        values[:, gains.hidden] = 0.0
        return np.clip(values, 0.0, 1.0)

    def _derived(self) -> _Gains:
        """The gain matrix and curve bank, built again only if the areas, links or curves
        changed since the last call."""
        gains = self._gains
        if gains is None or not gains.current(self.areas, self.links, self.curves):
            gains = self._gains = _Gains.build(self.areas, self.links, self.curves)
        return gains
