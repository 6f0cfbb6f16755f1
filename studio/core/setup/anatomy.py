"""Where an artist puts a pose's lines, from the face's anatomy: the glabellar lines of a frown,
the crow's feet of a squint, the nasolabial fold of a smile, the marionette line of a mouth
frown.

The furrows of ``wrinkle_synth`` follow each pose's own compression, which is what makes them
work on any head. A rig's brow lowerer, though, squeezes the whole brow and the lower forehead
sideways, and laying furrows across that compression fills the forehead with near-vertical
lines up to the scalp — where a corrugator and procerus frown makes one to three vertical lines
*between the brows* and one or two across the root of the nose. So a pose that pulls the brow
down keeps its compression as *where* and *how strong*, and takes *where exactly and which way*
from the face: two vertical lines, one either side of the midline (an artist's "11"), no
further out than the inner ends of the brows, from above the root of the nose up to where the
pose stops squeezing the skin, deepest low and fading as they rise, and one faint line across
the root of the nose where the squeezed skin reaches that low.
Every line stays inside the skin the pose compresses (``wrinkle_synth.placed_region``).

A squint (the lower lid pushed up) squeezes the lids and the skin under the eye, and furrows
across that compression cross under the eye and radiate both ways from a point — where an
artist paints crow's feet: three to five lines fanning out from the outer corner of the eye
over the temple side only, none on the eye (``crows_feet``).

A smile (the mouth corner pulled up and out) squeezes the whole cheek, and furrows across
that compression are parallel lines over the cheek — where an artist paints one deep
nasolabial fold, from the wing of the nose down and out to beside the mouth corner, and the
cheek bunching under the eye in a line or two below the lower lid. A mouth frown (the corner
pulled down and out) squeezes the skin around the corner, and furrows across it radiate around
the mouth like hairs — where an artist paints at most a short marionette line down from the
corner. Both are one fold along an anatomical line (``fold``), bent toward where *this* pose
squeezes the skin most near that line and as deep as it squeezes it there (``fold_path``): a
fold placed by anatomy alone missed the squeezed skin of heads whose crease lies elsewhere.

Places are in face coordinates (``FacePlaces``: x toward the character's left, y up, z to
the front, from the tip of the nose, in the face box's half width), with anchors measured on
the ICT-FaceKit head's 68 landmarks (inner brows 0.167 either side of the midline, 0.83 above
the tip of the nose; the root of the nose 0.52 above it), so they are shares of the face's own
size. Heights start from where the pose's squeezed skin begins on the head at hand
(``FacePlaces.squeezed_band``): a head whose brows sit lower in its face box gets its lines
lower.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.wrinkles.skin_strain import WRINKLING_COMPRESSION

Array = np.ndarray

STRONG = 98.0  # a pose's strong compression: this percentile over the skin it compresses
GLABELLA_SHARE = 0.05  # a pose with this share of its compression between the brows …
DOWNWARD = 0.3  # … and lowers it when its compressed skin moves down by this share of its motion
# between the brows, for telling a brow lowerer: up to this far out (inner brows' half gap), …
DETECT_SIDE = (0.3, 1.7)
DETECT_HEIGHT = (0.47, 1.44, 0.11)  # … from this high up to this high (face y), fading
INNER_BROW = 0.167  # the inner ends of the brows, either side of the midline (face x)
SIDE_BALANCE = 0.5  # a brow lowerer draws a side's line if it squeezes it this much of the other
SIDE_FADE = (0.05, 0.3)  # … and a one-sided one's window ends this far its side of the midline
SQUEEZED_LOW = 0.1  # the bottom of a frown's squeezed skin: this share of its compression lies
SQUEEZED_HIGH = 0.9  # lower (between the brows) — and its top: this share lies lower (room
SQUEEZED_TOP = 0.95  # for a line across the root of the nose) — and where the lines end: this
# share lies lower (higher up the pose squeezes the skin too little to wrinkle: 2 % on the ICT
# head, where its area ends; lines reaching past it were cut there, square-ended)
BOTTOM = 0.51  # the bottom measured on the ICT-FaceKit head's brow lowerers (face y) …
BOTTOM_RANGE = (0.2, 0.8)  # … and the bottoms believed on other heads
NOSE_BAND = 0.5  # squeezed skin this tall (face y) holds a line across the root of the nose …
NOSE_LINE = 0.03  # … this far above its bottom (the ICT head's root of the nose: 0.54) …
NOSE_LINE_SPACING = 0.08  # … a valley this wide (face y) …
NOSE_LINE_HALF = 0.06  # … ending this far above and below its bottom …
NOSE_LINE_FULL = 0.6  # … full this far either side of the midline (inner brows' half gap) …
NOSE_LINE_END = 0.9  # … and gone from this far out …
NOSE_LINE_GAIN = 0.15  # … much shallower than the vertical lines (0.4 outweighed them), …
NOSE_ROOT = 0.17  # … which begin this far above the bottom (without it: at the bottom) …
GLABELLA_TOP = 1.35  # … and end where the squeezed skin does, no higher than this (face y;
# the inner brows at 0.83 on the ICT head: 1.5 drew bars up the forehead) …
GLABELLA_SHORTEST = 0.2  # … (this long at least, face y) …
GLABELLA_FADE = 0.08  # … fading in over this much at their bottom …
GLABELLA_TAPER = 0.6  # … and tapering out over this share of their length below their top:
# deepest low, where the corrugators pull the brows together, shallow as they rise …
GLABELLA_DROP = 0.1  # … which lies this much lower (face y) per inner brows' half gap out
GLABELLA_TIP = 0.4  # the lines narrowing to this share of their width where they fade
FACE_TOP = 0.95  # furrows end at the top of the face box (the skin the poses deform) …
TOP_FADE = 0.1  # … fading out over this much below it (shares of its half height)
FACING = -0.62  # glabellar lines lie on skin facing forward (face z): the face, not the scalp
LINE_OFFSET = 0.45  # two lines, this share of the inner brows' half gap either side of the
# midline at their bottom (an artist's "11"; three, a line on the midline too, drew a comb) …
LINE_SPLAY = 0.3  # … spreading out by this share of it as they rise to their top …
LINE_WIDTH = 1.0  # … each one valley this wide (shares of the half gap), flat skin between …
ONE_SIDED_WIDTH = 1.5  # … a one-sided pose's single line broader (one corrugator, pulling
# the skin of its side into one fold) …
LINE_NARROW = 0.5  # … its bottom bunched narrower than its shoulders (the phase + this × sin)
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
FAN_HUB_BACK = 0.12  # … radiating from this far behind the corner (toward the eye's middle) …
FAN_HUB_SPACING = 15.0  # … a line every this many degrees around that point
GLABELLA_GAIN = 1.3  # the glabellar lines as deep as PLACED_GAIN (1.8 saturated their walls:
# slots with square ends, however they tapered) …
FAN_GAIN = 0.6  # … crow's feet shallower (1.5 drew claws): few, fine lines
LID_ANGLES = (-125.0, -80.0)  # and two lines under the lower lid (``lower_lid_lines``), clear
LID_GAIN = 0.6  # of the fan's lowest lines, as shallow as them


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
        window = (smoothstep(DETECT_SIDE[1], DETECT_SIDE[0], across)
                  * smoothstep(low - fade, low + fade, y)
                  * smoothstep(high + fade, high - fade, y)
                  * smoothstep(FACING - 0.08, FACING + 0.08, z))
        if float(weight @ window) / total < GLABELLA_SHARE:
            return False
        motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
        up_axis = self._up(rest)
        down = -float(weight @ (motion @ up_axis)) / total
        size = float(weight @ np.linalg.norm(motion, axis=1)) / total
        return size > 0.0 and down > DOWNWARD * size

    def brow_sides(self, per_vertex: Array) -> tuple[float, ...]:
        """The sides (−1: the character's right, 1: left, face x) whose glabellar line a brow
        lowerer draws: each side squeezed between the brows (``per_vertex`` compression
        weights, within ``DETECT_SIDE``'s reach of the midline) by at least ``SIDE_BALANCE``
        of the more squeezed side — both for a frown, one for a one-sided pose (the ICT
        head's left brow lowerer squeezes the right side a quarter as much)."""
        weight = np.asarray(per_vertex, np.float64)
        offset = (self.xyz[:, 0] - self.midline) / INNER_BROW
        near = np.abs(offset) <= DETECT_SIDE[1]
        squeezed = [float(weight[near & (np.sign(offset) == side)].sum()) for side in (-1, 1)]
        most = max(squeezed)
        if most <= 0.0:
            return (-1.0, 1.0)
        return tuple(side for side, w in zip((-1.0, 1.0), squeezed, strict=True)
                     if w >= SIDE_BALANCE * most)

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

    def squeezed_band(self, compression: Array) -> tuple[float, bool, float]:
        """Where a frown's lines begin on this head: the bottom (face y) of the skin a brow
        lowerer squeezes between the brows (``compression`` per vertex; ``SQUEEZED_LOW`` of it
        lies lower), within ``BOTTOM_RANGE``, and whether that skin is ``NOSE_BAND`` tall —
        room for a line across the root of the nose below the vertical lines. Heads differ in
        proportions: the brows of one sit lower in its face box than another's."""
        x, y, z = self.xyz.astype(np.float64).T
        across = np.abs(x - self.midline) / INNER_BROW
        weight = (np.asarray(compression, np.float64) * smoothstep(SIDE_END, SIDE_FULL, across)
                  * smoothstep(FACING - 0.08, FACING + 0.08, z))
        total = weight.sum()
        if total <= 0.0:
            return BOTTOM, True, GLABELLA_TOP
        order = np.argsort(y)
        share = np.cumsum(weight[order]) / total
        low, high, top = (float(y[order][min(int(np.searchsorted(share, q)), len(y) - 1)])
                          for q in (SQUEEZED_LOW, SQUEEZED_HIGH, SQUEEZED_TOP))
        return float(np.clip(low, *BOTTOM_RANGE)), high - low >= NOSE_BAND, top

    def _up(self, rest: Array) -> Array:
        """The model direction of face y, fitted from the vertices (y is linear in position)."""
        return self._axis(rest, 1)

    def _axis(self, rest: Array, k: int) -> Array:
        """The model direction of face axis ``k`` (0: x, 1: y, 2: z), fitted from the
        vertices (face coordinates are linear in position)."""
        points = np.c_[np.asarray(rest, np.float64), np.ones(len(rest))]
        solution, *_ = np.linalg.lstsq(points, self.xyz[:, k].astype(np.float64), rcond=None)
        axis = solution[:3]
        return axis / max(float(np.linalg.norm(axis)), 1e-300)


def on_face(box_y: Array) -> Array:
    """1 up to the top of the face box, fading to 0 over the crown above it (``box_y``, the
    height in the box, from ``FACE_TOP`` − ``TOP_FADE`` to ``FACE_TOP``): the face box ends
    where the poses stop deforming the skin, and a rig's brow raise that still squeezes the
    scalp there would otherwise draw forehead lines over the top of the head — which any
    frown or squint whose motion falls in the brow raise's wrinkle vectors there reveals
    too."""
    return smoothstep(FACE_TOP, FACE_TOP - TOP_FADE, box_y).astype(np.float32)


def squeezed_share(compression: Array, where: Array) -> float:
    """How much a pose squeezes the skin ``where`` (a weight per vertex), on average, as a
    share of its strong compression (the ``STRONG`` percentile of ``compression``, per vertex,
    over the skin it squeezes at all); 0 if it squeezes none."""
    weight = np.asarray(compression, np.float64)
    squeezed = weight[weight > 0.0]
    total = float(np.sum(where))
    if squeezed.size == 0 or total <= 0.0:
        return 0.0
    return float(where @ weight) / total / max(float(np.percentile(squeezed, STRONG)), 1e-300)


def moved_share(rest: Array, target: Array, where: Array, axis: Array) -> float:
    """How far a pose moves the skin ``where`` (a weight per vertex) along ``axis`` (a model
    direction), on average, as a share of its largest motion; 0 if it moves nothing."""
    motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
    largest = float(np.linalg.norm(motion, axis=1).max(initial=0.0))
    total = float(np.sum(where))
    if largest <= 0.0 or total <= 0.0:
        return 0.0
    return float(where @ (motion @ axis)) / total / largest


def smoothstep(edge0: float, edge1: float, x: Array) -> Array:
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def glabella(x: Array, y: Array, z: Array, midline: float, bottom: float = BOTTOM,
             nose: bool = True, top: float = GLABELLA_TOP,
             sides: tuple[float, ...] = (-1.0, 1.0)) -> tuple[Array, Array]:
    """(window, phase) images for a frown's lines from images of face x, y and z (or per-vertex
    arrays of them), on a head whose squeezed skin begins at ``bottom`` (face y:
    ``FacePlaces.squeezed_band``) and ends at ``top``. The window is 1 between the inner
    brows, from ``bottom`` (or above the line across the root of the nose, with ``nose``),
    tapering out over the upper ``GLABELLA_TAPER`` of the way to ``top`` (``GLABELLA_TOP`` at
    most), on skin that faces forward, with soft edges; there the phase (radians, a line's
    bottom at 0) makes one valley ``LINE_OFFSET`` beside the midline on either side, spreading
    a little as it rises, and flat skin between and beside them: the corrugators' lines. With
    ``nose``, below them the window holds one shallower horizontal line (at
    ``NOSE_LINE_GAIN``) across the root of the nose, the procerus's, and the phase runs up and
    down there. Only on the ``sides`` the pose squeezes (``FacePlaces.brow_sides``): a
    one-sided brow lowerer draws its own side's line, its window ending just on its side of the
    midline."""
    across = np.abs(x - midline) / INNER_BROW  # 1 at the inner ends of the brows
    start = bottom + NOSE_ROOT if nose else bottom
    facing = smoothstep(FACING - 0.08, FACING + 0.08, z)
    top = min(max(top, start + GLABELLA_SHORTEST), GLABELLA_TOP)
    end = top - GLABELLA_DROP * across
    along = (smoothstep(start - GLABELLA_FADE, start + GLABELLA_FADE, y)
             * smoothstep(end, end - GLABELLA_TAPER * (top - start), y))
    vertical = smoothstep(SIDE_END, SIDE_FULL, across) * along
    rise = np.clip((y - start) / max(top - start, 1e-6), 0.0, 1.0)
    # each line narrowing as it fades toward its ends, as a fold does: a spindle, not a slot
    width = (LINE_WIDTH * (ONE_SIDED_WIDTH if len(sides) == 1 else 1.0)
             * (GLABELLA_TIP + (1.0 - GLABELLA_TIP) * np.sqrt(along)))
    phase = _one_valley((across - LINE_OFFSET * (1.0 + LINE_SPLAY * rise)) / width)
    phase = phase + LINE_NARROW * np.sin(phase)
    if nose:
        line = bottom + NOSE_LINE
        off = np.abs(y - line)
        across_root = (NOSE_LINE_GAIN * smoothstep(NOSE_LINE_END, NOSE_LINE_FULL, across)
                       * smoothstep(NOSE_LINE_HALF, 0.5 * NOSE_LINE_SPACING, off))
        phase = np.where(across_root > vertical, 2.0 * np.pi * (y - line) / NOSE_LINE_SPACING,
                         phase)
        vertical = np.maximum(vertical, across_root)
    if len(sides) == 1:  # clear of the midline: the other side's line shares the map
        vertical = vertical * smoothstep(*SIDE_FADE, sides[0] * (x - midline) / INNER_BROW)
    return (vertical * facing).astype(np.float32), phase.astype(np.float32)


def crows_feet(x: Array, y: Array, z: Array, midline: float,
               sides: tuple[float, ...] = (-1.0, 1.0)) -> tuple[Array, Array]:
    """(window, phase) images for a squint's crow's feet from images of face x, y and z (or
    per-vertex arrays of them), beside the outer corner of the eye on the ``sides`` it
    squints (``FacePlaces.squinting_sides``): lines radiating from the corner outward only,
    ``FAN_SPACING`` degrees apart over ``FAN_ANGLES``, from ``FAN_START`` (off the lids) to
    ``FAN_END`` from the corner; and two shallower lines under the lower lid, along it
    (``LID_ANGLES``), where a squint that pushes the lid up bunches the skin below it — all
    an avatar maker's lid squint squeezes, its outer corner hardly. The phase runs around the
    corner (a line's bottom at each multiple of 2π), and down from the lid under it."""
    del z  # the temple faces sideways, the lids forward: both hold crow's feet
    side = np.where(x - midline >= 0.0, 1.0, -1.0)
    dx = side * (x - midline) - OUTER_EYE[0]  # outward from the corner
    dy = y - OUTER_EYE[1]
    r = np.hypot(dx, dy)
    angle = np.degrees(np.arctan2(dy, dx))
    low, high = FAN_ANGLES
    window = (smoothstep(FAN_START - FAN_FADE, FAN_START + FAN_FADE, r)
              * smoothstep(FAN_END + FAN_FADE, FAN_END - FAN_FADE, r)
              * smoothstep(low - FAN_EDGE, low + FAN_EDGE, angle)
              * smoothstep(high + FAN_EDGE, high - FAN_EDGE, angle)
              * np.isin(side, sides))
    # the lines lie across the orbicularis' ring, radiating from behind the corner (toward
    # the eye's middle), not from the corner itself: they start spread along it, no hub
    hub = np.degrees(np.arctan2(dy, dx + FAN_HUB_BACK))
    phase = 2.0 * np.pi * (hub - FAN_FIRST) / FAN_HUB_SPACING
    lids, lid_phase, near = lower_lid_lines(side * (x - midline), y, LID_ANGLES, LID_GAIN)
    lids = lids * np.isin(side, sides)
    phase = np.where(near & ~(window > 0.0), lid_phase, phase)
    window = np.maximum(window, lids)
    return window.astype(np.float32), phase.astype(np.float32)


# --- the lower face: a smile's nasolabial fold and cheek bunching, a mouth frown's marionette
# line. Anchors on the ICT-FaceKit head's landmarks (face x on the character's left, y): the
# wing of the nose (35) at (0.18, −0.18), the mouth corner (54) at (0.36, −0.51), the left eye's
# lower lid (46, 47) at y 0.42 between x 0.39 and 0.55.
NASOLABIAL = ((0.23, -0.08), (0.47, -0.62))  # from above the wing of the nose to beside and
# below the mouth corner: where an artist paints the nasolabial fold …
MARIONETTE = ((0.39, -0.56), (0.47, -0.86))  # … and a marionette line, down from the corner
FOLD_REACH = 0.12  # the fold follows the pose's strongest compression this far either side …
FOLD_BINS = 10  # … found over this many stretches along it …
FOLD_POWER = 3.0  # … weighting the compression by this power (its strongest, not its spread)
FOLD_WIDTH = (0.3, 0.4)  # one valley this wide (face x) inside and outside its bottom: a
# single broad fold, steeper toward the mouth and the cheek rolling over it, no second one beside
# it (0.14 and 0.4, three times as deep, drew a trench with hard walls)
FLAT_BEYOND = 0.02  # past its rims the phase rises this much as steeply: the skin stays flat
FOLD_ENDS = (0.1, 0.4)  # fading in over this share of its length, out over this share
FOLD_TIP = 0.25  # … narrowing to this share of its width where it has faded
FOLD_FACING = -1.0  # on skin in front of this (face z): the face, not the ear nor the scalp
FOLD_GAIN = 1.2  # a nasolabial fold, a little deeper than a frown's lines and broader …
MARIONETTE_GAIN = 0.4  # … a marionette line, shallower and shorter
LOWER_LID = (0.45, 0.47, 0.3, 0.17)  # the lower lid's arc: centre (face x, y), half width and
# depth of an ellipse whose bottom lies where the cheek bunches under the eye …
BUNCH_SPACING = 0.08  # … and a second line this much lower (face y) …
BUNCH_ANGLES = (-125.0, -60.0)  # … under the eye (degrees from outward, down negative) …
BUNCH_EDGE = 15.0  # … fading over this much …
BUNCH_GAIN = 0.25  # … shallower than the fold (relative to it)
BUNCH_MARGIN = 0.3  # their phase holds this many spacings (and 30°) beyond their window
SMILE_REACH = 0.25  # a pose compresses the skin this close to the nasolabial line …
SMILE_SHARE = 0.35  # … by this share of its compression …
SMILE_UP = 0.45  # … moving it up by this share of its motion (a mouth frown: down) …
SMILE_OUT = 0.35  # … and outward by this share: on the ICT head a smile 0.68 and 0.51, a frown
# −0.84 and 0.41; not a dimple (0.52, 0.23), the mouth moved aside (0.38, 0.80), a stretch
# (−0.19, 0.78), the lower lip pulled down (−0.86, 0.29), a sneer (0.97, −0.07)


def _segment(dx: Array, y: Array, line: tuple[tuple[float, float], tuple[float, float]]
             ) -> tuple[Array, Array]:
    """(u, v): how far along a line from its start (0) to its end (1), and how far from it,
    outward positive (face x units), for points at ``dx`` (outward from the midline) and ``y``."""
    (x0, y0), (x1, y1) = line
    ax, ay = x1 - x0, y1 - y0
    length = float(np.hypot(ax, ay))
    ex, ey = ax / length, ay / length
    px, py = dx - x0, y - y0
    u = (px * ex + py * ey) / length
    v = py * ex - px * ey  # to the left of a line running down and out: outward
    return u, v


def mouth_sides(places: FacePlaces, rest: Array, target: Array, compression: Array,
                line: tuple[tuple[float, float], tuple[float, float]], up: bool
                ) -> tuple[float, ...]:
    """The sides (−1, 1: face x) on which a pose pulls the mouth corner along ``line`` (on that
    side): ``SMILE_SHARE`` of its compression (``compression`` per vertex) lies within
    ``SMILE_REACH`` of the line, and that skin moves up (``up``: a smile, bunching the cheek
    against the nose's wing) or down (a mouth frown) by ``SMILE_UP`` of its motion and outward
    by ``SMILE_OUT``. Empty for any other pose: a sneer lifts the skin beside the nose without
    pulling it out, a dimple pulls the corner back, a stretch or the mouth moved aside pull it
    sideways, a pucker or a mentalis push squeeze the lips and chin toward the midline."""
    weight = np.asarray(compression, np.float64)
    total = weight.sum()
    if total <= 0.0:
        return ()
    x, y, z = places.xyz.astype(np.float64).T
    motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
    rise = motion @ places._up(rest) * (1.0 if up else -1.0)
    across = motion @ places._axis(rest, 0)
    size = np.linalg.norm(motion, axis=1)
    length = float(np.hypot(line[1][0] - line[0][0], line[1][1] - line[0][1]))
    sides = []
    for side in (-1.0, 1.0):
        u, v = _segment(side * (x - places.midline), y, line)
        beyond = (np.clip(u, 0.0, 1.0) - u) * length  # past the line's ends
        near = (np.hypot(beyond, v) < SMILE_REACH) & (z > FOLD_FACING)
        share = float(weight[near].sum()) / total
        moved = float(weight[near] @ size[near])
        if share >= SMILE_SHARE and moved > 0.0 and (
                float(weight[near] @ rise[near]) >= SMILE_UP * moved
                and side * float(weight[near] @ across[near]) >= SMILE_OUT * moved):
            sides.append(side)
    return tuple(sides)


@dataclass(frozen=True)
class FoldPath:
    """Where one pose's fold lies on this head and how deep, per side (0: the character's
    right, 1: left) and per stretch along its line (``FOLD_BINS``): from the pose's own
    compression (``fold_path``)."""

    offsets: Array  # (2, FOLD_BINS) face x: how far out of the line the fold's bottom lies
    depths: Array  # (2, FOLD_BINS) in [0, 1]: its depth there
    bunch: Array  # (2,) in [0, 1]: the depth of the cheek's bunching under the eye


def fold_path(places: FacePlaces, compression: Array, sides: tuple[float, ...],
              line: tuple[tuple[float, float], tuple[float, float]]) -> FoldPath:
    """The fold's path on this head: for each of ``FOLD_BINS`` stretches along ``line``, how
    far out (face x) the pose squeezes the skin most within ``FOLD_REACH`` of it (its
    compression to the power ``FOLD_POWER`` as weights; 0 where it squeezes none), so the fold
    lies on *this* head's crease, not only on the anatomy's average one; and how deep, from
    that strong compression (full from ``WRINKLING_COMPRESSION``, none below a quarter of it)
    — along the fold only, so its edges stay smooth where the compression beside it is
    patchy. Both smoothed along the line, so the fold bends and fades gently. The cheek's
    bunching under the eye is as deep as the pose squeezes the skin there."""
    x, y, z = places.xyz.astype(np.float64).T
    squeeze = np.asarray(compression, np.float64) * (z > FOLD_FACING)
    weight = squeeze ** FOLD_POWER
    offsets, depths, bunch = np.zeros((2, FOLD_BINS)), np.zeros((2, FOLD_BINS)), np.zeros(2)
    for k, side in enumerate((-1.0, 1.0)):
        if side not in sides:
            continue
        dx = side * (x - places.midline)
        u, v = _segment(dx, y, line)
        near = (np.abs(v) < FOLD_REACH) & (u >= 0.0) & (u < 1.0)
        at = np.clip((u[near] * FOLD_BINS).astype(int), 0, FOLD_BINS - 1)
        w = weight[near]
        total = np.bincount(at, w, FOLD_BINS)
        known = total > 1e-3 * max(float(total.max(initial=0.0)), 1e-300)
        safe = np.maximum(total, 1e-300)
        offset = np.where(known, np.bincount(at, w * v[near], FOLD_BINS) / safe, 0.0)
        strong = np.where(known, np.bincount(at, w * squeeze[near], FOLD_BINS) / safe, 0.0)
        offsets[k] = np.clip(_along(offset), -0.8 * FOLD_REACH, 0.8 * FOLD_REACH)
        depths[k] = _along(_ramp(strong))
        cx, cy, a, b = LOWER_LID
        rho = np.hypot((dx - cx) / a, (y - cy) / b)
        under = (rho > 1.0 - 0.5 * BUNCH_SPACING / b) & (rho < 1.0 + 2.0 * BUNCH_SPACING / b) & (
            y < cy) & (z > FOLD_FACING)
        if under.any():
            w = weight[under]
            bunch[k] = _ramp(float(w @ squeeze[under]) / max(float(w.sum()), 1e-300))
    return FoldPath(offsets, depths, bunch)


def _ramp(compression: Array | float) -> Array:
    """0 below a quarter of ``WRINKLING_COMPRESSION``, 1 from it on: a signature line is as
    deep as an artist paints it wherever the pose squeezes the skin at all."""
    return np.clip((np.asarray(compression) - 0.25 * WRINKLING_COMPRESSION)
                   / (0.75 * WRINKLING_COMPRESSION), 0.0, 1.0)


def _along(values: Array) -> Array:
    """Smoothed along a line's stretches ([1, 2, 1] twice, the ends held)."""
    for _ in range(2):
        values = np.r_[values[0], 0.25 * values[:-2] + 0.5 * values[1:-1] + 0.25 * values[2:],
                       values[-1]]
    return values


def _one_valley(t: Array) -> Array:
    """A phase of one valley only: 2π per unit of ``t`` from −½ to ½ (the valley's bottom at
    0, its rims at ±π), then barely rising (``FLAT_BEYOND`` as steep), so the valley profile
    stays at its rim's 0 — one fold whose walls fade smoothly into the skin beside it, with
    no second valley and no edge for the window to cut — while the phase's gradient still
    points across the fold."""
    rim = np.clip(t, -0.5, 0.5)
    return 2.0 * np.pi * (rim + FLAT_BEYOND * (t - rim))


def lower_lid_lines(dx: Array, y: Array, angles: tuple[float, float], gain: Array | float
                    ) -> tuple[Array, Array, Array]:
    """(window, phase, support) for two short lines under the lower lid, along its arc
    (``LOWER_LID``: at the arc's bottom and ``BUNCH_SPACING`` below it, then flat skin), over
    ``angles`` (degrees around the eye's centre from outward, down negative), at ``gain``;
    from images of face x outward from the midline (``dx``) and y. The support is where the
    phase must be theirs: their window and ``BUNCH_MARGIN`` beyond it, so that another
    line's phase meets theirs only where neither draws — a resampled phase that mixes two
    cannot draw a line there."""
    cx, cy, a, b = LOWER_LID
    ex, ey = (dx - cx) / a, (y - cy) / b
    below = (np.hypot(ex, ey) - 1.0) * b  # how far below the lid's arc (face y, about)
    angle = np.degrees(np.arctan2(ey, ex))
    low, high = angles
    window = (gain * smoothstep(low - BUNCH_EDGE, low + BUNCH_EDGE, angle)
              * smoothstep(high + BUNCH_EDGE, high - BUNCH_EDGE, angle)
              * smoothstep(-BUNCH_SPACING, -0.5 * BUNCH_SPACING, below)
              * smoothstep(2.0 * BUNCH_SPACING, 1.5 * BUNCH_SPACING, below))
    margin = BUNCH_MARGIN * BUNCH_SPACING
    support = ((angle > low - BUNCH_EDGE - BUNCH_MARGIN * 100.0)
               & (angle < high + BUNCH_EDGE + BUNCH_MARGIN * 100.0)
               & (below > -BUNCH_SPACING - margin) & (below < 2.0 * BUNCH_SPACING + margin))
    phase = _one_valley(0.5 * (below / BUNCH_SPACING - 0.5)) * 2.0 + np.pi
    return window, phase, support


def fold(x: Array, y: Array, z: Array, midline: float, sides: tuple[float, ...],
         line: tuple[tuple[float, float], tuple[float, float]], path: FoldPath,
         bunch: bool = False) -> tuple[Array, Array]:
    """(window, phase) images for one fold along ``line`` on the ``sides`` given, bent and
    deepened as ``path`` says (``fold_path``), from images of face x, y and z (or per-vertex
    arrays): a single valley (``FOLD_WIDTH`` inside and outside) whose bottom follows the
    line, fading in and out at its ends (``FOLD_ENDS``) — a nasolabial fold, a marionette
    line. With ``bunch``, two short, shallower lines under the lower lid too (``LOWER_LID``,
    as deep as the pose squeezes the skin there): the cheek a smile pushes up bunching under
    the eye. The window holds each line's depth; the phase is 0 along a line's bottom."""
    side = np.where(x - midline >= 0.0, 1.0, -1.0)
    dx = side * (x - midline)
    u, v = _segment(dx, y, line)
    centres = (np.arange(FOLD_BINS) + 0.5) / FOLD_BINS
    left = side > 0.0
    offset = np.where(left, np.interp(u, centres, path.offsets[1]),
                      np.interp(u, centres, path.offsets[0]))
    depth = np.where(left, np.interp(u, centres, path.depths[1]),
                     np.interp(u, centres, path.depths[0]))
    d = v - offset
    ends = smoothstep(-0.02, FOLD_ENDS[0], u) * smoothstep(1.0, 1.0 - FOLD_ENDS[1], u)
    # narrowing as it fades: a crease ends in a point, not on a cut straight across it (a
    # valley wider than its fade is long ended in a box with a step at its foot)
    narrow = FOLD_TIP + (1.0 - FOLD_TIP) * np.sqrt(ends)
    across = d / (np.where(d < 0.0, FOLD_WIDTH[0], FOLD_WIDTH[1]) * narrow)  # ±½ at the rims
    window = depth * ends * smoothstep(1.0, 0.6, np.abs(across))
    phase = _one_valley(across)
    if bunch:
        under, lid_phase, near = lower_lid_lines(
            dx, y, BUNCH_ANGLES, BUNCH_GAIN * np.where(left, path.bunch[1], path.bunch[0]))
        phase = np.where(near & ~(window > 0.0), lid_phase, phase)
        window = np.maximum(window, under)
    window = window * np.isin(side, sides) * smoothstep(FOLD_FACING - 0.08,
                                                         FOLD_FACING + 0.08, z)
    return window.astype(np.float32), phase.astype(np.float32)
