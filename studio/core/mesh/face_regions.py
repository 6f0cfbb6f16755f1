"""Names for places on a face, so a report can say *where* a pose compresses the skin.

Places are given in normalised face coordinates: x toward the character's own left, y up, the
face's box spanning about −1 … 1 both ways (forehead at the top, chin at the bottom). The
anchors follow average human proportions; the name of a point is its nearest anchor's. "Left"
and "right" are the character's own, as in ARKit's and most rigs' pose names.
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray

_SIDED = {  # name: (|x|, y) on the character's left; mirrored for the right
    # placed where the ICT-FaceKit scan's landmarks fall in its face box (which ends at the
    # chin): brows, lids, eye corner, mouth corner and lips
    "brow": (0.5, 0.5),
    "upper eyelid": (0.47, 0.32),  # a blink, a wide eye, the eyes looking about
    "eye corner": (0.68, 0.26),
    "lower eyelid": (0.45, 0.15),
    # the nasal side, beside the bridge and the wing: where a sneer (noseSneer) bunches the
    # skin; without it that compression was named after the lower eyelid
    "side of the nose": (0.2, -0.05),
    "cheek": (0.62, -0.3),
    "nasolabial fold": (0.36, -0.27),  # from the nose's wing to beside the mouth's corner
    "mouth corner": (0.38, -0.47),  # a frown, a dimple, a press, a stretch
    "jaw": (0.75, -0.75),
}
_CENTRAL = {
    "forehead": (0.0, 0.72),
    "between the brows": (0.0, 0.4),
    "nose": (0.0, -0.1),
    "upper lip": (0.0, -0.3),
    "chin": (0.0, -0.85),
    "lower lip": (0.0, -0.52),
}


def _anchors() -> tuple[list[str], Array]:
    names, points = list(_CENTRAL), list(_CENTRAL.values())
    for name, (x, y) in _SIDED.items():
        names += [f"left {name}", f"right {name}"]
        points += [(x, y), (-x, y)]
    return names, np.asarray(points, np.float64)


_NAMES, _POINTS = _anchors()


def region_name(x: float, y: float) -> str:
    """The named region nearest to a point in normalised face coordinates."""
    d = np.hypot(_POINTS[:, 0] - x, _POINTS[:, 1] - y)
    return _NAMES[int(np.argmin(d))]


def region_names() -> list[str]:
    return list(_NAMES)
