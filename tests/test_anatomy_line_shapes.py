"""The shape of the lines anatomy places (``studio.core.setup.anatomy``).

A fold's ends (``fold``): a nasolabial or marionette crease tapers to a point, narrowing as it
fades, instead of ending on a cut straight across it.

Before, the fold's valley kept its full width (0.85 face x across, as wide as a marionette line
is long) right to where its depth had faded: its end was a box, whose edge showed under a
raking light as a hard horizontal step with a bright tick at its foot (docs/look.md, round 2:
"a box end with a hard horizontal step").

A frown's glabellar lines (``glabella``) narrow toward their top as they fade, as a fold does
(before, each kept one width from bottom to top: "browDown line width too uniform", round 2).

Crow's feet (``crows_feet``) lie across the orbicularis' ring: they radiate from behind the eye's
outer corner, so near the corner they are spread out, not meeting at one point. Before, every
line radiated from the corner itself: "a starburst whose rays meet at one point" (round 1 and 2).
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.setup import anatomy
from studio.core.setup.anatomy import FAN_END, FAN_START, FOLD_BINS, OUTER_EYE, FoldPath

pytestmark = pytest.mark.core

STEPS = 400


def fold_across(line, along: float) -> tuple[np.ndarray, np.ndarray]:
    """(offsets across the line in face x, the fold's window there) at ``along`` (0: the
    line's start, 1: its end), on the character's left, the fold at full depth all along."""
    (x0, y0), (x1, y1) = line
    length = float(np.hypot(x1 - x0, y1 - y0))
    ex, ey = (x1 - x0) / length, (y1 - y0) / length
    v = np.linspace(-1.5, 1.5, STEPS)
    x = x0 + along * (x1 - x0) - v * ey  # outward (the line's left) positive
    y = y0 + along * (y1 - y0) + v * ex
    midline = 0.02  # the face's midline is not at x = 0 on every head
    path = FoldPath(np.zeros((2, FOLD_BINS)), np.ones((2, FOLD_BINS)), np.zeros(2))
    window, _ = anatomy.fold(x + midline, y, np.zeros_like(x), midline, (1.0,), line, path)
    return v, window


def width(line, along: float) -> float:
    """How wide (face x) the fold draws at ``along``: where its window holds any depth."""
    v, window = fold_across(line, along)
    return float((window > 1e-4).sum() * (v[1] - v[0]))


@pytest.mark.parametrize("line", [anatomy.NASOLABIAL, anatomy.MARIONETTE],
                         ids=["nasolabial", "marionette"])
def test_a_fold_narrows_to_a_point_where_it_fades(line):
    middle = width(line, 0.5)
    assert middle > 0.3
    near_end = width(line, 0.93)
    assert 0.0 < near_end < 0.6 * middle  # narrowing as it fades, not a box
    assert width(line, 0.985) < 0.45 * middle
    # and its depth falls to nothing at both ends, smoothly
    depths = [float(fold_across(line, t)[1].max()) for t in (0.5, 0.8, 0.93, 0.99, 1.0)]
    assert depths[0] == pytest.approx(1.0, abs=1e-3)
    assert (np.diff(depths) <= 0.0).all()
    assert depths[-1] < 1e-6 and depths[-2] < 0.01


def fan_spacing(radius: float) -> float:
    """The crow's feet's mean spacing (face x) along an arc ``radius`` from the eye's outer
    corner, over the fan's middle (where every line is drawn): its length over the lines."""
    angles = np.radians(np.linspace(-40.0, 30.0, 400))
    midline = -0.03
    x = midline + OUTER_EYE[0] + radius * np.cos(angles)
    y = OUTER_EYE[1] + radius * np.sin(angles)
    window, phase = anatomy.crows_feet(x, y, np.zeros_like(x), midline, sides=(1.0,))
    assert (window > 0.5).all()
    lines = abs(float(phase[-1] - phase[0])) / (2.0 * np.pi)
    return radius * float(angles[-1] - angles[0]) / lines


def test_crows_feet_do_not_meet_at_one_point():
    near, far = FAN_START + 0.08, FAN_END - 0.1
    # from one point, the spacing grows as the distance from it: near / far of it
    assert fan_spacing(near) > 1.25 * (near / far) * fan_spacing(far)


def glabellar_width(y: float) -> float:
    """How wide (face x) the left glabellar line's valley is at height ``y`` (face y)."""
    midline = 0.04
    x = midline + np.linspace(0.0, 1.5 * anatomy.INNER_BROW, 600)
    window, phase = anatomy.glabella(x, np.full_like(x, y), np.zeros_like(x), midline)
    valley = (np.abs(phase) < np.pi) & (window > 0.0)
    return float(valley.sum() * (x[1] - x[0]))


def test_glabellar_lines_narrow_toward_their_top():
    start = anatomy.BOTTOM + anatomy.NOSE_ROOT
    middle = glabellar_width(start + 0.15)
    assert middle > 0.0
    assert glabellar_width(anatomy.GLABELLA_TOP - 0.1) < 0.75 * middle
