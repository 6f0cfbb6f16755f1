"""Capture in: a Live Link Face take, written by the test with known curves, keyed onto the
production head's timeline (tests/production_head.py: ARKit poses as ``browDown_L``…).

The take spells its columns the ways real files and rigs do (``browInnerUp``, ``BrowDownLeft``,
``EYESQUINTLEFT``, ``mouthSmile_R``), has a column no pose takes, a head rotation, and samples
that fall between the frames of its 60 fps timecode; the timeline must show the known curves
at the project's 24 or 30 fps within 1/255 at every frame. Bad takes go through the real command
line in a subprocess: exit code 2, one line naming the file, nothing written.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.animation.timeline import Key, Timeline, Track
from studio.core.files.errors import StudioError
from studio.core.formats.capture import (
    CaptureError,
    apply_take,
    import_capture,
    match_columns,
    read_live_link_csv,
    reduce_keys,
)
from studio.core.project.reader import load_project
from tests.production_head import POSES, build_head
from tests.test_bad_inputs import run_cli, snapshot

RATE = 60.0  # the take's timecode rate
START_S = 14 * 3600 + 23 * 60 + 7 + 12 / RATE  # the first sample: 14:23:07, frame 12
DURATION_S = 3.0
# column as the take spells it → the production head's pose it must drive
MATCHED = {"browInnerUp": "browInnerUp", "BrowDownLeft": "browDown_L",
           "BrowDownRight": "browDown_R", "MouthSmileLeft": "mouthSmile_L",
           "mouthSmile_R": "mouthSmile_R", "jawOpen": "jawOpen",
           "EYESQUINTLEFT": "eyeSquint_L"}
NO_POSE = "EyeBlinkLeft"  # an ARKit shape the head has no pose for
ROTATION = "HeadYaw"
MISSING = ["eyeSquint_R", "eyeLookUp_L"]  # poses the take has no column for
COLUMNS = [*MATCHED, NO_POSE, ROTATION]


def curve(k: int, t: np.ndarray) -> np.ndarray:
    """Column k's known weight at t seconds: a different frequency and phase per column,
    changing by up to 0.17 a frame at 24 fps, so a frame out of place shows."""
    return 0.5 + 0.45 * np.sin(2.0 * np.pi * (0.4 + 0.15 * k) * t + k)


def timecode(seconds: float, rate: float = RATE) -> str:
    """``HH:MM:SS:FF.fff`` (FF.fff: the fractional frame at ``rate``)."""
    whole = int(seconds)
    frame = (seconds - whole) * rate
    return f"{whole // 3600:02d}:{whole // 60 % 60:02d}:{whole % 60:02d}:{frame:06.3f}"


def sample_times() -> np.ndarray:
    """Seconds from the first sample: 60 a second, each a little off its frame (as a phone's
    samples are), never by half a frame."""
    i = np.arange(int(DURATION_S * RATE) + 1)
    return np.round(i + 0.3 * np.sin(1.7 * i) * (i > 0), 3) / RATE  # as the timecodes hold it


def write_take(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A Live Link Face CSV of the known curves; returns (times, values) as written."""
    t = sample_times()
    values = np.stack([curve(k, t) for k in range(len(COLUMNS) - 1)]
                      + [-0.3 * np.ones_like(t)], axis=1)  # the head turned: radians
    values = np.round(values, 6)
    rows = [",".join([timecode(START_S + s), "61", *(f"{v:.6f}" for v in row)])
            for s, row in zip(t, values, strict=True)]
    path.write_text("Timecode,BlendShapeCount," + ",".join(COLUMNS) + "\n"
                    + "\n".join(rows) + "\n")
    return t, values


@pytest.fixture(scope="module")
def head_project(tmp_path_factory) -> Path:
    """The production head as ``wrinkle-studio new`` makes it (ARKit poses, no keys)."""
    folder = tmp_path_factory.mktemp("head")
    head = build_head("mm", vertices=561)
    files = head.write_set(folder / "obj")
    args = ["new", "--mesh", str(files["neutral"]), "--not-face", "eye_L", "eye_R", "teeth",
            "-o", str(folder / "head.wrinkle")]
    for pose in POSES:
        args += ["--pose", f"{pose}={files[pose]}"]
    with redirect_stdout(io.StringIO()):
        assert main(args) == 0
    return folder / "head.wrinkle"


# --- the take lands where it should ---------------------------------------------------------

def expected_weights(t: np.ndarray, values: np.ndarray, fps: float) -> dict[str, np.ndarray]:
    """Each matched pose's weight at every frame: the written samples, linearly interpolated
    at frame / fps seconds."""
    frames = np.arange(int(t[-1] * fps) + 1)
    return {pose: np.interp(frames / fps, t, values[:, k])
            for k, pose in enumerate(MATCHED.values())}


@pytest.mark.core
@pytest.mark.parametrize("fps", [24.0, 30.0])
def test_take_lands_on_the_timeline_at_the_right_frames_and_values(tmp_path, fps):
    t, values = write_take(tmp_path / "take.csv")
    take = read_live_link_csv(tmp_path / "take.csv")
    assert take.rate == RATE  # frame numbers reach 30: a 60 fps take
    assert take.duration == pytest.approx(t[-1], abs=1e-6)
    old = Timeline(fps=fps)
    timeline, report = apply_take(old, take, POSES)
    expected = expected_weights(t, values, fps)
    frames = len(next(iter(expected.values())))
    assert (timeline.fps, timeline.start, timeline.end) == (fps, 0, frames - 1)
    assert report.frames == frames and report.fps == fps
    worst = 0.0
    for frame in range(frames):
        weights = timeline.weights_at(frame)
        assert set(weights) == set(MATCHED.values())
        worst = max(worst, max(abs(weights[p] - expected[p][frame]) for p in weights))
    assert worst <= 1.0 / 255.0
    # and the known curve itself, within what sampling at 60 fps adds
    for k, pose in enumerate(MATCHED.values()):
        track = next(tr for tr in timeline.tracks if tr.pose == pose)
        at = np.arange(frames)
        assert np.abs(track.values_at(at) - curve(k, at / fps)).max() < 1.0 / 255.0 + 2e-3
        assert all(key.interpolation == "linear" for key in track.keys)
        assert len(track.keys) < frames  # keys where the curve needs them, not every frame


@pytest.mark.core
def test_report_names_matches_unmatched_columns_rotations_and_poses_without_a_column(tmp_path):
    write_take(tmp_path / "take.csv")
    _, report = apply_take(Timeline(fps=30.0), read_live_link_csv(tmp_path / "take.csv"), POSES)
    assert dict(report.matched) == MATCHED
    assert report.unmatched == (NO_POSE,)
    assert report.ignored == (ROTATION,)
    assert list(report.missing) == MISSING
    assert report.samples == len(sample_times())
    assert report.duration == pytest.approx(DURATION_S, abs=0.01)
    assert report.clipped == 0
    text = "\n".join(report.lines())
    assert f"columns without a pose (1): {NO_POSE}" in text
    assert f"ignored, not blend shapes (1): {ROTATION}" in text
    assert "poses without a column (2), left as they were: eyeSquint_R, eyeLookUp_L" in text
    assert "BrowDownLeft → browDown_L" in text


@pytest.mark.core
def test_other_tracks_are_kept_at_their_times_and_matched_ones_replaced(tmp_path):
    write_take(tmp_path / "take.csv")
    old = Timeline([Track("eyeLookUp_L", [Key(48.0, 0.7, "cosine")]),
                    Track("browInnerUp", [Key(5.0, 1.0)])], fps=24.0, start=0, end=96)
    timeline, _ = apply_take(old, read_live_link_csv(tmp_path / "take.csv"), POSES, fps=30.0)
    kept = next(tr for tr in timeline.tracks if tr.pose == "eyeLookUp_L")
    assert [(k.frame, k.value, k.interpolation) for k in kept.keys] == [(60.0, 0.7, "cosine")]
    brow = next(tr for tr in timeline.tracks if tr.pose == "browInnerUp")
    assert brow.keys[0].frame == 0.0 and brow.value_at(5.0) != 1.0
    assert [tr.pose for tr in timeline.tracks].count("browInnerUp") == 1
    assert [(k.frame, k.value) for k in old.tracks[0].keys] == [(48.0, 0.7)]  # not changed


@pytest.mark.core
def test_a_take_at_30_fps_and_one_over_midnight(tmp_path):
    path = tmp_path / "take.csv"
    rows = [f"23:59:59:{f:06.3f},61,{f / 30:.4f}" for f in (27.0, 28.0, 29.0)]
    rows += [f"00:00:00:{f:06.3f},61,{(30 + f) / 30:.4f}" for f in (0.0, 1.0)]
    path.write_text("Timecode,BlendShapeCount,JawOpen\n" + "\n".join(rows) + "\n")
    take = read_live_link_csv(path)
    assert take.rate == 30.0  # no frame number reaches 30
    assert np.allclose(take.times, np.arange(5) / 30.0)


@pytest.mark.core
def test_columns_match_any_arkit_spelling_and_each_pose_once():
    matched, unmatched, missing = match_columns(
        ["EyeBlinkLeft", "eyeBlink_L", "JAWOPEN", "Smile", "HeadYaw"],
        ["eyeBlink_L", "jaw_open", "smile", "frown"])
    assert matched == [("EyeBlinkLeft", "eyeBlink_L"), ("JAWOPEN", "jaw_open"),
                       ("Smile", "smile")]
    assert unmatched == ["eyeBlink_L", "HeadYaw"]  # the second spelling of a taken pose
    assert missing == ["frown"]


# --- keys -----------------------------------------------------------------------------------

def check_keys(curve_values: np.ndarray, tolerance: float) -> np.ndarray:
    keys = reduce_keys(curve_values, tolerance)
    frames = np.arange(len(curve_values))
    assert keys[0] == 0 and keys[-1] == len(curve_values) - 1
    assert np.all(np.diff(keys) > 0)
    rebuilt = np.interp(frames, keys, curve_values[keys])
    assert np.abs(rebuilt - curve_values).max() <= tolerance
    return keys


@pytest.mark.core
def test_keys_reproduce_any_curve_within_the_tolerance():
    rng = np.random.default_rng(7)
    ramp = np.linspace(0.0, 1.0, 200)
    assert list(check_keys(ramp, 1e-6)) == [0, 199]
    step = np.r_[np.zeros(50), np.ones(50)]
    assert list(check_keys(step, 1e-6)) == [0, 49, 50, 99]
    smooth = 0.5 + 0.5 * np.sin(np.linspace(0.0, 12.0, 600))
    assert len(check_keys(smooth, 0.5 / 255)) < 200
    noisy = np.clip(np.cumsum(rng.normal(0.0, 0.02, 1000)) + 0.5, 0.0, 1.0)
    check_keys(noisy, 0.5 / 255)
    check_keys(rng.random(300), 0.5 / 255)
    assert list(reduce_keys(np.array([0.2]))) == [0]


# --- the command line -----------------------------------------------------------------------

@pytest.mark.core
def test_cli_round_trip_keys_the_take_into_the_written_project(tmp_path, head_project):
    t, values = write_take(tmp_path / "take.csv")
    out = tmp_path / "out.wrinkle"
    printed = io.StringIO()
    with redirect_stdout(printed):
        code = main(["capture", str(head_project), "--csv", str(tmp_path / "take.csv"),
                     "--fps", "30", "-o", str(out)])
    assert code == 0
    text = printed.getvalue()
    assert NO_POSE in text and ROTATION in text and "eyeSquint_R" in text
    assert f"wrote {out}" in text
    project = load_project(out)
    timeline = project.timeline
    assert timeline.fps == 30.0
    expected = expected_weights(t, values, 30.0)
    for pose, weights in expected.items():
        track = next(tr for tr in timeline.tracks if tr.pose == pose)
        assert np.abs(track.values_at(np.arange(len(weights))) - weights).max() <= 1 / 255
    assert not load_project(head_project).timeline.has_keys  # the input is untouched


BAD_TAKES: dict[str, tuple[bytes, str]] = {
    "ragged row": (b"Timecode,BlendShapeCount,JawOpen\n00:00:00:01.000,61,0.5\n"
                   b"00:00:00:02.000,61\n", "line 3 has 2 values"),
    "non-numeric value": (b"Timecode,BlendShapeCount,JawOpen,BrowInnerUp\n"
                          b"00:00:00:01.000,61,0.5,0.1\n00:00:00:02.000,61,abc,0.1\n",
                          "line 3, column 'JawOpen': 'abc' is not a finite number"),
    "not a finite number": (b"Timecode,BlendShapeCount,JawOpen\n00:00:00:01.000,61,nan\n",
                            "'nan' is not a finite number"),
    "no Timecode": (b"Time,BlendShapeCount,JawOpen\n1,61,0.5\n", "no Timecode column"),
    "empty": (b"", "the capture file is empty"),
    "header only": (b"Timecode,BlendShapeCount,JawOpen\n", "no samples"),
    "binary garbage": (bytes(np.random.default_rng(3).integers(0, 256, 4096, np.uint8)),
                       "not a CSV text file"),
    "bad timecode": (b"Timecode,BlendShapeCount,JawOpen\n12:00,61,0.5\n",
                     "line 2: the timecode '12:00' is not HH:MM:SS:FF"),
    "backwards": (b"Timecode,BlendShapeCount,JawOpen\n00:00:01:00.000,61,0.5\n"
                  b"00:00:00:05.000,61,0.5\n", "line 3: the timecode goes back in time"),
    "nothing matches": (b"Timecode,BlendShapeCount,TongueOut\n00:00:00:01.000,61,0.5\n",
                        "no column of the take names a key pose"),
}


@pytest.mark.parametrize("name", list(BAD_TAKES))
def test_bad_take_is_one_line_naming_the_file_exit_2_and_writes_nothing(tmp_path, head_project,
                                                                        name):
    data, needle = BAD_TAKES[name]
    take = tmp_path / "take.csv"
    take.write_bytes(data)
    before = snapshot(tmp_path)
    code, lines, _, _ = run_cli(["capture", str(head_project), "--csv", str(take),
                                 "-o", str(tmp_path / "out.wrinkle")], tmp_path)
    assert code == 2, lines
    assert len(lines) == 1, lines
    assert str(take) in lines[0] and needle in lines[0], lines[0]
    assert snapshot(tmp_path) == before


def test_cli_refuses_to_write_over_an_input_and_a_missing_take(tmp_path, head_project):
    write_take(tmp_path / "take.csv")
    before = snapshot(tmp_path)
    for args, needle in (
            (["--csv", str(tmp_path / "take.csv"), "-o", str(tmp_path / "take.csv")],
             "would overwrite the input file"),
            (["--csv", str(tmp_path / "none.csv"), "-o", str(tmp_path / "o.wrinkle")],
             "does not exist"),
            (["--csv", str(tmp_path), "-o", str(tmp_path / "o.wrinkle")], "a folder")):
        code, lines, _, _ = run_cli(["capture", str(head_project), *args], tmp_path)
        assert code == 2 and len(lines) == 1 and needle in lines[0], lines
    assert snapshot(tmp_path) == before


@pytest.mark.core
def test_capture_error_names_the_file(tmp_path):
    (tmp_path / "t.csv").write_text("Timecode,JawOpen\n00:00:00:75.000,0.5\n")
    with pytest.raises(CaptureError, match="not below the take's rate of 60 fps") as info:
        read_live_link_csv(tmp_path / "t.csv")
    assert info.value.path == tmp_path / "t.csv"


# --- a glTF animation of morph weights ------------------------------------------------------

GLTF_TARGETS = ["browInnerUp", "browDown_L", "jawOpen", "tongueOut"]


def write_gltf_take(path: Path, times: np.ndarray, weights: np.ndarray,
                    interpolation: str = "LINEAR") -> None:
    """A .gltf (data-URI buffer) whose one animation drives the weights of a mesh's four morph
    targets, named in ``mesh.extras.targetNames``."""
    import base64
    import json

    data = times.astype("<f4").tobytes() + weights.astype("<f4").tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0}],
           "meshes": [{"name": "head", "extras": {"targetNames": GLTF_TARGETS},
                       "primitives": [{"attributes": {}, "targets": [{}] * 4}]}],
           "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                        + base64.b64encode(data).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": 4 * len(times)},
                           {"buffer": 0, "byteOffset": 4 * len(times),
                            "byteLength": 4 * weights.size}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(times),
                          "type": "SCALAR"},
                         {"bufferView": 1, "componentType": 5126, "count": weights.size,
                          "type": "SCALAR"}],
           "animations": [{"samplers": [{"input": 0, "output": 1,
                                         "interpolation": interpolation}],
                           "channels": [{"sampler": 0,
                                         "target": {"node": 0, "path": "weights"}}]}]}
    path.write_text(json.dumps(doc))


@pytest.mark.core
def test_a_gltf_weights_animation_lands_like_a_csv_take(tmp_path, head_project):
    times = 0.5 + np.arange(49) / 24.0  # two seconds of keys, the first at 0.5 s
    weights = np.stack([curve(k, times) for k in range(4)], axis=1)
    write_gltf_take(tmp_path / "take.gltf", times, weights)
    out = tmp_path / "out.wrinkle"
    printed = io.StringIO()
    with redirect_stdout(printed):
        assert main(["capture", str(head_project), "--gltf", str(tmp_path / "take.gltf"),
                     "-o", str(out)]) == 0
    assert "columns without a pose (1): tongueOut" in printed.getvalue()
    timeline = load_project(out).timeline
    frames = np.arange(int(2.0 * timeline.fps) + 1)
    for k, pose in enumerate(["browInnerUp", "browDown_L", "jawOpen"]):
        track = next(tr for tr in timeline.tracks if tr.pose == pose)
        known = np.interp(0.5 + frames / timeline.fps, times, weights[:, k].astype("f4"))
        assert np.abs(track.values_at(frames) - known).max() <= 1 / 255


@pytest.mark.core
def test_a_step_gltf_animation_holds_and_a_cubic_one_is_refused(tmp_path):
    times = np.array([0.0, 1.0, 2.0])
    weights = np.array([[0.0, 0.2, 0.4, 0.6], [1.0, 0.2, 0.4, 0.6], [0.5, 0.2, 0.4, 0.6]])
    write_gltf_take(tmp_path / "step.gltf", times, weights, "STEP")
    timeline, _ = import_capture(tmp_path / "step.gltf", Timeline(fps=10.0), ["browInnerUp"])
    track = timeline.tracks[0]
    assert list(track.values_at([0, 5, 9, 10, 15, 19, 20])) == pytest.approx(
        [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.5], abs=1 / 255)
    write_gltf_take(tmp_path / "cubic.gltf", times, np.repeat(weights, 3, axis=0),
                    "CUBICSPLINE")
    with pytest.raises(StudioError, match="CUBICSPLINE") as info:
        import_capture(tmp_path / "cubic.gltf", Timeline(), ["browInnerUp"])
    assert str(tmp_path / "cubic.gltf") in str(info.value)
