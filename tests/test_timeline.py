"""Key-pose animation: weights at given frames for each interpolation mode, holds, the
"sequence all poses" set-up, and the saved form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.core.animation.timeline import INTERPOLATIONS, Key, Timeline, Track, sequence_all_poses

pytestmark = pytest.mark.core


def track(mode: str) -> Track:
    """0 at frame 10 rising to 1 at frame 20 (shaped by ``mode``), back to 0.5 at frame 30."""
    return Track("smile", [Key(10, 0.0, mode), Key(20, 1.0, mode), Key(30, 0.5, "linear")])


@pytest.mark.parametrize(("mode", "frame", "expected"), [
    ("linear", 12.5, 0.25),
    ("linear", 15.0, 0.5),
    ("cosine", 15.0, 0.5),  # Parke: C = (1 - cos(f·π)) / 2 at f = 1/2
    ("cosine", 12.5, (1 - math.cos(math.pi / 4)) / 2),
    ("cosine", 17.5, (1 - math.cos(3 * math.pi / 4)) / 2),
    ("smooth", 15.0, 0.5),
    ("smooth", 12.5, 0.25 * 0.25 * (3 - 0.5)),  # f²(3 − 2f) at f = 1/4 = 0.15625
    ("constant", 12.5, 0.0),
    ("constant", 19.99, 0.0),
    ("constant", 20.0, 1.0),
])
def test_weight_between_keys_for_each_interpolation(mode, frame, expected):
    """Both evaluations: one frame at a time (playback) and vectorised (export, curves)."""
    assert track(mode).value_at(frame) == pytest.approx(expected, abs=1e-9)
    assert track(mode).values_at([frame, frame])[1] == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize("mode", INTERPOLATIONS)
def test_keys_are_hit_exactly_and_held_outside_them(mode):
    t = track(mode)
    assert t.values_at([10, 20, 30]) == pytest.approx([0.0, 1.0, 0.5])
    assert t.values_at([-100, 0, 9.99]) == pytest.approx([0.0, 0.0, 0.0])  # before the first
    assert t.values_at([30.5, 1000]) == pytest.approx([0.5, 0.5])  # after the last


def test_the_mode_of_a_key_shapes_only_the_way_to_the_next_key():
    t = Track("p", [Key(0, 0.0, "constant"), Key(10, 1.0, "linear"), Key(20, 0.0, "cosine")])
    assert t.value_at(5) == 0.0  # held
    assert t.value_at(15) == pytest.approx(0.5)  # linear
    assert t.value_at(12.5) == pytest.approx(0.75)


def test_a_track_without_keys_is_zero_and_vectorised_matches_one_by_one():
    assert Track("p").values_at([0, 5]) == pytest.approx([0.0, 0.0])
    t = track("cosine")
    frames = np.linspace(0, 40, 97)
    assert t.values_at(frames) == pytest.approx([t.value_at(f) for f in frames])


def test_weights_at_lists_only_animated_poses():
    timeline = Timeline([track("linear"), Track("frown")])
    assert timeline.weights_at(15) == {"smile": pytest.approx(0.5)}
    assert timeline.has_keys and not Timeline([Track("frown")]).has_keys


def test_sequence_all_poses_is_neutral_pose_neutral_in_turn():
    timeline = sequence_all_poses(["a", "b", "c"], fps=24.0, rise=0.5, hold=0.5, fall=0.5)
    assert [t.pose for t in timeline.tracks] == ["a", "b", "c"]
    assert timeline.fps == 24.0 and timeline.start == 0 and timeline.end == 3 * 36
    for i, t in enumerate(timeline.tracks):
        base = 36 * i
        assert [(k.frame, k.value) for k in t.keys] == [
            (base, 0.0), (base + 12, 1.0), (base + 24, 1.0), (base + 36, 0.0)]
        assert all(k.interpolation == "cosine" for k in t.keys)
    # one pose at a time: at each pose's hold only that pose is on
    for i, pose in enumerate("abc"):
        weights = timeline.weights_at(36 * i + 18)
        assert weights[pose] == 1.0
        assert sum(weights.values()) == 1.0
    assert timeline.weights_at(36) == {"a": 0.0, "b": 0.0, "c": 0.0}  # neutral between poses


def test_dict_round_trip_keeps_every_key_and_setting():
    timeline = Timeline([track("smooth"), Track("frown", [Key(3, 0.25, "constant")])],
                        fps=30.0, start=-5, end=60)
    data = timeline.to_dict()
    again = Timeline.from_dict(data)
    assert again.to_dict() == data
    assert (again.fps, again.start, again.end) == (30.0, -5, 60)
    for frame in (0, 12.5, 25, 40):
        assert again.weights_at(frame) == timeline.weights_at(frame)


def test_from_dict_sorts_keys_and_rejects_bad_ranges():
    data = {"fps": 24, "start": 0, "end": 10,
            "tracks": [{"pose": "p", "keys": [[8, 1.0, "linear"], [2, 0.0, "linear"]]}]}
    assert [k.frame for k in Timeline.from_dict(data).tracks[0].keys] == [2.0, 8.0]
    with pytest.raises(ValueError):
        Timeline.from_dict({**data, "end": 0})
    with pytest.raises(ValueError):
        Timeline.from_dict({**data, "fps": 0})
    with pytest.raises(ValueError):
        Key(0, 0.0, "bouncy")


def test_the_sample_ships_with_an_animation_of_every_pose():
    from studio.core.sample.synthetic import POSES, make_test_face

    project = make_test_face()
    assert [t.pose for t in project.timeline.tracks] == list(POSES)
    assert project.timeline.weights_at(0) == dict.fromkeys(POSES, 0.0)
    assert project.timeline.weights_at(18)[POSES[0]] == 1.0


# --- by hand: defaults, messages and the thesis's sequence (each value worked out) ---


def test_a_timeline_record_without_fields_takes_the_defaults():
    timeline = Timeline.from_dict({})
    assert (timeline.fps, timeline.start, timeline.end, timeline.tracks) == (24.0, 0, 96, [])
    slow = Timeline.from_dict({"fps": 0.5, "start": 3, "end": 4})
    assert (slow.fps, slow.start, slow.end) == (0.5, 3, 4)  # any positive rate, end after start
    for bad in ({"fps": 0}, {"fps": -24}, {"start": 5, "end": 5}, {"start": 6, "end": 5}):
        with pytest.raises(ValueError) as info:
            Timeline.from_dict(bad)
        assert str(info.value) == "the timeline needs a positive frame rate and end after start"


def test_an_unknown_interpolation_is_named():
    with pytest.raises(ValueError) as info:
        Key(0.0, 1.0, "bouncy")
    assert str(info.value) == "unknown interpolation 'bouncy'"


def test_the_thesis_sequence_by_hand():
    """0.5 s up, 0.5 s held, 0.5 s down at 24 fps: 12 frames each, one pose after the other."""
    timeline = sequence_all_poses(["a", "b"])
    assert timeline.fps == 24.0 and timeline.end == 72
    a, b = timeline.tracks
    assert [(k.frame, k.value, k.interpolation) for k in a.keys] == [
        (0.0, 0.0, "cosine"), (12.0, 1.0, "cosine"), (24.0, 1.0, "cosine"), (36.0, 0.0, "cosine")]
    assert [k.frame for k in b.keys] == [36.0, 48.0, 60.0, 72.0]
    uneven = sequence_all_poses(["a"], fps=10.0, rise=0.3, hold=0.1, fall=0.6,
                                interpolation="linear")
    assert [k.frame for k in uneven.tracks[0].keys] == [0.0, 3.0, 4.0, 10.0]
    assert {k.interpolation for k in uneven.tracks[0].keys} == {"linear"}
    assert sequence_all_poses([]).end == 1  # no pose: still a timeline one frame long


def test_a_new_key_is_a_local_change_of_the_curve():
    """Red once: with ``insert_key`` adding no way back, the key past the last held 0.8 to the
    end and the one on an empty track held 1 over the whole range."""
    from studio.core.animation.timeline import insert_key

    keys = [(10.0, 0.0, "cosine"), (20.0, 1.0, "cosine"), (30.0, 0.0, "linear")]
    # between keys: only that key is added (each key shapes only the way to the next)
    assert insert_key(keys, (25.0, 0.5, "cosine"), 0, 96) == [*keys[:2], (25.0, 0.5, "cosine"),
                                                            keys[2]]
    # past the last key: back to what the track held (0) at the range's end
    assert insert_key(keys, (50.0, 0.8, "cosine"), 0, 96)[-2:] == [(50.0, 0.8, "cosine"),
                                                                   (96.0, 0.0, "cosine")]
    # at the weight the track held there, or on the range's end: no way back needed
    assert insert_key(keys, (50.0, 0.0, "cosine"), 0, 96)[-1] == (50.0, 0.0, "cosine")
    assert insert_key(keys, (96.0, 0.8, "cosine"), 0, 96)[-1] == (96.0, 0.8, "cosine")
    # before the first key: from the range's start at the weight held there
    assert insert_key(keys, (5.0, 0.3, "smooth"), 0, 96)[:2] == [(0.0, 0.0, "smooth"),
                                                                 (5.0, 0.3, "smooth")]
    # an empty track is 0 before and after its one key
    made = insert_key([], (24.0, 1.0, "cosine"), 0, 96)
    assert made == [(0.0, 0.0, "cosine"), (24.0, 1.0, "cosine"), (96.0, 0.0, "cosine")]
    track = Track("p", [Key(*k) for k in made])
    assert track.values_at([0, 24, 96]) == pytest.approx([0.0, 1.0, 0.0])
    # a key on another key's frame replaces it
    assert insert_key(keys, (20.0, 0.4, "linear"), 0, 96)[1] == (20.0, 0.4, "linear")
