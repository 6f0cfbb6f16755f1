"""Combing wrinkle directions: the math of the Comb tool (technique 2), numpy only.

A hair-grooming comb turns a drag on the screen into a direction on the surface. A screen
stroke ``(dx, dy)`` (pixels, y down) at a vertex ``P`` seen from the eye ``E`` is a plane
through the eye: the *stroke plane*, spanned by the view ray ``v = P − E`` and the world vector
``u = dx·right − dy·up`` that moves ``P`` along the stroke on screen. The combed direction is
where that plane cuts the vertex's tangent plane: ``t = n × (v × u)``, turned so that moving
along it moves ``P`` along the stroke, not against it. That is the stroke projected onto the
surface along the view rays, so the drawn vector lies on the drag as the user sees it wherever
the surface is tilted (an orthogonal projection of ``u`` onto the tangent plane would not: on a
cheek turned away it points off the drag). Where the two planes coincide (at the silhouette)
the orthogonal projection is used; where even that vanishes the vertex is left alone.

Each dab blends a vertex's direction toward its combed one by ``strength · falloff`` (the
technique-1 brush's falloff, over screen pixels), so repeated dabs converge on the drag and a
soft brush edge bends directions only a little.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.wrinkles.brush import falloff
from studio.core.wrinkles.wdv import STILL_EPSILON

Array = np.ndarray

DEGENERATE = 1e-6  # relative size under which a cross product has no direction


def _unit(vectors: Array) -> tuple[Array, Array]:
    """Unit rows and their lengths (zero rows stay zero: no NaN)."""
    length = np.linalg.norm(vectors, axis=1)
    safe = np.where(length > 0.0, length, 1.0)
    return vectors / safe[:, None], length


def stroke_directions(positions: Array, normals: Array, eye: Array, right: Array, up: Array,
                      stroke: tuple[float, float]) -> tuple[Array, Array]:
    """Per vertex, the unit surface direction that a screen stroke ``(dx, dy)`` (pixels, y
    down) draws at it, seen from ``eye`` with the camera's ``right`` and ``up`` axes; and
    whether it has one (False where the stroke is zero or the tangent plane has no direction
    along it). Shapes: (K, 3) positions and unit normals in, (K, 3) and (K,) out."""
    positions = np.asarray(positions, np.float64).reshape(-1, 3)
    normals, _ = _unit(np.asarray(normals, np.float64).reshape(-1, 3))
    dx, dy = float(stroke[0]), float(stroke[1])
    u = dx * np.asarray(right, np.float64) - dy * np.asarray(up, np.float64)
    if not np.any(u):
        return np.zeros_like(positions), np.zeros(len(positions), bool)
    u = u / np.linalg.norm(u)
    view, _ = _unit(positions - np.asarray(eye, np.float64))
    plane = np.cross(view, u)  # the stroke plane's normal (u lies in the image plane, so it
    # is never along a ray inside the view: the length stays near 1)
    t = np.cross(normals, plane)
    t, size = _unit(t)
    # u without its part along the ray: the sign of t's component along it says whether t
    # moves the vertex along the stroke on screen (t = α·v + β·u, t·w = β·|w|²)
    w = u[None, :] - (view @ u)[:, None] * view
    along = np.einsum("ij,ij->i", t, w)
    t[along < 0.0] *= -1.0
    # where the tangent plane is the stroke plane (t = 0), or cuts it along the view ray (t
    # moves nothing on screen): the orthogonal projection of the stroke instead
    flat = (size < DEGENERATE) | (np.abs(along) < DEGENERATE * np.linalg.norm(w, axis=1))
    if flat.any():
        ortho = u[None, :] - (normals[flat] @ u)[:, None] * normals[flat]
        t[flat], ortho_size = _unit(ortho)
        size = size.copy()
        size[flat] = ortho_size
    ok = size >= DEGENERATE
    t[~ok] = 0.0
    return t, ok


def blend_directions(old: Array, target: Array, weight: Array) -> Array:
    """``normalize((1 − w)·old + w·target)`` per row: a dab of weight ``w`` bends a direction
    toward its combed one; a zero (unauthored) direction takes the target at once, as does one
    the target exactly opposes (their mix has no direction of its own)."""
    old = np.asarray(old, np.float64).reshape(-1, 3)
    target = np.asarray(target, np.float64).reshape(-1, 3)
    w = np.clip(np.asarray(weight, np.float64).reshape(-1), 0.0, 1.0)[:, None]
    mixed, size = _unit((1.0 - w) * old + w * target)
    lost = size < DEGENERATE
    mixed[lost] = target[lost]
    keep = w[:, 0] <= 0.0
    mixed[keep] = old[keep]
    return mixed


@dataclass(frozen=True)
class CombBrush:
    radius: float = 40.0  # screen pixels
    hardness: float = 0.5  # fraction of the radius combed at full strength; the rest fades
    strength: float = 0.5  # how far each dab bends a direction toward the drag (0..1)


def dab_weights(pixels: Array, centre: tuple[float, float], brush: CombBrush) -> Array:
    """Each vertex's share of a dab at ``centre``: strength × the brush falloff of its distance
    on the screen; (K,) float64, 0 outside the radius."""
    distance = np.linalg.norm(np.asarray(pixels, np.float64) - np.asarray(centre), axis=1)
    return np.clip(brush.strength, 0.0, 1.0) * falloff(distance, brush.radius,
                                                        brush.hardness).astype(np.float64)


def comb_dab(directions: Array, positions: Array, normals: Array, pixels: Array,
             centre: tuple[float, float], stroke: tuple[float, float], brush: CombBrush,
             eye: Array, right: Array, up: Array) -> tuple[Array, Array]:
    """One dab over candidate vertices (their current directions, posed positions, normals and
    screen pixels, (K, ·)): which rows it changes and their new unit directions."""
    weight = dab_weights(pixels, centre, brush)
    near = np.flatnonzero(weight > 0.0)
    target, ok = stroke_directions(positions[near], normals[near], eye, right, up, stroke)
    rows = near[ok]
    return rows, blend_directions(directions[rows], target[ok], weight[rows]).astype(np.float32)


def typical_length(motion: Array, scale: float) -> float:
    """The authored length a combed vertex gets where its pose does not move it: the median
    motion of the vertices that move (so the scale-free visibility stays in the range of the
    rest of the area), else the face's size."""
    moving = motion[motion > STILL_EPSILON * scale]
    return float(np.median(moving)) if len(moving) else float(scale)


def combed_lengths(lengths: Array, motion: Array, fallback: float, still: float) -> Array:
    """Authored lengths for combed vertices: what they had, else their pose's motion, else (the
    pose moves them less than ``still``) ``fallback`` — a combed vertex is authored (length >
    0), as Create's are, and a tiny length would make the scale-free visibility jump to 1."""
    lengths = np.asarray(lengths, np.float32)
    motion = np.asarray(motion, np.float32)
    fresh = np.where(motion > still, motion, np.float32(fallback))
    return np.where(lengths > 0.0, lengths, fresh).astype(np.float32)
