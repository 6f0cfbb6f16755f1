"""Mirror partners of poses named in another spelling than their partner's.

A head from one tool may name its left smile ``MouthSmileLeft`` while a pose added later is
``mouthSmile_R``: mirroring a mask or a WDV area must still find the partner, in the name the
head actually uses, in both directions; each pose pairs once; a one-sided pose pairs with
nothing.
"""

from __future__ import annotations

import pytest

from studio.core.animation.pose_names import mirror_name, pair_poses, region_hint

pytestmark = pytest.mark.core


@pytest.mark.parametrize(
    ("name", "available", "partner"),
    [
        ("mouthSmile_R", ["jawOpen", "MouthSmileLeft"], "MouthSmileLeft"),
        ("MouthSmileLeft", ["mouth_smile_right", "jawOpen"], "mouth_smile_right"),
        ("browDown_L", ["browDown_R", "browDownRight"], "browDown_R"),  # own spelling first
        ("eyeBlinkLeft", ["eye_blink_right"], "eye_blink_right"),
        ("eyeBlink_L", ["jawOpen"], None),
        ("jawOpen", ["jawOpen"], None),
    ],
)
def test_the_partner_is_found_in_the_spelling_the_head_uses(name, available, partner) -> None:
    assert mirror_name(name, available) == partner


def test_each_pose_pairs_once_and_one_sided_poses_pair_with_nothing() -> None:
    names = ["mouthSmileLeft", "mouthSmile_L", "mouthSmileRight", "eyeBlink_L", "jawOpen"]
    assert pair_poses(names) == [("mouthSmileLeft", "mouthSmileRight")]
    assert pair_poses(["eyeBlink_L"]) == []
    assert pair_poses(["browDown_R", "browDown_L"]) == [("browDown_L", "browDown_R")]


@pytest.mark.parametrize(
    ("name", "region"),
    [
        ("A01_Brow_Inner_Up", "brow"),
        ("frown_brow", "brow"),
        ("squint_eyes", "eye"),
        ("tongueOut", "tongue"),
        ("CTRL_puff", None),
    ],
)
def test_the_region_comes_from_the_ARKit_name_or_a_word_in_it(name, region) -> None:
    assert region_hint(name) == region
