"""Editing a response curve by its handles (studio.core.wrinkles.response_handles): where the
handles are, and what dragging, adding, removing, picking and converting make of a curve."""

from __future__ import annotations

import pytest

from studio.core.wrinkles.response import MAX_POINTS, ResponseCurve
from studio.core.wrinkles.response_handles import (
    GAP,
    added,
    converted,
    handles,
    moved,
    nearest,
    removed,
)

pytestmark = pytest.mark.core

THREE = ResponseCurve("custom", points=((0.0, 0.0), (0.5, 0.2), (1.0, 1.0)))
FOUR = ResponseCurve("custom", points=((0.1, 0.0), (0.3, 0.4), (0.6, 0.5), (0.9, 1.0)))
STEP = ResponseCurve("smooth_step", 0.2, 0.6)


def xs(curve: ResponseCurve) -> list[float]:
    return [x for x, _ in curve.points]


# --------------------------------------------------------------------------- handles

def test_a_custom_curves_handles_are_its_points() -> None:
    """A custom curve's handles are exactly its points, in order."""
    assert handles(FOUR) == ((0.1, 0.0), (0.3, 0.4), (0.6, 0.5), (0.9, 1.0))


def test_a_smooth_steps_handles_are_its_thresholds_at_the_bottom_and_the_top() -> None:
    """A smooth step has two handles: (start, 0) and (end, 1)."""
    assert handles(STEP) == ((0.2, 0.0), (0.6, 1.0))


@pytest.mark.parametrize("kind", ["linear", "ease_in", "ease_out", "ease_in_out"])
def test_the_fixed_kinds_have_no_handles(kind: str) -> None:
    """Linear and the eases cannot be edited: no handles."""
    assert handles(ResponseCurve(kind)) == ()


# --------------------------------------------------------------------------- moved

def test_dragging_a_middle_point_moves_it_freely_between_its_neighbours() -> None:
    """A point dragged within its neighbours lands exactly where it was dropped."""
    assert moved(FOUR, 1, 0.25, 0.7).points == ((0.1, 0.0), (0.25, 0.7), (0.6, 0.5),
                                                (0.9, 1.0))


def test_dragging_a_point_past_its_right_neighbour_stops_just_short_of_it() -> None:
    """Past the next point, x stops one GAP before it; y is kept in [0, 1]."""
    dragged = moved(FOUR, 1, 0.95, 1.4)
    assert dragged.kind == "custom"
    assert xs(dragged) == pytest.approx([0.1, 0.6 - GAP, 0.6, 0.9])
    assert dragged.points[1][1] == 1.0
    # the second-to-last point stops before the last one, not at the right edge
    assert xs(moved(THREE, 1, 1.0, 0.5)) == pytest.approx([0.0, 1.0 - GAP, 1.0])


def test_dragging_a_point_past_its_left_neighbour_stops_just_short_of_it() -> None:
    """Before the previous point, x stops one GAP after it; y below 0 becomes 0."""
    dragged = moved(FOUR, 2, 0.0, -0.3)
    assert xs(dragged) == pytest.approx([0.1, 0.3, 0.3 + GAP, 0.9])
    assert dragged.points[2][1] == 0.0
    assert xs(moved(FOUR, 1, 0.0, 0.4)) == pytest.approx([0.1, 0.1 + GAP, 0.6, 0.9])


def test_the_end_points_stop_at_the_edges_of_the_square() -> None:
    """The first point stops at x = 0, the last at x = 1."""
    assert moved(FOUR, 0, -0.5, 0.3).points[0] == (0.0, 0.3)
    assert moved(FOUR, 3, 1.5, 0.8).points[3] == (1.0, 0.8)
    assert moved(THREE, 0, 0.2, 0.1).points == ((0.2, 0.1), (0.5, 0.2), (1.0, 1.0))
    assert moved(THREE, 2, 0.7, 0.6).points == ((0.0, 0.0), (0.5, 0.2), (0.7, 0.6))


def test_dragging_the_first_point_past_the_second_stops_short_of_the_second() -> None:
    """The first point cannot cross the second one."""
    assert xs(moved(FOUR, 0, 0.8, 0.0)) == pytest.approx([0.3 - GAP, 0.3, 0.6, 0.9])


def test_dragging_a_smooth_steps_start_moves_only_the_start() -> None:
    """The start handle moves along x; the end stays, and y is ignored."""
    assert moved(STEP, 0, 0.1, 0.9) == ResponseCurve("smooth_step", 0.1, 0.6)
    assert moved(STEP, 0, -0.4, 0.0) == ResponseCurve("smooth_step", 0.0, 0.6)


def test_dragging_a_smooth_steps_end_moves_only_the_end() -> None:
    """The end handle moves along x; the start stays."""
    assert moved(STEP, 1, 0.8, 0.0) == ResponseCurve("smooth_step", 0.2, 0.8)
    assert moved(STEP, 1, 1.7, 1.0) == ResponseCurve("smooth_step", 0.2, 1.0)


def test_a_smooth_steps_thresholds_cannot_cross() -> None:
    """Start stops a GAP below the end, and the end a GAP above the start."""
    assert moved(STEP, 0, 0.9, 0.0) == ResponseCurve("smooth_step", 0.6 - GAP, 0.6)
    assert moved(STEP, 1, 0.0, 1.0) == ResponseCurve("smooth_step", 0.2, 0.2 + GAP)


# --------------------------------------------------------------------------- added

def test_a_point_is_added_in_its_place_along_x() -> None:
    """An added point is inserted in x order, with the values given."""
    assert added(THREE, 0.25, 0.6).points == ((0.0, 0.0), (0.25, 0.6), (0.5, 0.2), (1.0, 1.0))
    assert added(THREE, 0.75, 0.1).points == ((0.0, 0.0), (0.5, 0.2), (0.75, 0.1), (1.0, 1.0))


def test_a_point_added_outside_the_square_is_clamped_into_it() -> None:
    """x and y beyond [0, 1] are brought to the nearest edge."""
    assert added(FOUR, 1.5, 2.0).points[-1] == (1.0, 1.0)
    assert added(FOUR, -0.5, -1.0).points[0] == (0.0, 0.0)
    assert added(FOUR, 0.45, 1.3).points[2] == (0.45, 1.0)
    assert added(FOUR, 0.45, -0.3).points[2] == (0.45, 0.0)


def test_a_point_too_close_to_another_is_refused() -> None:
    """Within GAP of an existing x the curve is unchanged; exactly GAP away is allowed."""
    assert added(THREE, 0.5005, 0.9) is THREE
    assert added(THREE, 0.4995, 0.9) is THREE
    grown = added(THREE, 0.001, 0.3)  # exactly GAP from the point at 0
    assert grown.points == ((0.0, 0.0), (0.001, 0.3), (0.5, 0.2), (1.0, 1.0))


def test_a_full_curve_takes_no_more_points() -> None:
    """A curve at MAX_POINTS points is unchanged; one point below it takes one more."""
    step = 1.0 / MAX_POINTS
    full = ResponseCurve("custom", points=tuple((i * step, 0.5) for i in range(MAX_POINTS)))
    assert added(full, 0.99, 0.5) is full
    almost = ResponseCurve("custom", points=full.points[:-1])
    assert len(added(almost, 0.99, 0.5).points) == MAX_POINTS


@pytest.mark.parametrize("curve", [ResponseCurve(), ResponseCurve("ease_in"), STEP])
def test_only_custom_curves_take_points(curve: ResponseCurve) -> None:
    """Adding a point to any other kind leaves the curve as it was."""
    assert added(curve, 0.4, 0.4) is curve


# --------------------------------------------------------------------------- removed

def test_removing_a_point_keeps_the_others_in_order() -> None:
    """The point at the index goes; the rest stay as they were."""
    assert removed(FOUR, 1).points == ((0.1, 0.0), (0.6, 0.5), (0.9, 1.0))
    assert removed(FOUR, 0).points == ((0.3, 0.4), (0.6, 0.5), (0.9, 1.0))
    assert removed(FOUR, 3).points == ((0.1, 0.0), (0.3, 0.4), (0.6, 0.5))
    shrunk = removed(THREE, 1)
    assert shrunk.kind == "custom" and shrunk.points == ((0.0, 0.0), (1.0, 1.0))


def test_the_last_two_points_cannot_be_removed() -> None:
    """A two-point curve is unchanged by a removal."""
    two = removed(THREE, 1)
    assert removed(two, 0) is two
    assert removed(two, 1) is two


@pytest.mark.parametrize("curve", [ResponseCurve(), STEP])
def test_only_custom_curves_lose_points(curve: ResponseCurve) -> None:
    """Removing a point from any other kind leaves the curve as it was."""
    assert removed(curve, 0) is curve


# --------------------------------------------------------------------------- nearest

def test_the_handle_under_the_pointer_is_found() -> None:
    """The pointer on a handle, or close to it, picks that handle."""
    assert nearest(FOUR, 0.3, 0.4, 0.05, 0.05) == 1
    assert nearest(FOUR, 0.62, 0.48, 0.05, 0.05) == 2
    assert nearest(FOUR, 0.12, 0.0, 0.05, 0.05) == 0
    assert nearest(STEP, 0.58, 0.98, 0.05, 0.05) == 1


def test_of_several_handles_in_reach_the_closest_is_found() -> None:
    """Two handles in reach: the one nearer the pointer wins, whichever comes first."""
    close = ResponseCurve("custom", points=((0.0, 0.0), (0.5, 0.5), (0.52, 0.5), (1.0, 1.0)))
    assert nearest(close, 0.505, 0.5, 0.1, 0.1) == 1
    assert nearest(close, 0.515, 0.5, 0.1, 0.1) == 2


def test_no_handle_is_found_out_of_reach() -> None:
    """Pointers beyond the reach on either side, in x or in y, find nothing."""
    assert nearest(FOUR, 0.45, 0.45, 0.05, 0.05) is None  # between handles
    assert nearest(FOUR, 0.6 + 0.15, 0.5, 0.05, 0.05) is None  # right of a handle
    assert nearest(FOUR, 0.6 - 0.15, 0.5, 0.05, 0.05) is None  # left of it
    assert nearest(FOUR, 0.6, 0.5 + 0.15, 0.05, 0.05) is None  # above it
    assert nearest(FOUR, 0.6, 0.5 - 0.15, 0.05, 0.05) is None  # below it
    assert nearest(FOUR, 0.6 + 0.0707, 0.5 + 0.0707, 0.05, 0.05) is None  # 1.41 reaches off
    assert nearest(FOUR, 0.6 + 0.06, 0.5, 0.05, 0.05) is None  # 1.2 reaches off
    assert nearest(ResponseCurve("ease_in"), 0.5, 0.25, 1.0, 1.0) is None  # no handles


def test_the_reach_is_an_ellipse_with_its_own_size_per_axis() -> None:
    """A wide reach in x and a narrow one in y: far along x is found, far along y is not."""
    assert nearest(FOUR, 0.6 + 0.15, 0.5, 0.2, 0.02) == 2
    assert nearest(FOUR, 0.6, 0.5 + 0.15, 0.2, 0.02) is None
    assert nearest(FOUR, 0.6, 0.5 + 0.15, 0.02, 0.2) == 2
    assert nearest(FOUR, 0.6 + 0.15, 0.5, 0.02, 0.2) is None
    assert nearest(FOUR, 0.6, 0.5 + 0.02, 0.1, 0.05) == 2  # 0.4 of the reach in y: in
    assert nearest(FOUR, 0.6 + 0.04, 0.5, 0.05, 0.1) == 2  # 0.8 of the reach in x: in


def test_a_handle_exactly_at_the_reach_is_found() -> None:
    """The edge of the ellipse counts as within reach."""
    assert nearest(THREE, 0.25, 0.2, 0.25, 0.5) == 1
    assert nearest(THREE, 0.5, 0.7, 0.25, 0.5) == 1


# --------------------------------------------------------------------------- converted

def test_converting_to_the_same_kind_keeps_the_curve() -> None:
    """Choosing the kind a curve already has changes nothing (a step keeps its thresholds)."""
    assert converted(STEP, "smooth_step") is STEP
    assert converted(FOUR, "custom") is FOUR


def test_converting_to_custom_starts_from_the_current_shape() -> None:
    """A custom curve made from ease in samples ease in at five points."""
    assert converted(ResponseCurve("ease_in"), "custom") == ResponseCurve(
        "custom", points=((0.0, 0.0), (0.25, 0.0625), (0.5, 0.25), (0.75, 0.5625), (1.0, 1.0)))


def test_converting_to_a_smooth_step_starts_from_the_middle_thresholds() -> None:
    """A new smooth step runs from 0.25 to 0.75."""
    assert converted(FOUR, "smooth_step") == ResponseCurve("smooth_step", 0.25, 0.75)
    assert converted(ResponseCurve(), "smooth_step") == ResponseCurve("smooth_step", 0.25, 0.75)


@pytest.mark.parametrize("kind", ["linear", "ease_in", "ease_out", "ease_in_out"])
def test_converting_to_a_fixed_kind_gives_that_kind(kind: str) -> None:
    """The fixed kinds are just themselves, whatever the curve was."""
    assert converted(FOUR, kind) == ResponseCurve(kind)
    assert converted(STEP, kind) == ResponseCurve(kind)
