"""Key-pose names as rigs spell them: ARKit's 52 blend shapes in every common spelling, sides,
and left/right pairs.

Rigs from capture tools, DCCs and engines name the same shapes differently: ``eyeBlinkLeft``
(Apple), ``EyeBlinkLeft`` (Live Link Face CSV), ``eyeBlink_L`` (many rigs), ``eye_blink_left``,
``blendShape1.eyeBlink_L`` (a Maya blend-shape node), ``A01_Brow_Inner_Up``… The studio never
renames a user's pose; these functions only *recognise* names — to pair a left pose with its
right one (mirroring a mask), to say where on the face a pose acts, and to match capture
columns to poses.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

# Apple ARKit, ARFaceAnchor.BlendShapeLocation: 52 shapes
ARKIT_NAMES = (
    "eyeBlinkLeft", "eyeLookDownLeft", "eyeLookInLeft", "eyeLookOutLeft", "eyeLookUpLeft",
    "eyeSquintLeft", "eyeWideLeft", "eyeBlinkRight", "eyeLookDownRight", "eyeLookInRight",
    "eyeLookOutRight", "eyeLookUpRight", "eyeSquintRight", "eyeWideRight",
    "jawForward", "jawLeft", "jawRight", "jawOpen",
    "mouthClose", "mouthFunnel", "mouthPucker", "mouthLeft", "mouthRight", "mouthSmileLeft",
    "mouthSmileRight", "mouthFrownLeft", "mouthFrownRight", "mouthDimpleLeft",
    "mouthDimpleRight", "mouthStretchLeft", "mouthStretchRight", "mouthRollLower",
    "mouthRollUpper", "mouthShrugLower", "mouthShrugUpper", "mouthPressLeft", "mouthPressRight",
    "mouthLowerDownLeft", "mouthLowerDownRight", "mouthUpperUpLeft", "mouthUpperUpRight",
    "browDownLeft", "browDownRight", "browInnerUp", "browOuterUpLeft", "browOuterUpRight",
    "cheekPuff", "cheekSquintLeft", "cheekSquintRight",
    "noseSneerLeft", "noseSneerRight",
    "tongueOut",
)
_BY_KEY = {name.lower(): name for name in ARKIT_NAMES}
# jawLeft / mouthRight move toward a side; they are not one side's version of a shape
_DIRECTIONAL = {"jawleft", "jawright", "mouthleft", "mouthright"}

# a namespace or node prefix ("blendShape1.", "Face:", "ARKit_", "A01_", "bs_")
_PREFIX = re.compile(r"^(?:.*[.:|])?(?:arkit[_\-]?|bs[_\-]|a\d{2}[_\-]|\d+[_\-])?",
                     re.IGNORECASE)
# a side written at the end: "Left", "_L", ".L", "_left", "L" after a lower-case letter …
_SIDE_END = re.compile(r"(?P<sep>[_.\-\s]?)(?P<side>left|right|l|r)$", re.IGNORECASE)
# … or at the start: "L_", "Left_", "left-"
_SIDE_START = re.compile(r"^(?P<side>left|right|l|r)(?P<sep>[_.\-\s])", re.IGNORECASE)
REGIONS = ("brow", "eye", "cheek", "nose", "mouth", "jaw", "tongue")


def _squash(text: str) -> str:
    return re.sub(r"[_.\-\s]", "", text).lower()


def _split_side(name: str) -> tuple[str, str | None]:
    """(the name without its side marker, "left" | "right" | None)."""
    raw = name.strip()
    base = _PREFIX.sub("", raw)
    if len(_squash(base)) <= 2:  # "noseSneer.L": the ".L" is a side, not a namespace's end
        base = raw
    if _squash(base) in _DIRECTIONAL:
        return base, None
    match = _SIDE_END.search(base)
    if match:
        side, sep = match["side"], match["sep"]
        before = base[:match.start()]
        # a bare "l"/"r" counts only as a marker after a separator or a lower-case letter
        # ("eyeBlinkL"), never inside a word ("mouthFunnel")
        marker = len(side) > 1 or sep or (before and before[-1].islower() and side.isupper())
        if marker and before:
            return before, "left" if side.lower().startswith("l") else "right"
    match = _SIDE_START.match(base)
    if match and len(base) > match.end():
        return base[match.end():], "left" if match["side"].lower().startswith("l") else "right"
    return base, None


def canonical(name: str) -> str | None:
    """The ARKit name a pose name spells (``"eyeBlink_L"`` → ``"eyeBlinkLeft"``), or None."""
    base, side = _split_side(name)
    key = _squash(base)
    if side is None:
        return _BY_KEY.get(key) or _BY_KEY.get(_squash(_PREFIX.sub("", name)))
    return _BY_KEY.get(key + side)


def side(name: str) -> str | None:
    """"left" or "right" (the character's own) when the name says so, else None."""
    known = canonical(name)
    if known is not None and known.lower() not in _DIRECTIONAL:
        if known.endswith("Left"):
            return "left"
        if known.endswith("Right"):
            return "right"
        return None
    return _split_side(name)[1]


_SWAPS = (("Left", "Right"), ("left", "right"), ("LEFT", "RIGHT"), ("L", "R"), ("l", "r"))


def swapped_sides(name: str) -> list[str]:
    """The name with its side marker swapped, in its own spelling (``browDown_L`` →
    ``browDown_R``, ``mouthSmileLeft`` → ``mouthSmileRight``, ``L_eye`` → ``R_eye``): every
    reading, most likely first; empty when the name has no side."""
    if side(name) is None:
        return []
    out = []
    for a, b in _SWAPS:
        for old, new in ((a, b), (b, a)):
            for pattern in (rf"(?<=[_.\-\s]){old}$", rf"(?<=[a-z]){old}$", rf"^{old}(?=[_.\-\s])"):
                candidate = re.sub(pattern, new, name)
                if candidate != name and candidate not in out:
                    out.append(candidate)
    return out


def mirror_name(name: str, available: Iterable[str]) -> str | None:
    """The other side's pose among ``available``, in the user's own spelling
    (``browDown_L`` → ``browDown_R``, ``mouthSmileLeft`` → ``mouthSmileRight``), or None."""
    names = list(available)
    candidates = swapped_sides(name)
    if not candidates:
        return None
    found = next((c for c in candidates if c in names), None)
    if found is not None:
        return found
    known = canonical(name)
    if known is not None:  # another spelling of the paired ARKit shape
        other = known[:-4] + "Right" if known.endswith("Left") else known[:-5] + "Left"
        return next((n for n in names if canonical(n) == other), None)
    return None


def pair_poses(names: Iterable[str]) -> list[tuple[str, str]]:
    """(left, right) pairs among the names, each pose in at most one pair."""
    names = list(names)
    pairs, used = [], set()
    for name in names:
        if name in used or side(name) != "left":
            continue
        other = mirror_name(name, names)
        if other is not None and other not in used and side(other) == "right":
            pairs.append((name, other))
            used.update((name, other))
    return pairs


def region_hint(name: str) -> str | None:
    """Which part of the face a pose acts on (brow, eye, cheek, nose, mouth, jaw, tongue),
    from its ARKit name or a recognisable word in it; None when the name does not say."""
    known = canonical(name)
    key = (known or name).lower()
    for region in REGIONS:
        if key.startswith(region) or (known is None and region in key):
            return region
    return None
