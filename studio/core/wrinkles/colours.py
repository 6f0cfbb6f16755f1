"""Colours for new areas that a person can tell apart from the ones already there.

Why: areas are told apart by colour (their rows, their vectors, their masks on the canvas). A
fixed palette taken in order gives a new area a colour next to one an automatic set-up already
used (the sample's 17 areas cover the hue circle), and a vector area drawn in the selection's
own colour hides which dots are selected. A new area takes, of 36 hues at two brightnesses, the
one farthest from every colour in use and from the selection's.
"""

from __future__ import annotations

import colorsys
from collections.abc import Iterable

import numpy as np

Colour = tuple[int, int, int]

SELECTION: Colour = (255, 140, 0)  # selected vertices, as Blender draws them: orange


def _candidates() -> np.ndarray:
    rows = [colorsys.hsv_to_rgb(h / 36.0, s, v) for v, s in ((0.95, 0.75), (0.75, 0.9))
            for h in range(36)]
    return np.rint(np.asarray(rows) * 255.0)


_CANDIDATES = _candidates()


def colour_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The "redmean" distance between RGB colours (0–255): closer to what the eye sees than
    plain RGB distance, for the price of a weighted one. Broadcasts over leading axes."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    r = (a[..., 0] + b[..., 0]) / 2.0
    d = a - b
    return np.sqrt((2 + r / 256) * d[..., 0] ** 2 + 4 * d[..., 1] ** 2
                   + (2 + (255 - r) / 256) * d[..., 2] ** 2)


def distinct_colour(existing: Iterable[Iterable[int]], avoid: Iterable[Colour] = (SELECTION,)
                    ) -> Colour:
    """The candidate colour farthest from every colour in ``existing`` and ``avoid``."""
    taken = np.asarray([tuple(c)[:3] for c in (*existing, *avoid)], float).reshape(-1, 3)
    if not len(taken):
        return tuple(int(v) for v in _CANDIDATES[0])  # type: ignore[return-value]
    nearest = colour_distance(_CANDIDATES[:, None, :], taken[None, :, :]).min(axis=1)
    best = _CANDIDATES[int(np.argmax(nearest))]
    return int(best[0]), int(best[1]), int(best[2])
