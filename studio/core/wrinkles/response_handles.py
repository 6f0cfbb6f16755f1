"""Editing a response curve by its handles: the points a curve editor lets the user drag.

A custom curve's handles are its points; a smooth step's are its two thresholds, drawn at
(start, 0) and (end, 1) and moved along x only; the fixed kinds have none. Every edit returns a
new, valid :class:`ResponseCurve` (a drag past a neighbour stops just short of it), so the
editor never has to handle a refused curve in the middle of a gesture — and this logic is tested
without a display.
"""

from __future__ import annotations

from studio.core.wrinkles.response import MAX_POINTS, Point, ResponseCurve

GAP = 1e-3  # the least x distance kept between neighbouring handles


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(float(value), low), high)


def handles(curve: ResponseCurve) -> tuple[Point, ...]:
    """Where the curve's handles are drawn, in (weight, response) coordinates."""
    if curve.kind == "custom":
        return curve.points
    if curve.kind == "smooth_step":
        return ((curve.start, 0.0), (curve.end, 1.0))
    return ()


def moved(curve: ResponseCurve, index: int, x: float, y: float) -> ResponseCurve:
    """The curve with handle ``index`` dragged to (x, y), kept between its neighbours."""
    points = list(handles(curve))
    low = points[index - 1][0] + GAP if index > 0 else 0.0
    high = points[index + 1][0] - GAP if index + 1 < len(points) else 1.0
    x = _clamp(x, low, high)
    if curve.kind == "smooth_step":
        start, end = (x, curve.end) if index == 0 else (curve.start, x)
        return ResponseCurve("smooth_step", start, end)
    points[index] = (x, _clamp(y, 0.0, 1.0))
    return ResponseCurve("custom", points=tuple(points))


def added(curve: ResponseCurve, x: float, y: float) -> ResponseCurve:
    """A custom curve with a point added at (x, y); unchanged when it cannot take one (full, or
    too close to an existing point)."""
    if curve.kind != "custom" or len(curve.points) >= MAX_POINTS:
        return curve
    x, y = _clamp(x, 0.0, 1.0), _clamp(y, 0.0, 1.0)
    if any(abs(px - x) < GAP for px, _ in curve.points):
        return curve
    return ResponseCurve("custom", points=tuple(sorted((*curve.points, (x, y)))))


def removed(curve: ResponseCurve, index: int) -> ResponseCurve:
    """A custom curve without point ``index``; unchanged when only two points are left."""
    if curve.kind != "custom" or len(curve.points) <= 2:
        return curve
    return ResponseCurve("custom", points=curve.points[:index] + curve.points[index + 1:])


def nearest(curve: ResponseCurve, x: float, y: float, reach_x: float, reach_y: float
            ) -> int | None:
    """The handle within (reach_x, reach_y) of (x, y) — an ellipse, because a plot's units
    differ per axis — the closest one if several; None if none."""
    best, best_distance = None, 1.0
    for i, (hx, hy) in enumerate(handles(curve)):
        distance = ((hx - x) / reach_x) ** 2 + ((hy - y) / reach_y) ** 2
        if distance <= best_distance:
            best, best_distance = i, distance
    return best


def converted(curve: ResponseCurve, kind: str) -> ResponseCurve:
    """The curve of ``kind`` a user gets on choosing it for a link that has ``curve``: a custom
    curve starts as the current shape (so editing begins from what was there), a smooth step
    from its middle thresholds; the fixed kinds are just themselves."""
    if kind == curve.kind:
        return curve
    if kind == "custom":
        return curve.as_custom()
    if kind == "smooth_step":
        return ResponseCurve("smooth_step", 0.25, 0.75)
    return ResponseCurve(kind)
