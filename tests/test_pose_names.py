"""Pose names as rigs spell them: ARKit's 52 in every common spelling, sides and pairs."""

from __future__ import annotations

import pytest

from studio.core.animation.pose_names import (
    ARKIT_NAMES,
    canonical,
    mirror_name,
    pair_poses,
    region_hint,
    side,
    swapped_sides,
)

pytestmark = pytest.mark.core

SPELLINGS = [  # (as a rig or a capture file writes it, ARKit name, side)
    ("eyeBlinkLeft", "eyeBlinkLeft", "left"),
    ("EyeBlinkLeft", "eyeBlinkLeft", "left"),  # Live Link Face CSV
    ("eyeBlink_L", "eyeBlinkLeft", "left"),
    ("eyeBlink_Left", "eyeBlinkLeft", "left"),
    ("eye_blink_left", "eyeBlinkLeft", "left"),
    ("EYEBLINK_L", "eyeBlinkLeft", "left"),
    ("eyeBlinkL", "eyeBlinkLeft", "left"),
    ("blendShape1.eyeBlink_L", "eyeBlinkLeft", "left"),  # a Maya blend-shape node
    ("ARKit_eyeBlink_L", "eyeBlinkLeft", "left"),
    ("L_eyeSquint", "eyeSquintLeft", "left"),
    ("noseSneer.R", "noseSneerRight", "right"),
    ("mouth_smile_R", "mouthSmileRight", "right"),
    ("MouthSmileRight", "mouthSmileRight", "right"),
    ("A01_Brow_Inner_Up", "browInnerUp", None),
    ("Face:jawOpen", "jawOpen", None),
    ("mouthFunnel", "mouthFunnel", None),  # ends in "l", has no side
    ("JawLeft", "jawLeft", None),  # moves the jaw to the left: a shape of its own, no side
    ("mouthRight", "mouthRight", None),
    ("tongueOut", "tongueOut", None),
]


@pytest.mark.parametrize(("name", "arkit", "which"), SPELLINGS)
def test_spellings_are_recognised(name, arkit, which):
    assert canonical(name) == arkit
    assert side(name) == which


def test_all_52_names_are_known_and_map_to_themselves():
    assert len(ARKIT_NAMES) == len(set(ARKIT_NAMES)) == 52
    assert all(canonical(n) == n for n in ARKIT_NAMES)
    pairs = pair_poses(ARKIT_NAMES)
    assert len(pairs) == 18  # 7 eye, 7 mouth, 2 brow, 1 cheek and 1 nose shape per side
    assert ("browDownLeft", "browDownRight") in pairs
    assert ("jawLeft", "jawRight") not in pairs


def test_other_names_keep_their_sides_and_spelling():
    assert canonical("brow_raise_left") is None and side("brow_raise_left") == "left"
    assert side("surprise") is None and swapped_sides("surprise") == []
    names = ["browDown_L", "browDown_R", "mouthSmileLeft", "mouthSmileRight",
             "brow_raise_left", "brow_raise_right", "EyeWideLeft", "eye_wide_right"]
    assert mirror_name("browDown_L", names) == "browDown_R"
    assert mirror_name("mouthSmileRight", names) == "mouthSmileLeft"
    assert mirror_name("brow_raise_left", names) == "brow_raise_right"
    assert mirror_name("EyeWideLeft", names) == "eye_wide_right"  # two spellings, one shape
    assert mirror_name("browDown_L", ["browDown_L"]) is None
    assert swapped_sides("L_eye") == ["R_eye"]


def test_regions():
    assert [region_hint(n) for n in ("browInnerUp", "eyeSquint_L", "cheekPuff", "noseSneer_L",
                                     "mouthSmile_R", "jawOpen", "tongueOut", "surprise")] == [
        "brow", "eye", "cheek", "nose", "mouth", "jaw", "tongue", None]
