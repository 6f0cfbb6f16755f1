"""Where an artist puts a pucker's lines: short vertical lines on the skin above the upper lip,
and fewer below the lower lip — the perioral ("smoker's") lines.

A pucker or a funnel (the lips pursed: the mouth's corners drawn in toward the midline, the
lips pushed forward) squeezes the skin around the mouth sideways, most the upper lip's, and
furrows across that compression run up and down over the whole upper lip and cheek beside it —
where an artist paints a row of short lines standing on the lips' border, each at right angles
to it, on the skin between the nose and the lip and under the lower lip, none on the red of
the lips nor on the cheek (``lip_lines``). Like the other lines of ``anatomy``, the pose's
compression says *where* and *how strong*, the face *where exactly and which way*, and every
line stays inside the skin the pose squeezes (``wrinkle_synth.placed_region``).

Places are in face coordinates (``FacePlaces``: x toward the character's left, y up, z to the
front, from the tip of the nose, in the face box's half width), with the lips' border from the
ICT-FaceKit head's 68 landmarks: the upper lip's top 0.41 below the tip of the nose on the
midline (51), its bow's peaks 0.116 out and 0.40 down (50, 52), 0.272 out and 0.458 down (49,
53), the mouth's corners 0.405 out and 0.577 down (48, 54); the lower lip's bottom 0.714 down
on the midline (57) and 0.288 out, 0.663 down (55, 59); the base of the nose 0.207 down (33).
"""

from __future__ import annotations

import numpy as np

from studio.core.setup.anatomy import FacePlaces, moved_share, smoothstep, squeezed_share

Array = np.ndarray

UPPER_BORDER = ((0.0, 0.116, 0.272, 0.405), (-0.411, -0.402, -0.458, -0.577))  # (face x out, y)
LOWER_BORDER = ((0.0, 0.288, 0.405), (-0.714, -0.663, -0.577))
LIP_CENTRE = (0.0, -0.56)  # the lines stand on the border, radiating from the mouth's middle …
LIP_SPACING = 11.0  # … a line every this many degrees around it (7: a comb of twenty) …
LIP_NARROW = 0.6  # … each narrower than their spacing, flat skin between (the phase bunched)
LIP_STAGGER = 0.5  # … and each its own length: up to this share shorter than the longest
UPPER_REACH = (0.01, 0.03, 0.11, 0.16)  # above the upper lip's border (face y): fading in from
# the border over the first two, out over the last two — short, below the base of the nose …
LOWER_REACH = (0.01, 0.03, 0.07, 0.11)  # … and below the lower lip's border, shorter
LIP_SIDE = (0.3, 0.36)  # out to this far from the midline, fading (inside the mouth's corners)
LIP_MIDDLE = (0.0, 0.04)  # … and fading in from the midline (the philtrum's groove)
LIP_FRONT = (-0.6, -0.5)  # on skin facing forward (face z), not the cheek's side
LOWER_GAIN = 0.5  # the lines under the lower lip, shallower than those above it
LIP_GAIN = 0.18  # the lines' depth, relative to a frown's: fine lines, close together (0.6
# drew deep cuts)
PURSE_SQUEEZED = 0.2  # a pose squeezes the upper lip's skin by this share of its strong
PURSE_IN = 0.06  # compression, and draws each mouth corner in by this share of its largest
# motion: the lips pursed (the ICT head's pucker: 0.29 and 0.11 each side, its funnel 0.29 and
# 0.10; a mouth pulled left 0.33 and 0.18 but −0.09, a lip press 0.20 and 0.00, an upper lip
# raise 0.41 and 0.00, a smile or a stretch outward)
CORNER_NEAR = 0.12  # the mouth's corner: the skin this near its landmark (face units)


def _border(out: Array, border: tuple[tuple[float, ...], tuple[float, ...]]) -> Array:
    """Face y of a lip's border at ``out`` (face x from the midline), linear between anchors."""
    return np.interp(out, *border)


def _upper_lip(out: Array, y: Array, length: Array | float = 1.0) -> Array:
    """In [0, 1]: the skin between the upper lip's border and the base of the nose, reaching
    ``length`` of the way up (a share of ``UPPER_REACH``'s)."""
    above = (y - _border(out, UPPER_BORDER)) / length
    return smoothstep(UPPER_REACH[0], UPPER_REACH[1], above) * smoothstep(
        UPPER_REACH[3], UPPER_REACH[2], above)


def _lower_lip(out: Array, y: Array, length: Array | float = 1.0) -> Array:
    """In [0, 1]: the skin just under the lower lip's border, as ``_upper_lip``."""
    below = (_border(out, LOWER_BORDER) - y) / length
    return smoothstep(LOWER_REACH[0], LOWER_REACH[1], below) * smoothstep(
        LOWER_REACH[3], LOWER_REACH[2], below)


def purses_lips(places: FacePlaces, rest: Array, target: Array, compression: Array) -> bool:
    """Whether a pose purses the lips (a pucker, a funnel): it squeezes the upper lip's skin
    (``compression`` per vertex: its mean over the triangles around it), on average, by
    ``PURSE_SQUEEZED`` of its strong compression, and draws *both* mouth corners in toward
    the midline by ``PURSE_IN`` of its largest motion — not a smile nor a stretch (outward),
    a mouth pulled to one side (one corner in, the other out) nor a lip press (the corners
    stay)."""
    x, y, z = places.xyz.astype(np.float64).T
    out = np.abs(x - places.midline)
    lip = _upper_lip(out, y) * smoothstep(*LIP_FRONT, z) * smoothstep(LIP_SIDE[1], LIP_SIDE[0],
                                                                       out)
    if squeezed_share(compression, lip) < PURSE_SQUEEZED:
        return False
    across = places._axis(rest, 0)
    corner_x, corner_y = UPPER_BORDER[0][-1], UPPER_BORDER[1][-1]
    for side in (-1.0, 1.0):  # toward the midline from either corner
        near = (np.hypot(x - places.midline - side * corner_x, y - corner_y) < CORNER_NEAR)
        if moved_share(rest, target, near.astype(np.float64), -side * across) < PURSE_IN:
            return False
    return True


def lip_lines(x: Array, y: Array, z: Array, midline: float) -> tuple[Array, Array]:
    """(window, phase) images for a pucker's lines from images of face x, y and z (or
    per-vertex arrays of them): short lines ``LIP_SPACING`` degrees apart around
    ``LIP_CENTRE``, standing on the lips' border, on the skin above the upper lip
    (``UPPER_REACH``) and, shallower (``LOWER_GAIN``), below the lower lip (``LOWER_REACH``),
    each its own length (``LIP_STAGGER``), inside the mouth's corners and faint on the
    philtrum's groove. The window's top is
    ``LIP_GAIN``; the phase (a line's bottom at each multiple of 2π) runs around the mouth."""
    out = np.abs(x - midline)
    across = (smoothstep(LIP_SIDE[1], LIP_SIDE[0], out) * smoothstep(*LIP_MIDDLE, out)
              * smoothstep(*LIP_FRONT, z))
    angle = np.degrees(np.arctan2(x - midline - LIP_CENTRE[0], np.abs(y - LIP_CENTRE[1])))
    # each line its own length (the golden ratio's multiples, evenly spread, never alike):
    # it changes only between lines, where the flat skin hides the step
    line = np.round(angle / LIP_SPACING)
    length = 1.0 - LIP_STAGGER * np.mod(line * 0.618034, 1.0)
    window = LIP_GAIN * across * np.maximum(_upper_lip(out, y, length),
                                            LOWER_GAIN * _lower_lip(out, y, length))
    phase = 2.0 * np.pi * angle / LIP_SPACING
    phase = phase + LIP_NARROW * np.sin(phase)
    return window.astype(np.float32), phase.astype(np.float32)
