"""Response curves of pose → area links: how a pose's weight (0..1) becomes its contribution.

A link's contribution to an area's activation is ``gain · curve(weight)``. The thesis raises
activations linearly with the pose [4.2.3.2]; skin does not: a frown line stays flat for most of
the movement and then creases, a forehead fold appears early and saturates. A curve per link lets
the author shape that without more poses or more areas.

The kinds, with ``t = clamp((x - start) / (end - start), 0, 1)`` (start, end = 0, 1 unless the
kind is ``smooth_step``):

    linear        y = x            (no clamp: exactly the behaviour before curves existed)
    ease_in       y = t²           (slow start: 0.25 at x = 0.5)
    ease_out      y = 1 - (1 - t)² (fast start: 0.75 at x = 0.5)
    ease_in_out   y = 3t² - 2t³    (smoothstep: 0.15625 at x = 0.25)
    smooth_step   y = 3t² - 2t³    between the thresholds start and end
    custom        piecewise linear through points (x, y) in [0, 1]², x strictly increasing;
                  flat beyond the first and last point

Every analytic kind is a cubic in ``t``, so a whole set of links evaluates in one vectorised pass
(:class:`CurveBank`): the activation vector is computed every frame of playback with dozens of
poses moving, and a Python loop over links per frame would dominate it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

Array = np.ndarray

LABELS = {"linear": "linear", "ease_in": "ease in", "ease_out": "ease out",
          "ease_in_out": "ease in/out", "smooth_step": "smooth step", "custom": "custom"}
# y = c0 + c1·t + c2·t² + c3·t³ for the analytic kinds
_CUBICS = {"linear": (0.0, 1.0, 0.0, 0.0), "ease_in": (0.0, 0.0, 1.0, 0.0),
           "ease_out": (0.0, 2.0, -1.0, 0.0), "ease_in_out": (0.0, 0.0, 3.0, -2.0),
           "smooth_step": (0.0, 0.0, 3.0, -2.0)}
MAX_POINTS = 32  # a custom curve's points: plenty for a hand-drawn shape, bounded for files
Point = tuple[float, float]
CurveTable = Mapping[str, Mapping[str, "ResponseCurve"]]  # pose -> {area: curve}


def _unit(value: Any, what: str) -> float:
    """``value`` as a float in [0, 1], or ValueError naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value) or not 0.0 <= value <= 1.0:
        raise ValueError(f"{what} must be a number from 0 to 1")
    return float(value)


@dataclass(frozen=True)
class ResponseCurve:
    """One link's curve; immutable and hashable, so links can be compared and shared."""

    kind: str = "linear"
    start: float = 0.0  # smooth_step's thresholds: 0 below start, 1 above end
    end: float = 1.0
    points: tuple[Point, ...] = ()  # custom's points

    def __post_init__(self) -> None:
        if self.kind not in LABELS:
            raise ValueError(f"kind must be one of {', '.join(LABELS)}, not {self.kind!r}")
        start, end = _unit(self.start, "start"), _unit(self.end, "end")
        if self.kind == "smooth_step" and not start < end:
            raise ValueError("start must be below end")
        if self.kind != "smooth_step" and (start, end) != (0.0, 1.0):
            raise ValueError(f"start and end belong to smooth_step curves, not {self.kind}")
        points = tuple((_unit(x, f"points[{i}] x"), _unit(y, f"points[{i}] y"))
                       for i, (x, y) in enumerate(_pairs(self.points)))
        if self.kind == "custom":
            if not 2 <= len(points) <= MAX_POINTS:
                raise ValueError(f"points must hold 2 to {MAX_POINTS} points")
            for i in range(1, len(points)):
                if points[i][0] <= points[i - 1][0]:
                    raise ValueError(f"points[{i}] x must be greater than the point before")
        elif points:
            raise ValueError(f"points belong to custom curves, not {self.kind}")
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "end", end)
        object.__setattr__(self, "points", points)

    @property
    def linear(self) -> bool:
        return self.kind == "linear"

    def evaluate(self, x: Array | float) -> Array:
        """The response at pose weights ``x`` (any shape), float64."""
        x = np.asarray(x, dtype=np.float64)
        if self.kind == "custom":
            xs, ys = zip(*self.points, strict=True)
            return np.interp(x, xs, ys)
        t = (x - self.start) / (self.end - self.start)
        if not self.linear:
            t = np.clip(t, 0.0, 1.0)
        c0, c1, c2, c3 = _CUBICS[self.kind]
        return c0 + t * (c1 + t * (c2 + t * c3))

    def to_dict(self) -> dict[str, Any]:
        """JSON form: only the fields the kind uses."""
        doc: dict[str, Any] = {"kind": self.kind}
        if self.kind == "smooth_step":
            doc.update(start=self.start, end=self.end)
        if self.kind == "custom":
            doc["points"] = [list(p) for p in self.points]
        return doc

    @classmethod
    def from_dict(cls, doc: Any) -> ResponseCurve:
        """The curve ``to_dict`` wrote; ValueError naming the bad field for anything else."""
        if not isinstance(doc, dict):
            raise ValueError("must be a JSON object")
        unknown = set(doc) - {"kind", "start", "end", "points"}
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]} is not a field of a curve")
        kind = doc.get("kind")
        if not isinstance(kind, str):
            raise ValueError("kind must be text")
        points = doc.get("points", [])
        if not isinstance(points, list) or len(points) > MAX_POINTS:
            raise ValueError(f"points must be a list of at most {MAX_POINTS} points")
        for i, p in enumerate(points):
            if not isinstance(p, list) or len(p) != 2:
                raise ValueError(f"points[{i}] must be a pair [x, y]")
        return cls(kind, doc.get("start", 0.0), doc.get("end", 1.0),
                   tuple((p[0], p[1]) for p in points))

    def as_custom(self, samples: int = 5) -> ResponseCurve:
        """A custom curve through ``samples`` points of this one: where editing by hand starts."""
        if self.kind == "custom":
            return self
        xs = np.linspace(0.0, 1.0, samples)
        return ResponseCurve("custom", points=tuple(
            (float(x), float(np.clip(y, 0.0, 1.0))) for x, y in zip(xs, self.evaluate(xs),
                                                                     strict=True)))


def _pairs(points: Any) -> list[tuple[Any, Any]]:
    try:
        pairs = [tuple(p) for p in points]
    except TypeError:
        raise ValueError("points must be a list of pairs [x, y]") from None
    for i, p in enumerate(pairs):
        if len(p) != 2:
            raise ValueError(f"points[{i}] must be a pair [x, y]")
    return pairs


LINEAR = ResponseCurve()


class CurveBank:
    """Many curves evaluated together: ``evaluate(x)`` gives ``curves[i](x[i])`` for every i in
    one vectorised pass (analytic kinds as cubics, custom kinds as padded point tables), built
    once per change of the curves and then used every frame."""

    def __init__(self, curves: Sequence[ResponseCurve]) -> None:
        n = len(curves)
        self.size = n
        cubic = np.array([c.kind != "custom" for c in curves], dtype=bool)
        self._cubic, self._custom = np.flatnonzero(cubic), np.flatnonzero(~cubic)
        analytic = [curves[i] for i in self._cubic]
        self._start = np.array([c.start for c in analytic])
        self._span = np.array([c.end - c.start for c in analytic])
        # linear curves are not clamped: the limits are infinite for them
        self._low = np.array([-np.inf if c.linear else 0.0 for c in analytic])
        self._high = np.array([np.inf if c.linear else 1.0 for c in analytic])
        self._coefficients = np.array([_CUBICS[c.kind] for c in analytic]).reshape(-1, 4)
        custom = [curves[i] for i in self._custom]
        width = max((len(c.points) for c in custom), default=2)
        self._last = np.array([len(c.points) - 2 for c in custom], dtype=np.intp)
        # padding repeats each curve's last point; segments past ``_last`` are never used
        table = np.array([c.points + c.points[-1:] * (width - len(c.points)) for c in custom])
        table = table.reshape(len(custom), width, 2)
        self._xs, self._ys = table[..., 0], table[..., 1]

    def evaluate(self, x: Array) -> Array:
        """``x``: (..., n) pose weights, one per curve (leading axes: frames, say); returns
        (..., n) float64 responses."""
        x = np.asarray(x, dtype=np.float64)
        out = np.empty(x.shape)
        if len(self._cubic):
            t = (x[..., self._cubic] - self._start) / self._span
            t = np.clip(t, self._low, self._high)
            c = self._coefficients
            out[..., self._cubic] = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
        if len(self._custom):
            xc = x[..., self._custom]
            rows = np.arange(len(self._custom))
            segment = np.clip((self._xs <= xc[..., None]).sum(axis=-1) - 1, 0, self._last)
            x0, x1 = self._xs[rows, segment], self._xs[rows, segment + 1]
            y0, y1 = self._ys[rows, segment], self._ys[rows, segment + 1]
            with np.errstate(over="ignore"):  # a near-vertical step: t saturates, as it should
                t = np.clip((xc - x0) / (x1 - x0), 0.0, 1.0)
            out[..., self._custom] = y0 + t * (y1 - y0)
        return out


def onset_weight(x: Array | float, onset: Array | float) -> Array:
    """Pose weights ``x`` as the wrinkles see them with an onset (broadcast together): 0 up to
    the onset, then rising linearly to 1 at full weight, ``max(0, (x - onset) / (1 - onset))``
    — a remap of the weight before each link's curve, so every curve keeps its shape over what
    is left of the movement. An onset of 0 leaves the weight exactly as it is (no clamp), which
    keeps every file made before onsets as it was; float64."""
    x = np.asarray(x, dtype=np.float64)
    onset = np.asarray(onset, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        remapped = np.maximum((x - onset) / (1.0 - onset), 0.0)
    return np.where(onset > 0.0, remapped, x)


def curves_to_dict(curves: CurveTable) -> dict[str, dict[str, dict[str, Any]]]:
    """The non-linear curves as JSON (linear is the default and is left out)."""
    doc = {pose: {area: c.to_dict() for area, c in by_area.items() if not c.linear}
           for pose, by_area in curves.items()}
    return {pose: by_area for pose, by_area in doc.items() if by_area}


def curves_from_dict(doc: Any) -> dict[str, dict[str, ResponseCurve]]:
    """What ``curves_to_dict`` wrote; ValueError naming the field ("pose.area.kind …")."""
    if not isinstance(doc, dict):
        raise ValueError("curves must be a JSON object")
    curves: dict[str, dict[str, ResponseCurve]] = {}
    for pose, by_area in doc.items():
        if not isinstance(by_area, dict):
            raise ValueError(f"{pose} must be a JSON object")
        curves[pose] = {}
        for area, curve in by_area.items():
            try:
                curves[pose][area] = ResponseCurve.from_dict(curve)
            except ValueError as exc:
                raise ValueError(f"{pose}.{area}: {exc}") from None
    return curves


def curve_of(curves: CurveTable, pose: str, area: str) -> ResponseCurve:
    """The curve of the link ``pose`` → ``area``: linear where none is set."""
    return curves.get(pose, {}).get(area, LINEAR)
