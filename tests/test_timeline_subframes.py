"""Timeline tracks between keys less than a frame apart, and tracks made on demand.

Capture takes resampled at another rate leave keys a fraction of a frame apart; the weight
between them must still be interpolated (not held), both by the vectorised ``values_at`` the
exporters use and by the per-frame ``value_at`` playback uses, and the two must agree.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.timeline import Key, Timeline, Track

pytestmark = pytest.mark.core


@pytest.mark.parametrize("gap", [0.25, 0.5, 1.0])
def test_keys_a_fraction_of_a_frame_apart_are_interpolated(gap: float) -> None:
    track = Track("jawOpen", [Key(10.0, 0.2, "linear"), Key(10.0 + gap, 0.6, "linear")])
    halfway = 10.0 + gap / 2
    assert track.value_at(halfway) == pytest.approx(0.4)
    assert track.values_at([10.0, halfway, 10.0 + gap]).tolist() == pytest.approx([0.2, 0.4, 0.6])


def test_both_evaluations_agree_before_between_and_after_the_keys() -> None:
    track = Track(
        "browInnerUp",
        [Key(2.0, 0.1, "smooth"), Key(2.5, 0.9, "cosine"), Key(4.0, 0.3, "linear")],
    )
    frames = np.array([0.0, 2.0, 2.1, 2.25, 2.5, 3.0, 3.9, 4.0, 7.5])
    assert track.values_at(frames) == pytest.approx([track.value_at(f) for f in frames])
    assert track.value_at(0.0) == 0.1 and track.value_at(7.5) == 0.3


def test_a_pose_without_a_track_gets_an_empty_one_kept_in_the_timeline() -> None:
    timeline = Timeline(tracks=[Track("smile", [Key(0.0, 1.0)])])
    made = timeline.track("blink")
    assert isinstance(made, Track) and made.pose == "blink" and made.keys == []
    assert timeline.tracks[-1] is made
    assert timeline.track("blink") is made and timeline.track("smile") is timeline.tracks[0]
    assert timeline.weights_at(0.0) == {"smile": 1.0}  # an empty track adds no weight
