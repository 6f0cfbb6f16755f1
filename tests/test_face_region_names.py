"""Where a pose compresses the skin, in words: each anchor's own point is named after it, on
the character's own left and right, and the anchor table itself (built at import, so tested
through its builder as well) pairs every sided name with its mirror image.
"""

from __future__ import annotations

import pytest

from studio.core.mesh.face_regions import _anchors, region_name, region_names

pytestmark = pytest.mark.core


@pytest.mark.parametrize(
    ("x", "y", "name"),
    [
        (0.0, 0.75, "forehead"),
        (0.02, 0.36, "between the brows"),
        (0.47, 0.43, "left brow"),
        (-0.47, 0.43, "right brow"),
        (0.7, 0.2, "left eye corner"),
        (-0.74, 0.25, "right eye corner"),
        (0.6, -0.32, "left cheek"),
        (-0.35, -0.6, "right mouth corner"),
        (0.8, -0.8, "left jaw"),
        (0.0, -0.95, "chin"),
        (0.01, -0.12, "nose"),
        # the ICT head's noseSneer_L and _R compress here (face coordinates measured there)
        (0.26, -0.05, "left side of the nose"),
        (-0.33, -0.05, "right side of the nose"),
        # where the ICT head's poses compress (its face coordinates): a blink, a squint, a
        # smile, a frown, a pucker, a lower lip pulled down, an inner brow raise
        (0.45, 0.28, "left upper eyelid"),
        (0.47, 0.19, "left lower eyelid"),
        (-0.41, -0.30, "right nasolabial fold"),
        (0.34, -0.47, "left mouth corner"),
        (0.0, -0.34, "upper lip"),
        (0.13, -0.66, "lower lip"),
        (0.29, 0.73, "forehead"),
    ],
)
def test_a_point_is_named_after_its_nearest_anchor(x: float, y: float, name: str) -> None:
    assert region_name(x, y) == name


def test_every_sided_anchor_has_its_mirror_image() -> None:
    names, points = _anchors()
    assert names == region_names()
    assert len(names) == len(set(names)) == 6 + 2 * 9
    assert points.shape == (24, 2) and points.dtype.kind == "f"
    for i, name in enumerate(names):
        if name.startswith("left "):
            j = names.index("right " + name.removeprefix("left "))
            assert points[j].tolist() == [-points[i][0], points[i][1]]
            assert points[i][0] > 0
    assert names[:6] == ["forehead", "between the brows", "nose", "upper lip", "chin",
                         "lower lip"]
    assert points[:6, 0].tolist() == [0.0] * 6
