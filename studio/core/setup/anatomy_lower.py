"""Where an artist puts the lines of the nose and the chin: a sneer's bunny lines, a mentalis
push's crease under the lower lip.

A sneer (the side of the nose pulled up) squeezes the side of the nose, the upper lip and the
cheek, and furrows across that compression swirl over the whole cheek — where an artist paints
bunny lines: two to four short oblique lines on the side of the nose bridge, between the inner
corner of the eye and the nose's side, running down and out, and nothing on the cheek beyond
(``bunny_lines``). A mentalis push (the chin boss pushed up: a pout's lower half) squeezes the
lower lip, the chin and the mouth's corners, and furrows across it wave over the whole chin —
where an artist paints one soft crease under the lower lip, the mentolabial sulcus
(``chin_crease``). (No dimpling of the chin: dimples a few furrow spacings apart alias on the
synthesis's work grid, the ICT head's shows blotches.)

Both keep the pose's compression as *where* and *how strong*, and take *where exactly and which
way* from the face, like ``anatomy.glabella``: every line stays inside the skin the pose
squeezes (``wrinkle_synth.placed_region``). Places are in face coordinates (``FacePlaces``: x
toward the character's left, y up, z to the front, from the tip of the nose, in the face box's
half width), with anchors measured on the ICT-FaceKit head's 68 landmarks (the inner corners of
the eyes 0.263 either side of the midline and 0.45 up; the nostril wings 0.178 out and 0.176
down; the lower lip's lowest point 0.636 down, the chin's 1.09), so they are shares of the
face's own size.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from studio.core.setup.anatomy import FacePlaces, moved_share, smoothstep, squeezed_share
from studio.core.setup.anatomy_lips import lip_lines, purses_lips

Array = np.ndarray

BEHIND_TIP = (-0.05, -0.1)  # the nose's side and the chin lie behind the tip of the nose (face
# z, fading in over this; the ICT head's: 0.1 to 0.45 behind): a face, not a flat sheet

# --- a sneer's bunny lines, on the side of the nose -------------------------------------------
# the side of the nose (face x outward from the midline): from off its ridge, which folds no
NOSE_IN = (0.0, 0.05)  # line, fading in over this …
NOSE_OUT = (0.3, 0.22)  # … out to where it meets the cheek (the inner eye corners: 0.263) …
NOSE_LOW = (0.08, 0.16)  # … above the nostril wings (face y, fading in over this) …
NOSE_HIGH = (0.46, 0.40)  # … up to the inner corners of the eyes (0.45), fading out over this …
NOSE_FRONT = (-0.5, -0.44)  # … on skin in front of the cheek's plane (face z): the nose's, not
# the cheek's nor the eye's corner
SNEER_SQUEEZED = 0.45  # a sneer squeezes that skin, on average, by this share of its strong
# compression (the ICT head's sneers: 0.77; its upper lip raise 0.37, eye squint 0.25, brow
# raise 0.24, cheek squint 0.22, mouth aside 0.19; the other side of a sneer 0.12) …
SNEER_UP = 0.15  # … and lifts it by this share of its largest motion (sneers 0.28; upper lip
# raise 0.09, brow raise 0.16, squints 0.03 or less)
BUNNY_CENTRE = (0.21, 0.26)  # the middle line's middle (face x outward, y): the outer side
# of the bridge below the inner eye corner, beside the skin the other side's sneer squeezes
# too (a map shared by both leaves a sneer's lines out where the other bares skin)
BUNNY_ANGLE = 65.0  # degrees below the horizontal: the lines run down and out …
BUNNY_SPACING = 0.065  # … this far apart (face units, across them) …
BUNNY_REACH = (0.15, 0.085)  # … in an oval this far along and across them from the middle,
BUNNY_FADE = 0.6  # … fading out from this share of it: two or three lines, the middle longest …
BUNNY_NARROW = 0.6  # … narrower than their spacing, flat skin between (the phase bunched by
# this much around each line's bottom: φ + this × sin φ)
BUNNY_GAIN = 0.6  # shallower than a frown's glabellar lines
BUNNY_QUIET = 0.002  # the window everywhere else but the other side of the nose: too faint
# to draw a line, but the skin a sneer squeezes there (between the brows, the cheek, the lip)
# is not skin it bares (``wrinkle_synth.FurrowField.bare``), which would erase the lines of
# every pose whose map it shares (a frown's) and leave it no map to share; the other side of
# the nose it bares, where the other side's sneer moves the skin just as it does

# --- a mentalis push's crease under the lower lip ---------------------------------------------
# the chin boss (face x from the midline, y, z): where a mentalis push lifts the skin …
CHIN_SIDE = (0.3, 0.2)  # … no further out than this (fading over the difference) …
CHIN_HIGH = (-0.78, -0.84)  # … below the crease under the lower lip (its lowest point: 0.636
# down) …
CHIN_LOW = (-1.06, -0.98)  # … above the chin's lowest point (1.09 down) …
CHIN_FRONT = (-0.6, -0.5)  # … facing forward (face z), not the underside of the jaw
CHIN_SQUEEZED = 0.1  # a mentalis push squeezes that skin by this share of its strong
# compression (the ICT head's lower lip shrug: 0.23; a mouth close 0.01) …
CHIN_UP = 0.48  # … and lifts it by this share of its largest motion (the shrug: 0.60; a lip
# press 0.37, a mouth close 0.15, a lip roll or a smile 0.10; a jaw drop lowers it: −0.68)
CREASE_FRONT = -0.3  # (the chin's front on the ICT head, face z, for a head without skin there)
CREASE = -0.84  # the crease under the lower lip on the midline (face y): the sulcus between
# the lower lip (0.636 down) and the chin boss (its most forward point 0.9 down), where the
# ICT head's shrug squeezes the skin most (0.75 to 0.87 down), below the lip's edge …
CREASE_CURVE = 1.0  # … rising by this times x² toward the sides, along the lip's arc …
CREASE_SIDE = (0.26, 0.0)  # … gone this far either side of the midline (the mouth corners:
# 0.361), deepest on it: tapering along its whole length, no end cut off …
CREASE_SPACING = 0.18  # … one valley this wide (face y), softer than the nose's lines …
CREASE_HALF = 0.05  # … full this far above and below its bottom …
CREASE_GAIN = 0.5  # … and shallow: the lower lip pushed up squeezes it into a narrow fold
CREASE_NEAR = 0.06  # the chin's front there: the most forward skin this near the crease's
# middle (face z; the ICT head's: −0.30) …
CREASE_BEHIND = (0.1, 0.07)  # … the crease on skin no further behind it than this (fading
# over the difference): the chin's front across the crease (−0.30 to −0.36), not the inside of
# the lower lip, which lies behind it (−0.40 and further) and on a UV island of its own


def _outward(x: Array, midline: float) -> tuple[Array, Array]:
    """Face x outward from the midline (≥ 0) and the side (−1: the character's right, 1)."""
    side = np.where(x - midline >= 0.0, 1.0, -1.0)
    return side * (x - midline), side


def _nose_side(x: Array, y: Array, z: Array, midline: float) -> Array:
    """In [0, 1]: the side of the nose above the nostril wings, up to the inner eye corners."""
    out, _ = _outward(x, midline)
    return (smoothstep(*NOSE_IN, out) * smoothstep(*NOSE_OUT, out)
            * smoothstep(*NOSE_LOW, y) * smoothstep(*NOSE_HIGH, y)
            * smoothstep(*NOSE_FRONT, z) * smoothstep(*BEHIND_TIP, z))


def _chin_boss(x: Array, y: Array, z: Array, midline: float) -> Array:
    """In [0, 1]: the chin boss, below the crease under the lower lip."""
    return (smoothstep(*CHIN_SIDE, np.abs(x - midline)) * smoothstep(*CHIN_HIGH, y)
            * smoothstep(*CHIN_LOW, y) * smoothstep(*CHIN_FRONT, z)
            * smoothstep(*BEHIND_TIP, z))


def _lifted(places: FacePlaces, rest: Array, target: Array, compression: Array,
            where: Array) -> tuple[float, float]:
    """How much a pose squeezes the skin ``where`` (a weight per vertex), on average, as a share
    of its strong compression, and how far it lifts it, on average, as a share of its largest
    motion (``anatomy.squeezed_share``, ``anatomy.moved_share``)."""
    return (squeezed_share(compression, where),
            moved_share(rest, target, where, places._up(rest)))


def sneering_sides(places: FacePlaces, rest: Array, target: Array, compression: Array
                   ) -> tuple[float, ...]:
    """The sides (−1: the character's right, 1: left, face x) on which a pose sneers: it
    squeezes the side of the nose above the nostril wings (``compression``, per vertex: its
    mean over the triangles around it) by ``SNEER_SQUEEZED`` of its strong compression and
    lifts it by ``SNEER_UP`` of its largest motion — the side of the nose pulled up, not an
    upper lip raised (it squeezes the lip, below), a cheek squint nor a brow raise. Empty for
    any other pose."""
    x, y, z = places.xyz.astype(np.float64).T
    _, side = _outward(x, places.midline)
    sides = []
    for s in (-1.0, 1.0):
        where = _nose_side(x, y, z, places.midline) * (side == s)
        squeezed, lifted = _lifted(places, rest, target, compression, where)
        if squeezed >= SNEER_SQUEEZED and lifted >= SNEER_UP:
            sides.append(s)
    return tuple(sides)


def pushes_chin(places: FacePlaces, rest: Array, target: Array, compression: Array) -> bool:
    """Whether a pose pushes the chin boss up (the mentalis): it squeezes the chin's skin below
    the lower lip (``compression`` per vertex, as for ``sneering_sides``) by
    ``CHIN_SQUEEZED`` of its strong compression and lifts it by ``CHIN_UP`` of its largest
    motion — not a lip press (it lifts the lips more than the chin), a jaw drop nor a
    frown."""
    x, y, z = places.xyz.astype(np.float64).T
    where = _chin_boss(x, y, z, places.midline)
    squeezed, lifted = _lifted(places, rest, target, compression, where)
    return squeezed >= CHIN_SQUEEZED and lifted >= CHIN_UP


def bunny_lines(x: Array, y: Array, z: Array, midline: float,
                sides: tuple[float, ...] = (-1.0, 1.0)) -> tuple[Array, Array]:
    """(window, phase) images for a sneer's bunny lines from images of face x, y and z (or
    per-vertex arrays of them), on the side of the nose on the ``sides`` it sneers
    (``sneering_sides``): three short lines ``BUNNY_SPACING`` apart in an oval
    (``BUNNY_REACH``) around ``BUNNY_CENTRE``, running down and out at ``BUNNY_ANGLE`` below
    the horizontal, on the nose between the inner corner of the eye and the nostril wing,
    none on the cheek. The window's top is ``BUNNY_GAIN``; the phase (a line's bottom at each
    multiple of 2π) runs across the lines. Elsewhere the window is ``BUNNY_QUIET``, but for
    the other side of the nose: no line."""
    out, side = _outward(x, midline)
    angle = np.radians(BUNNY_ANGLE)
    dx, dy = out - BUNNY_CENTRE[0], y - BUNNY_CENTRE[1]
    along = np.cos(angle) * dx - np.sin(angle) * dy  # down and out
    across = np.sin(angle) * dx + np.cos(angle) * dy  # up and out
    oval = np.hypot(along / BUNNY_REACH[0], across / BUNNY_REACH[1])
    nose = _nose_side(x, y, z, midline)
    mine = np.isin(side, sides)
    window = np.maximum(BUNNY_GAIN * nose * smoothstep(1.0, BUNNY_FADE, oval) * mine,
                        BUNNY_QUIET * np.where(mine, 1.0, 1.0 - nose))
    phase = 2.0 * np.pi * across / BUNNY_SPACING
    phase = phase + BUNNY_NARROW * np.sin(phase)
    return window.astype(np.float32), phase.astype(np.float32)


def chin_crease(x: Array, y: Array, z: Array, midline: float, front: float = CREASE_FRONT
                ) -> tuple[Array, Array]:
    """(window, phase) images for a mentalis push from images of face x, y and z (or
    per-vertex arrays of them): one soft crease under the lower lip (``CREASE`` on the
    midline, rising a little along the lip's arc toward the sides and fading out well inside
    the mouth's corners), on the chin's front (no further than ``CREASE_BEHIND`` behind
    ``front``, its face z there: ``lower_face_lines`` measures it), the phase running up and
    down across it. The window's top is ``CREASE_GAIN``."""
    across = np.abs(x - midline)
    off = y - (CREASE + CREASE_CURVE * across * across)
    window = (CREASE_GAIN * smoothstep(*CREASE_SIDE, across)
              * smoothstep(0.5 * CREASE_SPACING, CREASE_HALF, np.abs(off))
              * smoothstep(front - CREASE_BEHIND[0], front - CREASE_BEHIND[1], z))
    phase = 2.0 * np.pi * off / CREASE_SPACING
    return window.astype(np.float32), phase.astype(np.float32)


def lower_face_lines(places: FacePlaces, rest: Array, target: Array, compression: Array):
    """The place function (``functools.partial`` of ``bunny_lines``,
    ``anatomy_lips.lip_lines`` or ``chin_crease`` for this face) for a pose that sneers, purses
    the lips or pushes the chin up, from its compression per vertex (the mean over the
    triangles around each); None for any other pose."""
    if sides := sneering_sides(places, rest, target, compression):
        return partial(bunny_lines, midline=places.midline, sides=sides)
    if purses_lips(places, rest, target, compression):
        return partial(lip_lines, midline=places.midline)
    if pushes_chin(places, rest, target, compression):
        x, y, z = places.xyz.T
        near = np.hypot(x - places.midline, y - CREASE) < CREASE_NEAR
        front = float(z[near].max()) if near.any() else CREASE_FRONT
        return partial(chin_crease, midline=places.midline, front=front)
    return None
