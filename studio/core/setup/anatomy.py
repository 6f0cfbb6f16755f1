"""Where an artist puts a pose's lines, from the face's anatomy: the glabellar lines of a frown,
the crow's feet of a squint.

The furrows of ``wrinkle_synth`` follow each pose's own compression, which is what makes them
work on any head. A rig's brow lowerer, though, squeezes the whole brow and the lower forehead
sideways, and laying furrows across that compression fills the forehead with near-vertical
lines up to the scalp — where a corrugator and procerus frown makes one to three vertical lines
*between the brows* and one or two across the root of the nose. So a pose that pulls the brow
down keeps its compression as *where* and *how strong*, and takes *where exactly and which way*
from the face: three vertical lines (one on the midline, one either side of it), no further out
than the inner ends of the brows, from above the root of the nose up into the lower forehead,
and one shallower line across the root of the nose where the squeezed skin reaches that low.
Every line stays inside the skin the pose compresses (``wrinkle_synth.placed_region``).

A squint (the lower lid pushed up) squeezes the lids and the skin under the eye, and furrows
across that compression cross under the eye and radiate both ways from a point — where an
artist paints crow's feet: three to five lines fanning out from the outer corner of the eye
over the temple side only, none on the eye (``crows_feet``).

Places are in face coordinates (``FacePlaces``: x toward the character's left, y up, z to
the front, from the tip of the nose, in the face box's half width), with anchors measured on
the ICT-FaceKit head's 68 landmarks (inner brows 0.167 either side of the midline, 1.27 above
the tip of the nose; the root of the nose 0.52 above it), so they are shares of the face's own
size. Heights start from where the pose's squeezed skin begins on the head at hand
(``FacePlaces.squeezed_band``): a head whose brows sit lower in its face box gets its lines
lower.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

GLABELLA_SHARE = 0.05  # a pose with this share of its compression between the brows …
DOWNWARD = 0.3  # … and lowers it when its compressed skin moves down by this share of its motion
# between the brows, for telling a brow lowerer: up to this far out (inner brows' half gap), …
DETECT_SIDE = (0.3, 1.7)
DETECT_HEIGHT = (0.47, 1.44, 0.11)  # … from this high up to this high (face y), fading
INNER_BROW = 0.167  # the inner ends of the brows, either side of the midline (face x)
SQUEEZED_LOW = 0.1  # the bottom of a frown's squeezed skin: this share of its compression lies
SQUEEZED_HIGH = 0.9  # lower (between the brows) — and the top: this share lies lower
BOTTOM = 0.51  # the bottom measured on the ICT-FaceKit head's brow lowerers (face y) …
BOTTOM_RANGE = (0.2, 0.8)  # … and the bottoms believed on other heads
NOSE_BAND = 0.5  # squeezed skin this tall (face y) holds a line across the root of the nose …
NOSE_LINE = 0.03  # … this far above its bottom (the ICT head's root of the nose: 0.54) …
NOSE_LINE_SPACING = 0.08  # … a valley this wide (face y) …
NOSE_LINE_HALF = 0.06  # … ending this far above and below its bottom …
NOSE_LINE_FULL = 0.6  # … full this far either side of the midline (inner brows' half gap) …
NOSE_LINE_END = 0.9  # … and gone from this far out …
NOSE_LINE_GAIN = 0.4  # … shallower than the vertical lines, …
NOSE_ROOT = 0.17  # … which begin this far above the bottom (without it: at the bottom) …
GLABELLA_TOP = 1.4  # … and reach this far up the lower forehead (face y) …
GLABELLA_FADE = 0.08  # … fading in and out over this much
FACE_TOP = 0.95  # furrows end at the top of the face box (the skin the poses deform) …
TOP_FADE = 0.1  # … fading out over this much below it (shares of its half height)
FACING = -0.62  # glabellar lines lie on skin facing forward (face z): the face, not the scalp
LINE_OFFSET = 0.0  # one line on the midline, then every …
LINE_SPACING = 0.55  # … this share of the inner brows' half gap: three lines between the brows
SIDE_FULL = 0.9  # the lines at full depth this far out (shares of the inner brows' half gap) …
SIDE_END = 1.2  # … and none past the inner ends of the brows
OUTER_EYE = (0.635, 0.476)  # the outer corner of an eye (face x either side, y) …
EYE_REACH = 0.4  # … the skin within this of it, no higher than …
EYE_ABOVE = 0.05  # … this above it: a squint squeezes this share of its compression there …
EYE_SHARE = 0.4  # … (a brow lowerer: 0.12, a smile 0.07, a look up 0.28 on the ICT head) …
EYE_UP = 0.1  # … and that skin moves up by this share of its motion (the ICT head's squint:
# 0.71, cheek raise 0.65; the glTF test avatar's squint, toward the corner: 0.15; a look aside
# 0.05–0.07, a blink −0.35)
FAN_START = 0.06  # crow's feet from this far from the outer corner (off the lids) …
FAN_END = 0.46  # … out to this far, fading over …
FAN_FADE = 0.05  # … this much
FAN_ANGLES = (-68.0, 50.0)  # degrees from straight outward (up positive): the fan's spread …
FAN_EDGE = 10.0  # … fading over this much …
FAN_SPACING = 25.0  # … a line every this many degrees, …
FAN_FIRST = -60.0  # … the lowest here, …
FAN_GAIN = 1.5  # … this much deeper than a frown's lines: few, on skin the squint barely squeezes


@dataclass(frozen=True)
class FacePlaces:
    """Each welded vertex's place on the face, and the midline (face x)."""

    # (W, 3) face x (toward the character's left), y (up) and z (front), from the tip of the
    # nose, in the face box's half width
    xyz: Array
    midline: float  # face x of the left–right symmetry plane
    box_y: Array  # (W,) height in the face box (−1 … 1): the skin the poses deform

    @classmethod
    def of(cls, frame, rest: Array, skin: Array | None = None) -> FacePlaces:
        """From a ``face_frame.FaceFrame``, the neutral positions and the skin's weights: the
        frame's axes, the origin at the tip of the nose (the skin's most forward point on any
        head, and on its midline, where the mean of the skin is moved off it by a scan's
        asymmetric neck or a slight turn of the head) and the face box's half width as the
        unit (its height grows with a neck that a rig of few poses deforms; its width
        stays)."""
        local = (np.asarray(rest, np.float64) - np.asarray(frame.centre)) @ frame.basis()
        skin = np.asarray(skin, np.float64) > 0 if skin is not None else np.ones(len(rest), bool)
        front = np.flatnonzero(skin)[int(np.argmax(local[skin, 2]))] if skin.any() else 0
        return cls(((local - local[front]) / max(frame.half[0], 1e-300)).astype(np.float32),
                   0.0, (local[:, 1] / max(frame.half[1], 1e-300)).astype(np.float32))

    def lowers_brow(self, rest: Array, target: Array, per_vertex: Array) -> bool:
        """Whether a pose pulls a brow down: ``GLABELLA_SHARE`` of the skin it compresses
        (``per_vertex`` weights) lies between the brows, and the compressed skin moves down by
        more than ``DOWNWARD`` of its motion — a brow lowerer (a frown), not a brow raise,
        which compresses the forehead moving up, nor a blink, which compresses the lids."""
        weight = np.asarray(per_vertex, np.float64)
        total = weight.sum()
        if total <= 0.0:
            return False
        x, y, z = self.xyz.T
        across = np.abs(x - self.midline) / INNER_BROW
        low, high, fade = DETECT_HEIGHT
        window = (_smoothstep(DETECT_SIDE[1], DETECT_SIDE[0], across)
                  * _smoothstep(low - fade, low + fade, y)
                  * _smoothstep(high + fade, high - fade, y)
                  * _smoothstep(FACING - 0.08, FACING + 0.08, z))
        if float(weight @ window) / total < GLABELLA_SHARE:
            return False
        motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
        up_axis = self._up(rest)
        down = -float(weight @ (motion @ up_axis)) / total
        size = float(weight @ np.linalg.norm(motion, axis=1)) / total
        return size > 0.0 and down > DOWNWARD * size

    def squinting_sides(self, rest: Array, target: Array, compression: Array
                        ) -> tuple[float, ...]:
        """The sides (−1: the character's right, 1: left, face x) on which a pose squints:
        ``EYE_SHARE`` of the skin it compresses (``compression`` per vertex) lies around that
        outer corner of the eye (within ``EYE_REACH``, no higher than ``EYE_ABOVE`` above it)
        and moves up by ``EYE_UP`` of its motion — the lower lid and cheek pushed up, not an
        upper lid closing (a blink), the eye looking aside (the lids slide sideways) nor a
        brow lowered. Empty for any other pose."""
        weight = np.asarray(compression, np.float64)
        total = weight.sum()
        if total <= 0.0:
            return ()
        x, y = self.xyz[:, 0].astype(np.float64), self.xyz[:, 1].astype(np.float64)
        motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
        up = motion @ self._up(rest)
        size = np.linalg.norm(motion, axis=1)
        sides = []
        for side in (-1.0, 1.0):
            near = ((np.hypot(x - self.midline - side * OUTER_EYE[0], y - OUTER_EYE[1])
                     < EYE_REACH) & (y < OUTER_EYE[1] + EYE_ABOVE))
            share = float(weight[near].sum()) / total
            moved = float(weight[near] @ size[near])
            if share >= EYE_SHARE and moved > 0.0 and (
                    float(weight[near] @ up[near]) >= EYE_UP * moved):
                sides.append(side)
        return tuple(sides)

    def squeezed_band(self, compression: Array) -> tuple[float, bool]:
        """Where a frown's lines begin on this head: the bottom (face y) of the skin a brow
        lowerer squeezes between the brows (``compression`` per vertex; ``SQUEEZED_LOW`` of it
        lies lower), within ``BOTTOM_RANGE``, and whether that skin is ``NOSE_BAND`` tall —
        room for a line across the root of the nose below the vertical lines. Heads differ in
        proportions: the brows of one sit lower in its face box than another's."""
        x, y, z = self.xyz.astype(np.float64).T
        across = np.abs(x - self.midline) / INNER_BROW
        weight = (np.asarray(compression, np.float64) * _smoothstep(SIDE_END, SIDE_FULL, across)
                  * _smoothstep(FACING - 0.08, FACING + 0.08, z))
        total = weight.sum()
        if total <= 0.0:
            return BOTTOM, True
        order = np.argsort(y)
        share = np.cumsum(weight[order]) / total
        low, high = (float(y[order][min(int(np.searchsorted(share, q)), len(y) - 1)])
                     for q in (SQUEEZED_LOW, SQUEEZED_HIGH))
        return float(np.clip(low, *BOTTOM_RANGE)), high - low >= NOSE_BAND

    def _up(self, rest: Array) -> Array:
        """The model direction of face y, fitted from the vertices (y is linear in position)."""
        points = np.c_[np.asarray(rest, np.float64), np.ones(len(rest))]
        solution, *_ = np.linalg.lstsq(points, self.xyz[:, 1].astype(np.float64), rcond=None)
        up = solution[:3]
        return up / max(float(np.linalg.norm(up)), 1e-300)


def on_face(box_y: Array) -> Array:
    """1 up to the top of the face box, fading to 0 over the crown above it (``box_y``, the
    height in the box, from ``FACE_TOP`` − ``TOP_FADE`` to ``FACE_TOP``): the face box ends
    where the poses stop deforming the skin, and a rig's brow raise that still squeezes the
    scalp there would otherwise draw forehead lines over the top of the head — which any
    frown or squint whose motion falls in the brow raise's wrinkle vectors there reveals
    too."""
    return _smoothstep(FACE_TOP, FACE_TOP - TOP_FADE, box_y).astype(np.float32)


def _smoothstep(edge0: float, edge1: float, x: Array) -> Array:
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def glabella(x: Array, y: Array, z: Array, midline: float, bottom: float = BOTTOM,
             nose: bool = True) -> tuple[Array, Array]:
    """(window, phase) images for a frown's lines from images of face x, y and z (or per-vertex
    arrays of them), on a head whose squeezed skin begins at ``bottom`` (face y:
    ``FacePlaces.squeezed_band``). The window is 1 between the inner brows, from ``bottom``
    (or above the line across the root of the nose, with ``nose``) into the lower forehead, on
    skin that faces forward, with soft edges; there the phase (radians, a line's bottom at
    each multiple of 2π) makes vertical lines ``LINE_SPACING`` apart, the first
    ``LINE_OFFSET`` beside the midline on either side: the corrugators' lines. With ``nose``,
    below them the window holds one shallower horizontal line (at ``NOSE_LINE_GAIN``) across
    the root of the nose, the procerus's, and the phase runs up and down there."""
    across = np.abs(x - midline) / INNER_BROW  # 1 at the inner ends of the brows
    start = bottom + NOSE_ROOT if nose else bottom
    facing = _smoothstep(FACING - 0.08, FACING + 0.08, z)
    vertical = (_smoothstep(SIDE_END, SIDE_FULL, across)
                * _smoothstep(start - GLABELLA_FADE, start + GLABELLA_FADE, y)
                * _smoothstep(GLABELLA_TOP + GLABELLA_FADE, GLABELLA_TOP - GLABELLA_FADE, y))
    phase = 2.0 * np.pi * (across - LINE_OFFSET) / LINE_SPACING
    if nose:
        line = bottom + NOSE_LINE
        off = np.abs(y - line)
        across_root = (NOSE_LINE_GAIN * _smoothstep(NOSE_LINE_END, NOSE_LINE_FULL, across)
                       * _smoothstep(NOSE_LINE_HALF, 0.5 * NOSE_LINE_SPACING, off))
        phase = np.where(across_root > vertical, 2.0 * np.pi * (y - line) / NOSE_LINE_SPACING,
                         phase)
        vertical = np.maximum(vertical, across_root)
    return (vertical * facing).astype(np.float32), phase.astype(np.float32)


def crows_feet(x: Array, y: Array, z: Array, midline: float,
               sides: tuple[float, ...] = (-1.0, 1.0)) -> tuple[Array, Array]:
    """(window, phase) images for a squint's crow's feet from images of face x, y and z (or
    per-vertex arrays of them), beside the outer corner of the eye on the ``sides`` it
    squints (``FacePlaces.squinting_sides``): lines radiating from the corner outward only,
    ``FAN_SPACING`` degrees apart over ``FAN_ANGLES``, from ``FAN_START`` (off the lids) to
    ``FAN_END`` from the corner. The phase runs around the corner (a line's bottom at each
    multiple of 2π)."""
    del z  # the temple faces sideways, the lids forward: both hold crow's feet
    side = np.where(x - midline >= 0.0, 1.0, -1.0)
    dx = side * (x - midline) - OUTER_EYE[0]  # outward from the corner
    dy = y - OUTER_EYE[1]
    r = np.hypot(dx, dy)
    angle = np.degrees(np.arctan2(dy, dx))
    low, high = FAN_ANGLES
    window = (_smoothstep(FAN_START - FAN_FADE, FAN_START + FAN_FADE, r)
              * _smoothstep(FAN_END + FAN_FADE, FAN_END - FAN_FADE, r)
              * _smoothstep(low - FAN_EDGE, low + FAN_EDGE, angle)
              * _smoothstep(high + FAN_EDGE, high - FAN_EDGE, angle)
              * np.isin(side, sides))
    phase = 2.0 * np.pi * (angle - FAN_FIRST) / FAN_SPACING
    return window.astype(np.float32), phase.astype(np.float32)
