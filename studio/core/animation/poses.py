"""Key poses and their blending.

A key pose is a full set of welded positions with the neutral mesh's topology. The face in any
frame is ``P = P_neutral + Σ_k w_k (P_k − P_neutral)``; interpolating from one pose to the next is
the special case of two weights, with either a linear or Parke's cosine easing of the fraction.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from studio.core.files.errors import MeshError

Array = np.ndarray

NEUTRAL = "neutral"


@dataclass(eq=False)
class KeyPose:
    name: str
    positions: Array  # (W, 3) float32 welded positions

    def __post_init__(self) -> None:
        self.positions = np.ascontiguousarray(self.positions, dtype=np.float32)


# Normals, tangents and strain are computed in 32-bit floats, where squared lengths of edges
# beyond about 1e19 overflow: positions are refused past this, in any unit (1e9 km in mm).
COORDINATE_LIMIT = 1e9


def coordinate_problem(positions: Array, what: str) -> str | None:
    """Why these positions cannot be used (non-finite, or past ``COORDINATE_LIMIT``), naming
    the first bad vertex; None when they can."""
    finite = np.isfinite(positions).all(axis=1)
    if not finite.all():
        return f"{what} has a non-finite coordinate at vertex {int(np.argmax(~finite))}"
    huge = (np.abs(positions) > COORDINATE_LIMIT).any(axis=1)
    if huge.any():
        v = int(np.argmax(huge))
        return (f"{what} has a coordinate of {float(np.abs(positions[v]).max()):.3g} at vertex "
                f"{v}: the studio takes coordinates up to {COORDINATE_LIMIT:.0e} in any unit")
    return None


def check_pose_topology(rest: Array, pose: KeyPose, source: str | None = None) -> None:
    """Reject a pose that cannot be blended with the neutral mesh, naming the first mismatch."""
    if pose.positions.shape != rest.shape:
        raise MeshError(
            f"key pose '{pose.name}' has {len(pose.positions)} vertices, "
            f"the neutral mesh has {len(rest)}",
            source,
        )
    problem = coordinate_problem(pose.positions, f"key pose '{pose.name}'")
    if problem:
        raise MeshError(problem, source)


def parke_cosine(fraction: float | Array) -> float | Array:
    """Parke's ease: ``C = (1 − cos(f·π)) / 2`` — slow at both ends of a phase."""
    return (1.0 - np.cos(np.asarray(fraction) * math.pi)) * 0.5


def ease(fraction: float, mode: str) -> float:
    """Fraction of the way from one pose to the next for an interpolation mode."""
    f = min(max(float(fraction), 0.0), 1.0)
    if mode == "linear":
        return f
    if mode == "cosine":
        return float(parke_cosine(f))
    if mode == "smooth":
        return f * f * (3.0 - 2.0 * f)
    if mode == "constant":
        return 0.0 if f < 1.0 else 1.0
    raise ValueError(f"unknown interpolation mode '{mode}'")


# Up to this many poses of non-zero weight are added one by one (a pass over the positions each);
# more take one matrix product over every pose. An animation moves one or two poses at a time; a
# capture take moves all of them every frame.
_ADD_POSES = 3
# The product ``weights @ deltas`` goes through numpy's own einsum loop, not BLAS: it reads every
# delta once (memory-bound), so threads gain nothing, and threaded OpenBLAS on a busy machine waits
# for its worker threads — 52 poses × 30,000 vertices took 8 ms that way against 0.65 ms here.
_PRODUCT = "p,pn->n"


class PoseBlender:
    """Blends key poses by weight without per-frame allocation, at a cost that follows the poses
    in use: only poses of non-zero weight are read."""

    def __init__(self, rest: Array, poses: Sequence[KeyPose]) -> None:
        self.rest = np.ascontiguousarray(rest, dtype=np.float32)
        self.names = [p.name for p in poses]
        self._index: dict[str, int] = {}
        for k, name in enumerate(self.names):
            self._index.setdefault(name, k)
        n = len(poses)
        self._flat_rest = self.rest.ravel()
        self._deltas = np.empty((n, self.rest.size), dtype=np.float32)
        for k, pose in enumerate(poses):
            self._deltas[k] = (pose.positions - self.rest).ravel()
        self._weights = np.zeros(n, dtype=np.float32)
        self._out = np.empty(self.rest.size, dtype=np.float32)
        self._term = np.empty(self.rest.size, dtype=np.float32)

    def weights_vector(self, weights: Mapping[str, float]) -> Array:
        self._weights[:] = 0.0
        for name, w in weights.items():
            if name == NEUTRAL:
                continue
            k = self._index.get(name)
            if k is None:
                raise KeyError(name)
            self._weights[k] = w
        return self._weights

    def blend(self, weights: Mapping[str, float]) -> Array:
        """Welded positions for the given pose weights (poses not named weigh 0).

        The returned array is reused by the next call; copy it to keep it.
        """
        w = self.weights_vector(weights)
        out = self._out
        active = np.flatnonzero(w)
        if len(active) == 0:
            np.copyto(out, self._flat_rest)
        elif len(active) > _ADD_POSES:
            np.einsum(_PRODUCT, w, self._deltas, out=out)
            out += self._flat_rest
        else:
            first, *others = active.tolist()
            np.multiply(self._deltas[first], w[first], out=out)
            for k in others:
                np.multiply(self._deltas[k], w[k], out=self._term)
                out += self._term
            out += self._flat_rest
        return out.reshape(self.rest.shape)


def interpolate(a: Array, b: Array, fraction: float, mode: str = "linear") -> Array:
    """Positions a fraction of the way from pose ``a`` to pose ``b``."""
    c = ease(fraction, mode)
    return a + np.float32(c) * (b - a)
