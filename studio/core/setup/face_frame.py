"""Where the face is, and which way is up and front — for a head made anywhere.

Heads arrive in any units, anywhere in space, Y-up (glTF, Maya) or Z-up (Blender, 3ds Max),
with a neck, shoulders, eyes and teeth. The camera, the default framing and the report's region
names need the face's own frame, found here from the geometry and the key poses:

- **The face region** is the skin the key poses *deform* (edge lengths change), not merely move:
  a neck carried along by a jaw opening is translated, not deformed, and stays out.
- **Up**: given (``--up``), else from poses whose names say which way they move the skin
  (``browInnerUp`` up, ``jawOpen`` down, …: their mean motion, snapped to an axis when within
  30°), else the longer of the Y and Z extents (the two conventions in use); corrected across
  the way the face looks by its left–right symmetry; and, last, confirmed or overruled by
  the eyes above the nose tip (``face_features``: anatomy, which neither names, extents nor
  windings can mislead; not claimed where unclear).
- **Front**: the way the face region's surface faces (area-weighted normals, left and right
  cancel), checked against where the face region sits on the head (a face is at its front; a
  file whose normals point inward is caught there); without poses, the convention of the up
  axis; either confirmed or overruled by the nose tip ahead of the eyes.

The notes (``how``) say what decided each axis, and when the eyes and nose agreed.
- **Left** = up × front: the character's own left (+X for the bundled sample).

Every threshold is relative to the face's own size or motion, never in model units.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from studio.core.animation.pose_names import canonical
from studio.core.files.errors import StudioError
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.face_regions import region_name
from studio.core.setup.face_features import (
    FaceFeatures,
    asymmetry,
    find_face_features,
    unique_edges,
)
from studio.core.setup.stage_clock import stage

Array = np.ndarray

AXES = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0),
        "+z": (0, 0, 1), "-z": (0, 0, -1)}
SNAP_DEGREES = 30.0  # a detected direction this close to an axis is taken as that axis
DEFORMED_SHARE = 0.1  # a vertex deformed by a tenth of the strong deformation is face
MARGIN = 1.12  # the face box, a little larger than the deformed skin
BODY_HEIGHTS = 4.0  # skin this many face boxes tall is a body, not a head and neck …
HEAD_REACH = (1.8, (-1.5, 1.8), 2.6)  # … whose skin past these (face |x|, y, |z|) is not face
UPPER_SKIN = "no key pose deforms the skin: the face is taken to be the upper skin"
# the sample's face box from the eyes' middle (centre offset) and its half-extents, in the
# distance between the eyes, along (left, up, front): measured on the production test head at
# 900, 2172 and 5000 vertices (the centre 0.15-0.17 below the eyes and 0.85 behind, the
# halves 1.28-1.31, 1.39-1.42, 1.47)
EYES_BOX = ((0.0, -0.17, -0.85), (1.3, 1.4, 1.47))
MANY_POSES = 10  # in a rig of this many poses or more, the face ends below where two of them …
SHARED_LEAST = 0.25  # … deform the skin, unless that is under a quarter of what any of them does

# Which way poses move the skin, by ARKit name, and by words other rigs use
_UPWARD = {"browInnerUp", "browOuterUpLeft", "browOuterUpRight", "eyeWideLeft", "eyeWideRight",
           "noseSneerLeft", "noseSneerRight", "mouthUpperUpLeft", "mouthUpperUpRight",
           "cheekSquintLeft", "cheekSquintRight", "mouthSmileLeft", "mouthSmileRight"}
_DOWNWARD = {"jawOpen", "browDownLeft", "browDownRight", "mouthLowerDownLeft",
             "mouthLowerDownRight", "mouthFrownLeft", "mouthFrownRight", "eyeBlinkLeft",
             "eyeBlinkRight"}
_UP_WORDS = ("browraise", "browsup", "browup", "surprise", "raise")
_DOWN_WORDS = ("frown", "browdown", "jawdown", "blink")


def parse_axis(text: str) -> Array:
    """``y``, ``+z``, ``-Y``, … as a unit vector; StudioError for anything else."""
    key = str(text).strip().lower()
    key = key if key[:1] in "+-" else f"+{key}"
    if key not in AXES:
        raise StudioError(f"'{text}' is not an axis (use x, y, z, -x, -y or -z)")
    return np.array(AXES[key], np.float64)


def axis_name(vector: Array) -> str:
    """"+Z" for (0, 0, 1); the vector itself, rounded, when it is not along an axis."""
    v = np.asarray(vector, float)
    for name, axis in AXES.items():
        if np.allclose(v, axis, atol=1e-6):
            return name.upper()
    return "(" + ", ".join(f"{c:.2f}" for c in v) + ")"


def _snap(vector: Array, allowed: Iterable[str] = AXES) -> tuple[Array, bool]:
    """The nearest allowed axis if within ``SNAP_DEGREES``, else the unit vector itself."""
    v = np.asarray(vector, float)
    v = v / max(np.linalg.norm(v), 1e-300)
    allowed = list(allowed)
    if not allowed:
        return v, False
    best = max(allowed, key=lambda name: float(np.dot(v, AXES[name])))
    # "within" includes the boundary itself, which rounding may put a hair past
    if np.degrees(np.arccos(np.clip(np.dot(v, AXES[best]), -1, 1))) <= SNAP_DEGREES + 1e-9:
        return np.array(AXES[best], np.float64), True
    return v, False


def face_frame(project) -> FaceFrame:
    """A project's face frame (``project.view["up"]`` and ``["front"]`` are the axes chosen at
    import, if any). ``project`` is a ``studio.core.project.model.Project``."""
    with stage("orientation"):
        return detect_face_frame(project.mesh.rest, project.mesh.welded_triangles,
                                 [p.positions for p in project.poses],
                                 [p.name for p in project.poses], project.skin_weights(),
                                 project.view.get("up"), project.view.get("front"))


def beyond_the_head(frame: FaceFrame, rest: Array, skin: Array) -> Array | None:
    """(W,) bool: in a whole body, the skin beyond the head (shoulders, torso, limbs) — to be
    marked not face, so that what is measured as "the skin" (its size, its most forward point,
    the share a pose compresses) is the head's, not a body's ten times larger. None for a head
    (the skin is under ``BODY_HEIGHTS`` face boxes tall along up), when nothing lies beyond,
    or when no key pose showed where the face is (the box is a guess then).
    ``skin``: (W,) weights, 0 for parts already not face."""
    skin = np.asarray(skin) > 0
    if not skin.any() or not frame.posed:
        return None
    local = frame.to_face(rest)
    if np.ptp(local[skin, 1]) < 2.0 * BODY_HEIGHTS:  # the face box spans 2 in face y
        return None
    reach_x, (low, high), reach_z = HEAD_REACH
    beyond = skin & ((np.abs(local[:, 0]) > reach_x) | (local[:, 1] < low) | (local[:, 1] > high)
                     | (np.abs(local[:, 2]) > reach_z))
    return beyond if beyond.any() and not beyond[skin].all() else None


def face_locator(frame: FaceFrame):
    """A function naming the face region nearest to a model-space point (for reports)."""
    def locate(point: Array) -> str:
        x, y, _ = frame.to_face(np.asarray(point, np.float64)[None])[0]
        return region_name(float(x), float(y))

    return locate


def _pose_direction(name: str, words: bool) -> int:
    """+1 for a pose that moves skin up, −1 down, 0 when its name does not say: by its ARKit
    name, or (``words``) by a word such as "raise" or "frown" in it."""
    known = canonical(name)
    if known is not None:
        return 1 if known in _UPWARD else -1 if known in _DOWNWARD else 0
    if not words:
        return 0
    key = re.sub(r"[\s_.\-]", "", name.lower())
    if any(word in key for word in _DOWN_WORDS):
        return -1
    return 1 if any(word in key for word in _UP_WORDS) else 0


@dataclass(frozen=True)
class FaceFrame:
    """The face's axes (unit vectors in model space), the centre and half-size of its box
    along them, and what was assumed to find them."""

    left: tuple[float, float, float]
    up: tuple[float, float, float]
    front: tuple[float, float, float]
    centre: tuple[float, float, float]
    half: tuple[float, float, float]  # half-extents along left, up, front
    how: str
    mirror_axis: int = 0  # the model axis (0, 1, 2) that runs from the face's right to its left
    mirror_plane: float = 0.0  # … and where along it the left–right symmetry plane lies
    posed: bool = False  # the box is the skin the key poses deform (not a guess)

    def basis(self) -> Array:
        """3×3 whose columns are left, up, front: face coordinates → model directions."""
        return np.column_stack([self.left, self.up, self.front]).astype(np.float64)

    def to_face(self, points: Array) -> Array:
        """(N, 3) points in normalised face coordinates: x toward the character's left, y up,
        z toward the front, the face box spanning −1 … 1."""
        local = (np.asarray(points, np.float64) - self.centre) @ self.basis()
        return local / np.asarray(self.half)

    def corners(self) -> Array:
        """The face box's 8 corners in model space, for framing it."""
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
                         np.float64)
        return np.asarray(self.centre) + (signs * self.half) @ self.basis().T

    def to_dict(self) -> dict:
        return {"left": list(self.left), "up": list(self.up), "front": list(self.front),
                "centre": list(self.centre), "half": list(self.half), "how": self.how,
                "mirror_axis": self.mirror_axis, "mirror_plane": self.mirror_plane}


def _deformations(rest: Array, poses: Sequence[Array], edges: Array) -> Array:
    """(P, W): per pose and vertex, the largest relative change of its edges' lengths."""
    a, b = edges[:, 0], edges[:, 1]
    rest_len = np.linalg.norm(rest[a] - rest[b], axis=1)
    ok = rest_len > 0
    out = np.zeros((len(poses), len(rest)), np.float64)
    for row, positions in zip(out, poses, strict=True):
        length = np.linalg.norm(positions[a] - positions[b], axis=1)
        change = np.where(ok, np.abs(length / np.where(ok, rest_len, 1.0) - 1.0), 0.0)
        np.maximum.at(row, a, change)
        np.maximum.at(row, b, change)
    return out


def _deformation(rest: Array, poses: Sequence[Array], edges: Array) -> Array:
    """(W,) per vertex, the largest relative change of its edges' lengths over the poses."""
    if not len(poses):
        return np.zeros(len(rest), np.float64)
    return _deformations(rest, poses, edges).max(axis=0)


def _face_region(per_pose: Array, skin: Array) -> tuple[Array, Array | None]:
    """(W,) bool: the skin the poses deform — by a tenth of the strong deformation
    (``DEFORMED_SHARE``); and, with ``MANY_POSES`` or more, the skin at least two of them
    deform, which bounds a rig's face from below: the neck under the chin is pulled by a jaw
    opening alone (the forehead up to the hairline may be raised by one brow pose alone, so
    the top keeps the first). None for the second when the poses hardly overlap."""
    deformed = per_pose * skin
    largest = deformed.max(axis=0)
    none = np.zeros(per_pose.shape[1], bool)
    if not (largest > 0).any():
        return none, None
    strong = float(np.percentile(largest[largest > 0], 95))
    if strong <= 1e-6:
        return none, None
    votes = (deformed > DEFORMED_SHARE * strong).sum(axis=0)
    face = votes >= 1
    shared = votes >= 2
    if len(per_pose) < MANY_POSES or shared.sum() < SHARED_LEAST * face.sum():
        return face, None
    return face, shared


def detect_face_frame(rest: Array, triangles: Array, poses: Sequence[Array] = (),
                      pose_names: Sequence[str] = (), skin: Array | None = None,
                      up: str | None = None, front: str | None = None) -> FaceFrame:
    """The face's frame from the neutral positions (W, 3), welded triangles, the key poses'
    positions and names, the skin flags (not-face vertices excluded) and optional up and
    front axes (``--up``, ``--front``, or a VRM's own)."""
    rest = np.asarray(rest, np.float64)
    triangles = np.asarray(triangles)
    skin = np.ones(len(rest), bool) if skin is None else np.asarray(skin) > 0
    poses = [np.asarray(p, np.float64) for p in poses]
    notes: list[str] = []
    skin_points = rest[skin] if skin.any() else rest
    size = float(np.linalg.norm(np.ptp(skin_points, axis=0))) or 1.0

    # the face region: skin the poses deform
    face = np.zeros(len(rest), bool)
    chin_region = None
    if poses:
        edges = unique_edges(triangles)[0]
        face, chin_region = _face_region(_deformations(rest, poses, edges), skin)

    # the eyes and the nose tip: anatomy, which no name, extent or winding can mislead
    features = None
    if up is None or front is None:
        features = _features(rest, triangles, skin, face)

    # up
    if up is not None:
        up_vec = parse_axis(up)
        notes.append(f"up {axis_name(up_vec)} (as given)")
    else:
        up_vec, reason, sure = _weigh_up(rest, triangles, poses, pose_names, skin, size, face,
                                         features)
        notes += [f"up {axis_name(up_vec)} ({reason})", sure]

    # front
    given_front = None if front is None else parse_axis(front)
    if given_front is not None and abs(float(np.dot(given_front, up_vec))) > 1e-6:
        if up is not None:
            raise StudioError(f"the front {axis_name(given_front)} is not at right angles to "
                              f"the up {axis_name(up_vec)}")
        up_vec = np.array(AXES["+z"] if abs(given_front[1]) > 0.5 else AXES["+y"], float)
        notes[-2:] = [f"up {axis_name(up_vec)} (at right angles to the front given)"]
    if given_front is not None:
        front_vec, reason = given_front, "as given"
        region = face if face.sum() >= 3 else _front_guess(rest, skin, up_vec)
    elif face.sum() >= 3:
        region = face
        front_vec, reason = _front(rest, triangles, region, skin, up_vec)
    else:  # nothing shows where the face is: the convention that goes with the up axis
        region = _front_guess(rest, skin, up_vec)
        front_vec, reason = _conventional_front(up_vec)
        notes.append(UPPER_SKIN)
    # the nose ahead of the eyes only counts where the eyes above the nose gave this up:
    # eyes found upside down put the nose behind them too
    if (given_front is None and features is not None and np.allclose(features.up, up_vec)
            and abs(float(np.dot(features.front, up_vec))) < 1e-9):
        if np.allclose(features.front, front_vec):
            reason += "; the nose ahead of the eyes agrees"
        else:
            front_vec, reason = features.front, "the nose ahead of the eyes"
    notes.append(f"front {axis_name(front_vec)} ({reason})")
    left_vec = np.cross(up_vec, front_vec)
    left_vec /= np.linalg.norm(left_vec)

    basis = np.column_stack([left_vec, up_vec, front_vec])
    local = rest[region] @ basis
    lo, hi = np.percentile(local, 1, axis=0), np.percentile(local, 99, axis=0)
    if chin_region is not None and chin_region.sum() >= 3:  # the chin, not the neck below it
        lo[1] = np.percentile(rest[chin_region] @ up_vec, 1)
    centre_local = (lo + hi) / 2.0
    half = np.maximum((hi - lo) / 2.0 * MARGIN, 1e-3 * size)
    if (face.sum() < 3 and features is not None and np.allclose(features.up, up_vec)
            and np.allclose(features.front, front_vec)):
        # no pose shows the face, but its eyes and nose do: boxed as the sample's face is
        centre_local, half = _box_from_eyes(features, basis)
        notes[notes.index(UPPER_SKIN)] = ("no key pose deforms the skin: the face is boxed "
                                         "around its eyes and nose")
    centre = basis @ centre_local
    def floats(v: Array) -> tuple[float, float, float]:
        return tuple(float(x) for x in v)  # type: ignore[return-value]

    # the left-right symmetry plane, for mirroring masks and selections: across the model
    # axis nearest to "left", through the middle of the skin (a head is symmetric)
    mirror_axis = int(np.argmax(np.abs(left_vec)))
    mirror_plane = float(np.mean(skin_points[:, mirror_axis]))
    return FaceFrame(floats(left_vec), floats(up_vec), floats(front_vec), floats(centre),
                     floats(half), "; ".join(notes), mirror_axis, mirror_plane,
                     bool(face.sum() >= 3))


@dataclass(frozen=True)
class _UpEvidence:
    """One way of telling up: the axis it gives, in words, and how sure it is (0 … 1)."""

    up: Array
    words: str
    sure: float
    detail: str = ""  # what the sureness rests on, for the report


# how sure each kind of evidence is at best: eye parts and eye openings are hard to mistake;
# pits in a closed skin may be a mouth's corners or a nostril's hollows; extents are a guess
ANATOMY_SURE = {"eye parts": 0.9, "eye holes in the skin": 0.75, "eye sockets": 0.4}
EXTENTS_SURE = 0.1
FACING_SURE = 0.6  # the way a flat face looks and its symmetry (up's sign is a guess)


def _sure_words(sure: float) -> str:
    """How sure, in words and as a number: "sure, 0.86"."""
    word = "sure" if sure >= 0.75 else "fairly sure" if sure >= 0.5 else "unsure"
    return f"{word}, {sure:.2f}"


def _weigh_up(rest: Array, triangles: Array, poses: Sequence[Array], names: Sequence[str],
              skin: Array, size: float, face: Array, features: FaceFeatures | None
              ) -> tuple[Array, str, str]:
    """Up, the words saying what decided it, and a note saying how sure and what else said
    so. The poses' motion (or, without it, the longer extent) is corrected across the way the
    face looks; the eyes above the nose confirm it, or overrule it only when they are the
    surer evidence: pits taken for eye sockets on a mask without eyes may be its mouth
    corners, and never turn over a face whose brows rise and whose jaw opens the other way."""
    found = _up_from_poses(rest, poses, names, skin, size)
    if found is None:
        ext = np.ptp(rest[skin] if skin.any() else rest, axis=0)
        longer = AXES["+z"] if ext[2] > ext[1] * 1.001 else AXES["+y"]
        found = _UpEvidence(np.array(longer, float), "the longer of the Y and Z extents; give "
                            "--up to choose", EXTENTS_SURE)
    if face.sum() >= 3:
        across = _up_across_facing(rest, triangles, face, skin, found.up)
        # the face cannot look along its own up: corrected where the way it looks is surer
        # than what said up (a jaw opening's chin looks down as much as ahead: not surer)
        if across is not None and FACING_SURE * across[2] > found.sure:
            found = _UpEvidence(across[0], across[1], FACING_SURE * across[2])
    details = [found.detail] if found.detail else []
    winner = found
    if features is not None:
        eyes = _UpEvidence(features.up, f"the eyes above the nose ({features.eyes_from})",
                           ANATOMY_SURE.get(features.eyes_from, ANATOMY_SURE["eye sockets"]))
        if np.allclose(eyes.up, found.up):
            # two independent signs agreeing: surer than either
            winner = _UpEvidence(found.up, found.words,
                                 1.0 - (1.0 - found.sure) * (1.0 - eyes.sure))
            details.append(f"{eyes.words} agree")
        else:
            winner, loser = (eyes, found) if eyes.sure > found.sure else (found, eyes)
            if winner is eyes:
                winner = _UpEvidence(eyes.up, eyes.words + "; give --up to choose", eyes.sure)
            verb = "say" if loser is eyes else "says"
            details.append(f"{loser.words.split(';')[0]} {verb} {axis_name(loser.up)}, less "
                           f"sure ({loser.sure:.2f}): overruled")
    shown = f" ({'; '.join(details)})" if details else ""
    return winner.up, winner.words, f"how sure of up: {_sure_words(winner.sure)}{shown}"


def _up_from_poses(rest: Array, poses: Sequence[Array], names: Sequence[str], skin: Array,
                   size: float) -> _UpEvidence | None:
    """Up from the poses whose names say which way they move the skin: each votes for the
    axes by its mean motion's direction along them (signed by up or down), and the axis with
    the most votes wins — a one-sided frown that mostly pulls sideways still says "down" a
    little, and a brow raise says "up" a lot. How sure: the poses' mean agreement with the
    axis (1 when every one moves straight along it), less for few poses (one pose may be
    misnamed: n / (n + 1))."""
    votes = np.zeros(len(AXES))
    axes = np.array(list(AXES.values()), np.float64)
    used = []
    directions = []
    # ARKit names are unambiguous: when a rig has them, only they vote
    words = not any(_pose_direction(name, False) for name in names)
    for name, positions in zip(names, poses, strict=False):
        sign = _pose_direction(name, words)
        if sign == 0:
            continue
        motion = (positions - rest)[skin]
        length = np.linalg.norm(motion, axis=1)
        if length.max(initial=0.0) < 1e-5 * size:
            continue
        mean = motion[length > 0.2 * length.max()].mean(axis=0)
        if np.linalg.norm(mean) > 0:
            directions.append(sign * mean / np.linalg.norm(mean))
            used.append(name)
    if directions:
        votes = axes @ np.sum(directions, axis=0)
    if not used or votes.max() < 0.5:
        return None
    best = int(np.argmax(votes))
    agreeing = sum(float(d @ axes[best]) > 0.5 for d in directions)
    sure = float(np.clip(votes[best] / len(used), 0.0, 1.0)) * len(used) / (len(used) + 1)
    shown = ", ".join(used[:3]) + (" …" if len(used) > 3 else "")
    return _UpEvidence(axes[best], f"from the motion of {shown}", sure,
                       f"{agreeing} of {len(used)} moving that way")


def _features(rest: Array, triangles: Array, skin: Array, face: Array) -> FaceFeatures | None:
    """The eyes and nose tip, looked for around the skin the poses deform (its size sets the
    scale: a body's nose is small beside the body), then over all the skin (a blink deforms
    too little of the face to show its size). Over all the skin, eye sockets are not taken:
    hollows are everywhere on a body (between the legs, a pair beside a buttock's bump), and
    without poses nothing says where the face is; eye parts and eye openings are."""
    if face.sum() >= 3:
        found = find_face_features(rest, triangles, skin, face)
        if found is not None:
            return found
    return find_face_features(rest, triangles, skin, sockets=False)


def _up_across_facing(rest: Array, triangles: Array, face: Array, skin: Array, up: Array
                      ) -> tuple[Array, str, float] | None:
    """A better up when the one found is the way the face looks (a face's up is across its
    facing): a blink that moves the lid toward the camera, a ponytail longer than the head is
    tall. The face region's surface gives the facing (its area-weighted normals); of the two
    axes across it, the skin is mirror-symmetric across one (its left–right axis; the skin, as
    the region one pose moves may be one side of it): up is the other, positive. With how
    surely the region looks one way (``sure``: the normals' sum over the sum of their lengths).
    None when the up found is across the facing already."""
    tri = triangles[face[triangles].all(axis=1)]
    if not len(tri):
        return None
    p = rest[tri]
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    facing = normals.sum(axis=0)
    if np.linalg.norm(facing) == 0:
        return None
    # how surely the region looks one way: 1 for a flat lid, less for skin wrapping round
    # a chin (whose underside looks down as much as its front looks ahead)
    sure = float(np.linalg.norm(facing) / np.linalg.norm(normals, axis=1).sum())
    facing, snapped = _snap(facing)
    if not snapped or abs(float(np.dot(facing, up))) < 0.5:
        return None
    across = [np.array(a, np.float64) for a in ((1, 0, 0), (0, 1, 0), (0, 0, 1))
              if abs(np.dot(a, facing)) < 1e-9]
    points = rest[skin] if skin.any() else rest
    left = min(across, key=lambda axis: asymmetry(points, axis))
    up_vec = next(a for a in across if a is not left)
    return up_vec, (f"across the way the face looks ({axis_name(facing)}) and its left–right "
                    "symmetry; give --up to choose"), sure


def _box_from_eyes(features: FaceFeatures, basis: Array) -> tuple[Array, Array]:
    """The face's box (centre and half-extents in face axes) from its eyes and nose, in the
    proportions of the sample's face, whose poses deform it from hairline to chin
    (``EYES_BOX``): a head without poses is framed on its face, not its crown."""
    eyes = np.asarray(features.eyes, np.float64)
    apart = float(np.linalg.norm(eyes[0] - eyes[1]))
    centre_offset, half = (np.asarray(v, np.float64) * apart for v in EYES_BOX)
    return eyes.mean(axis=0) @ basis + centre_offset, half


def _conventional_front(up: Array) -> tuple[Array, str]:
    """Y up → the face looks toward +Z (glTF, Maya); Z up → toward −Y (Blender)."""
    key = axis_name(up)
    fronts = {"+Y": "+z", "-Y": "-z", "+Z": "-y", "-Z": "+y", "+X": "+z", "-X": "+z"}
    if key in fronts:
        return np.array(AXES[fronts[key]], np.float64), "the usual convention with that up axis"
    other = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
    return other / np.linalg.norm(other), "nothing to go by; an arbitrary side"


def _front_guess(rest: Array, skin: Array, up: Array) -> Array:
    """Without deforming poses: the upper half of the skin, to frame (a face is not a neck)."""
    skin = skin if skin.any() else np.ones(len(rest), bool)  # none marked: all of it
    height = rest @ up
    return skin & (height >= np.percentile(height[skin], 50))


def _front(rest: Array, triangles: Array, region: Array, skin: Array, up: Array
           ) -> tuple[Array, str]:
    """The horizontal direction the region's surface faces, snapped to an axis when close."""
    tri = triangles[region[triangles].all(axis=1)]
    p = rest[tri]
    normal_sum = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]).sum(axis=0)
    horizontal = normal_sum - np.dot(normal_sum, up) * up
    head = rest[skin] if skin.any() else rest
    centre_offset = rest[region].mean(axis=0) - head.mean(axis=0)
    offset = centre_offset - np.dot(centre_offset, up) * up
    # the face sits off the head's centre by more than rounding (relative to the head's size)
    off_centre = np.linalg.norm(offset) > 1e-6 * np.ptp(head, axis=0).max()
    reason = "the way the face's surface faces"
    if np.linalg.norm(horizontal) <= 1e-9 * max(np.linalg.norm(normal_sum), 1e-300):
        horizontal, reason = offset, "where the face sits on the head"
    elif off_centre and np.dot(horizontal, offset) < -0.5 * np.linalg.norm(
            horizontal) * np.linalg.norm(offset):
        horizontal, reason = -horizontal, "the surface's normals point inward; taken reversed"
    if np.linalg.norm(horizontal) == 0:
        horizontal = np.cross(up, np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9
                              else np.array([0.0, 1.0, 0.0]))
        reason = "nothing to go by; an arbitrary side"
    allowed = [n for n, a in AXES.items() if abs(np.dot(a, up)) < 1e-9]
    vector, snapped = _snap(horizontal, allowed)
    if not snapped:
        vector = horizontal / np.linalg.norm(horizontal)
    return vector, reason


def aim(camera: OrbitCamera, project, frame: str = "face",
        face: FaceFrame | None = None) -> FaceFrame:
    """Turn the camera to the face's axes and frame the face or the whole mesh; returns the
    face frame it found (or was given)."""
    face = face or face_frame(project)
    camera.basis = face.basis()
    if frame == "face":
        camera.frame_points(face.corners())
        if project is not None:  # never inside the hair in front of the face
            camera.stand_clear_of(project.mesh.rest)
    else:
        camera.frame(*project.mesh.bounds())
    return face
