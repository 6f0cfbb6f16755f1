"""Where an artist puts a pose's lines, from the face's anatomy: the glabellar lines of a frown.

The furrows of ``wrinkle_synth`` follow each pose's own compression, which is what makes them
work on any head. A rig's brow lowerer, though, squeezes the whole brow and the lower forehead
sideways, and laying furrows across that compression fills the forehead with near-vertical
lines up to the scalp — where a corrugator and procerus frown makes one to three vertical lines
*between the brows* (and a line across the root of the nose where the rig squeezes it). So a
pose that pulls the brow down keeps its compression as *where* and *how strong*, and takes
*where exactly and which way* from the face: vertical lines beside the midline, as far out as
the inner ends of the brows, from the root of the nose up into the lower forehead.

Places are in face coordinates (``FacePlaces``: x toward the character's left, y up, z to
the front, from the tip of the nose, in the face box's half width), with anchors measured on
the ICT-FaceKit head's 68 landmarks (inner brows 0.167 either side of the midline, 1.27 above
the tip of the nose; the root of the nose 0.52 above it), so they are shares of the face's own
size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

GLABELLA_SHARE = 0.05  # a pose with this share of its compression between the brows …
DOWNWARD = 0.3  # … and lowers it when its compressed skin moves down by this share of its motion
INNER_BROW = 0.167  # the inner ends of the brows, either side of the midline (face x)
NOSE_ROOT = 0.47  # the root of the nose (face y): where glabellar lines begin …
GLABELLA_TOP = 1.44  # … and how far up the lower forehead they reach (face y) …
GLABELLA_FADE = 0.11  # … fading in and out over this much
FACE_TOP = 0.95  # furrows end at the top of the face box (the skin the poses deform) …
TOP_FADE = 0.1  # … fading out over this much below it (shares of its half height)
FACING = -0.62  # glabellar lines lie on skin facing forward (face z): the face, not the scalp
LINE_OFFSET = 0.0  # the first line on the midline, then every …
LINE_SPACING = 0.35  # … this share of the inner brows' half gap
EDGE = 0.7  # the soft edge of the glabella, a share of its half width


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
        window, _ = glabella(x, y, z, self.midline)
        if float(weight @ window) / total < GLABELLA_SHARE:
            return False
        motion = np.asarray(target, np.float64) - np.asarray(rest, np.float64)
        up_axis = self._up(rest)
        down = -float(weight @ (motion @ up_axis)) / total
        size = float(weight @ np.linalg.norm(motion, axis=1)) / total
        return size > 0.0 and down > DOWNWARD * size

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


def glabella(x: Array, y: Array, z: Array, midline: float) -> tuple[Array, Array]:
    """(window, phase) images for a frown's lines from images of face x, y and z: the window
    is 1 between the inner brows, from the root of the nose into the lower forehead, on skin
    that faces forward, with soft edges; the phase (radians, a line's bottom at each multiple
    of 2π) makes vertical lines ``LINE_SPACING`` apart, the first ``LINE_OFFSET`` beside the
    midline on either side."""
    across = np.abs(x - midline) / INNER_BROW  # 1 at the inner ends of the brows
    side = _smoothstep(1.0 + EDGE, 1.0 - EDGE, across)
    height = (_smoothstep(NOSE_ROOT - GLABELLA_FADE, NOSE_ROOT + GLABELLA_FADE, y)
              * _smoothstep(GLABELLA_TOP + GLABELLA_FADE, GLABELLA_TOP - GLABELLA_FADE, y)
              * _smoothstep(FACING - 0.08, FACING + 0.08, z))
    phase = 2.0 * np.pi * (across - LINE_OFFSET) / LINE_SPACING
    return (side * height).astype(np.float32), phase.astype(np.float32)
