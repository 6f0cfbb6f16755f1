"""Capture takes written by hand, a few lines each: timecodes and the take's frame rate, the
header's checks, blank lines, budgets, every error naming the file and the line, resampling,
key reduction, the report's wording and a glTF take's own checks.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.timeline import Key, Timeline, Track
from studio.core.formats.capture import (
    CaptureError,
    CaptureReport,
    Take,
    apply_take,
    import_capture,
    match_columns,
    read_gltf_take,
    read_live_link_csv,
    read_take,
    reduce_keys,
    resample,
)
from tests.test_capture import write_gltf_take

pytestmark = pytest.mark.core

HEADER = "Timecode,BlendShapeCount,JawOpen"


def write(tmp_path: Path, *lines: str, name: str = "take.csv") -> Path:
    """A CSV take of exactly these lines (each ended by a newline)."""
    path = tmp_path / name
    path.write_text("".join(line + "\n" for line in lines))
    return path


def error_of(path: Path, rate: float | None = None) -> CaptureError:
    with pytest.raises(CaptureError) as info:
        read_live_link_csv(path, rate)
    assert info.value.path == path
    return info.value


def take_of(columns: tuple[str, ...], times: list[float], values: list[list[float]],
            rate: float = 30.0, ignored: tuple[str, ...] = ()) -> Take:
    return Take(Path("/takes/t.csv"), columns, ignored, np.array(times, dtype=np.float64),
                np.array(values, dtype=np.float64).reshape(len(times), len(columns)), rate)


# --- the file's text ------------------------------------------------------------------------

def test_a_take_over_the_byte_budget_is_refused_naming_the_setting(tmp_path, monkeypatch):
    """A take larger than MAX_CAPTURE_BYTES is a CaptureError naming the size and setting."""
    path = write(tmp_path, HEADER, "00:00:00:01.000,61,0.5")
    size = path.stat().st_size
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_CAPTURE_BYTES", "10")
    assert error_of(path).problem == (
        f"the capture file is {size} bytes, more than the limit of 10 bytes "
        "(set WRINKLE_STUDIO_MAX_CAPTURE_BYTES to raise it)")


def test_a_missing_take_is_a_capture_error(tmp_path):
    """A take that does not exist is a CaptureError that calls it the capture file."""
    err = error_of(tmp_path / "none.csv")
    assert "capture file" in err.problem


def test_blank_binary_and_non_utf8_takes_are_refused(tmp_path):
    """Whitespace only, a NUL byte and a non-UTF-8 byte each get their own message."""
    blank = tmp_path / "blank.csv"
    blank.write_bytes(b"  \n\n")
    assert error_of(blank).problem == "the capture file is empty"
    nul = tmp_path / "nul.csv"
    nul.write_bytes(b"Timecode,JawOpen\n00:00:00:01.000,0\x00.5\n")
    assert error_of(nul).problem == "binary data, not a CSV text file"
    latin = tmp_path / "latin.csv"
    latin.write_bytes(b"Timecode,Jaw\xe9Open\n00:00:00:01.000,0.5\n")
    assert error_of(latin).problem == "not a CSV text file: byte 12 is not UTF-8 text"


def test_a_byte_order_mark_is_not_part_of_the_first_column(tmp_path):
    """A UTF-8 BOM before 'Timecode' still finds the Timecode column."""
    path = tmp_path / "bom.csv"
    path.write_bytes(b"\xef\xbb\xbfTimecode,JawOpen\n00:00:00:01.000,0.5\n")
    assert read_live_link_csv(path).columns == ("JawOpen",)


# --- the header -----------------------------------------------------------------------------

def test_no_timecode_column_shows_the_first_three_names(tmp_path):
    """The message quotes the header's first three names, with '…' only when there are more."""
    tail = "; a Live Link Face take starts 'Timecode,BlendShapeCount,EyeBlinkLeft,…')"
    four = write(tmp_path, "Time,BlendShapeCount,JawOpen,EyeBlinkLeft", "1,61,0.5,0.1")
    assert error_of(four).problem == (
        "no Timecode column (the header starts 'Time,BlendShapeCount,JawOpen…'" + tail)
    three = write(tmp_path, " Time , Count,JawOpen", "1,61,0.5", name="three.csv")
    assert error_of(three).problem == (
        "no Timecode column (the header starts 'Time,Count,JawOpen'" + tail)


def test_a_column_twice_or_without_a_name_is_refused(tmp_path):
    """Names differing only in case are the same column; an empty name is refused."""
    twice = write(tmp_path, "Timecode,JawOpen,EyeBlinkLeft,jawopen", "00:00:00:01,0.5,0,0")
    assert error_of(twice).problem == "the column 'JawOpen' appears twice"
    nameless = write(tmp_path, "Timecode,JawOpen,", "00:00:00:01,0.5,0", name="n.csv")
    assert error_of(nameless).problem == "a column has no name"


# --- rows -----------------------------------------------------------------------------------

def test_blank_and_whitespace_lines_are_skipped_anywhere(tmp_path):
    """Empty lines and lines of spaces between rows are skipped, not the end of the take."""
    path = write(tmp_path, HEADER, "00:00:00:00.000,61,0.1", "", "   ",
                 "00:00:00:01.000,61,0.2", "", "00:00:00:02.000,61,0.3")
    take = read_live_link_csv(path)
    assert take.values[:, 0].tolist() == [0.1, 0.2, 0.3]
    assert np.allclose(take.times, [0.0, 1 / 30, 2 / 30])


def test_a_short_row_names_its_line_and_counts(tmp_path):
    """A row of one value in a three-column take is refused with its line number."""
    path = write(tmp_path, HEADER, "00:00:00:00.000,61,0.1", "0.5")
    assert error_of(path).problem == "line 3 has 1 values, the header names 3 columns"


def test_a_header_only_take_has_no_samples(tmp_path):
    """A header and blank lines: no samples."""
    path = write(tmp_path, HEADER, "")
    assert error_of(path).problem == "no samples: the file has a header but no rows"


def test_csv_errors_name_their_line(tmp_path):
    """A field over the csv module's size limit is a CaptureError naming the line."""
    huge = "x" * 131073
    head = write(tmp_path, huge + ",Timecode", "1,2", name="head.csv")
    assert error_of(head).problem == "line 1: field larger than field limit (131072)"
    row = write(tmp_path, HEADER, "00:00:00:00.000,61,0.1", f"{huge},61,0.2", name="row.csv")
    assert error_of(row).problem == "line 3: field larger than field limit (131072)"


def test_a_take_over_the_values_budget_is_refused(tmp_path, monkeypatch):
    """Lines times columns over MAX_CAPTURE_VALUES is refused before parsing."""
    path = write(tmp_path, HEADER, "00:00:00:01.000,61,0.5", "00:00:00:02.000,61,0.6")
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_CAPTURE_VALUES", "8")
    assert error_of(path).problem == (
        "the take is 9 values, more than the limit of 8 values "
        "(set WRINKLE_STUDIO_MAX_CAPTURE_VALUES to change it)")
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_CAPTURE_VALUES", "9")
    assert len(read_live_link_csv(path).times) == 2


def test_rotations_are_ignored_and_the_shape_count_dropped(tmp_path):
    """Head and eye rotations and BlendShapeCount are not value columns of the take."""
    path = write(tmp_path, "Timecode,BlendShapeCount,EyeBlinkLeft,HeadYaw,jawOpen,"
                           "LeftEyePitch,righteyeroll",
                 "00:00:00:00.000,61,0.25,-0.3,0.5,0.1,0.2")
    take = read_live_link_csv(path)
    assert take.columns == ("EyeBlinkLeft", "jawOpen")
    assert take.ignored == ("HeadYaw", "LeftEyePitch", "righteyeroll")
    assert take.values.tolist() == [[0.25, 0.5]]


# --- timecodes and the take's rate ----------------------------------------------------------

def test_a_frame_number_of_exactly_30_means_60_fps(tmp_path):
    """A frame number of 30.000 cannot be at 30 fps: the take is at 60."""
    path = write(tmp_path, HEADER, "00:00:01:29.000,61,0", "00:00:01:30.000,61,1")
    take = read_live_link_csv(path)
    assert take.rate == 60.0
    assert take.times.tolist() == pytest.approx([0.0, 1 / 60])


def test_the_take_rate_can_be_given(tmp_path):
    """A given rate divides the frame numbers, also through read_take."""
    path = write(tmp_path, HEADER, "00:00:00:00.000,61,0", "00:00:01:40.000,61,1")
    for take in (read_live_link_csv(path, 50.0), read_take(path, 50.0)):
        assert take.rate == 50.0
        assert take.times.tolist() == pytest.approx([0.0, 1.8])
    slow = write(tmp_path, HEADER, "00:00:00:00.000,61,0", "00:00:02:00.250,61,1",
                 name="slow.csv")
    assert read_live_link_csv(slow, 0.5).times.tolist() == pytest.approx([0.0, 2.5])


@pytest.mark.parametrize(("rate", "shown"), [(0.0, "0"), (-5.0, "-5"), (float("inf"), "inf"),
                                             (float("nan"), "nan")])
def test_a_given_rate_must_be_positive_and_finite(tmp_path, rate, shown):
    """Zero, negative, infinite and NaN rates are refused, showing the rate."""
    path = write(tmp_path, HEADER, "00:00:00:00.000,61,0")
    assert error_of(path, rate).problem == (
        f"the take's frame rate must be positive, not {shown}")


def test_a_frame_number_at_the_given_rate_is_refused(tmp_path):
    """Frame 30 does not exist at 30 fps."""
    path = write(tmp_path, HEADER, "00:00:00:29.000,61,0", "00:00:00:30.000,61,0")
    assert error_of(path, 30.0).problem == (
        "line 3: frame 30 of the timecode is not below the take's rate of 30 fps")


def test_a_bad_timecode_names_its_line(tmp_path):
    """A timecode that is not HH:MM:SS:FF is refused, quoted with its line."""
    path = write(tmp_path, HEADER, "00:00:00:01.000,61,0", "", "12:00,61,0.5")
    assert error_of(path).problem == "line 4: the timecode '12:00' is not HH:MM:SS:FF"


def test_the_first_step_back_in_time_is_reported(tmp_path):
    """Of two steps back, the first is named by its line and both timecodes."""
    path = write(tmp_path, HEADER, "00:00:00:10.000,61,0", "00:00:00:20.000,61,0",
                 "00:00:00:05.000,61,0", "00:00:00:25.000,61,0", "00:00:00:01.000,61,0")
    assert error_of(path).problem == (
        "line 4: the timecode goes back in time (from 00:00:00:20.000 to 00:00:00:05.000)")


@pytest.mark.parametrize("first", ["09:00:00:00.000", "12:00:00:00.000"])
def test_a_jump_back_of_half_a_day_or_less_is_not_midnight(tmp_path, first):
    """Only a jump back of more than half a day is taken as a take over midnight."""
    path = write(tmp_path, HEADER, f"{first},61,0", "00:00:00:00.000,61,0")
    assert error_of(path).problem == (
        f"line 3: the timecode goes back in time (from {first} to 00:00:00:00.000)")


def test_repeated_timecodes_are_kept(tmp_path):
    """Two samples at the same timecode are not a step back."""
    path = write(tmp_path, HEADER, "00:00:00:01.000,61,0", "00:00:00:01.000,61,0.5",
                 "00:00:00:02.000,61,1")
    assert read_live_link_csv(path).times.tolist() == pytest.approx([0.0, 0.0, 1 / 30])


# --- matching, resampling, keys -------------------------------------------------------------

def test_other_names_match_apart_from_case_and_separators():
    """'mouth.wide' takes a 'Mouth Wide' or 'MOUTHWIDE' column; a different name is left."""
    matched, unmatched, missing = match_columns(["MOUTHWIDE", "Mouth_Narrow"],
                                                ["mouth.wide", "mouth-narrow ", "frown"])
    assert matched == [("MOUTHWIDE", "mouth.wide"), ("Mouth_Narrow", "mouth-narrow ")]
    assert unmatched == [] and missing == ["frown"]


def test_resampling_at_a_step_takes_the_later_value_without_warnings():
    """Samples sharing a time are a step: a frame on it shows the value after the step."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        middle = resample(np.array([0.0, 1.0, 1.0, 2.0]), np.array([[0.0], [0.0], [1.0], [1.0]]),
                          2.0)
        end = resample(np.array([0.0, 1.0, 1.0]), np.array([[0.0], [0.0], [1.0]]), 1.0)
    assert middle[:, 0].tolist() == [0.0, 0.0, 1.0, 1.0, 1.0]
    assert end[:, 0].tolist() == [0.0, 1.0]


def test_resampling_interpolates_between_the_last_two_samples():
    """Frames between the last two samples lie on the line between them."""
    out = resample(np.array([0.0, 1.0, 2.0]), np.array([[0.0, 1.0], [1.0, 0.0], [0.0, 0.5]]),
                   4.0)
    assert out[:, 0].tolist() == pytest.approx([0, 0.25, 0.5, 0.75, 1, 0.75, 0.5, 0.25, 0])
    assert out[:, 1].tolist() == pytest.approx([1, 0.75, 0.5, 0.25, 0, 0.125, 0.25, 0.375, 0.5])


def test_keys_on_the_chord_are_dropped_even_at_zero_tolerance():
    """A key exactly on its neighbours' line is not needed, whatever the tolerance."""
    assert reduce_keys(np.zeros(4), 0.0).tolist() == [0, 3]
    assert reduce_keys(np.array([0.0, 0.25, 0.5, 0.75, 1.0]), 0.0).tolist() == [0, 4]


def test_a_plateau_keeps_only_its_corners():
    """A flat top between two ramps keeps its two corners: keys odd and even are both tried."""
    assert reduce_keys(np.array([0.0, 1.0, 1.0, 1.0, 0.0]), 0.0).tolist() == [0, 1, 3, 4]
    curve = np.array([0.0, 0.5, 1.0, 1.0, 1.0, 1.0, 0.5, 0.0])
    assert reduce_keys(curve, 0.0).tolist() == [0, 2, 5, 7]


# --- onto the timeline ----------------------------------------------------------------------

@pytest.mark.parametrize("fps", [0.0, -24.0, 1000.5, 2000.0, float("inf"), float("nan")])
def test_the_timeline_rate_must_be_above_0_and_at_most_1000(fps):
    """Rates outside (0, 1000] are refused, showing the rate."""
    take = take_of(("jawOpen",), [0.0, 1.0], [[0.0], [1.0]])
    with pytest.raises(CaptureError) as info:
        apply_take(Timeline(), take, ["jawOpen"], fps)
    assert info.value.problem == f"the frame rate must be above 0 and at most 1000, not {fps:g}"


@pytest.mark.parametrize(("fps", "frames"), [(0.5, 2), (1000.0, 2001)])
def test_the_edge_rates_are_accepted(fps, frames):
    """0.5 and 1000 fps are valid timeline rates."""
    take = take_of(("jawOpen",), [0.0, 1.0, 2.0], [[0.0], [0.5], [1.0]])
    timeline, report = apply_take(Timeline(), take, ["jawOpen"], fps)
    assert timeline.fps == fps and report.frames == frames


def test_nothing_matching_lists_the_columns_and_poses():
    """The message lists up to eight columns ('…' after), the poses, or 'none'."""
    def problem(columns: tuple[str, ...], poses: list[str]) -> str:
        take = take_of(columns, [0.0], [[0.0] * len(columns)])
        with pytest.raises(CaptureError) as info:
            apply_take(Timeline(), take, poses)
        assert info.value.path == Path("/takes/t.csv")
        return info.value.problem

    head = "no column of the take names a key pose of the project (columns: "
    nine = tuple(f"c{i}" for i in range(1, 10))
    assert problem(nine, []) == head + "c1, c2, c3, c4, c5, c6, c7, c8…; poses: none)"
    assert problem(nine[:8], ["frown", "smile"]) == (
        head + "c1, c2, c3, c4, c5, c6, c7, c8; poses: frown, smile)")
    assert problem((), ["frown"]) == head + "none; poses: frown)"


def test_a_take_over_the_frame_budget_is_refused(monkeypatch):
    """A take longer than MAX_FRAMES frames at the timeline's rate is refused."""
    take = take_of(("jawOpen",), [0.0, 0.5], [[0.0], [1.0]])
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FRAMES", "10")
    with pytest.raises(CaptureError) as info:
        apply_take(Timeline(), take, ["jawOpen"], 20.0)
    assert info.value.path == Path("/takes/t.csv")
    assert info.value.problem == ("the take at 20 fps is 11 frames, more than the limit of 10 "
                                  "frames (set WRINKLE_STUDIO_MAX_FRAMES to change it)")
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FRAMES", "11")
    assert apply_take(Timeline(), take, ["jawOpen"], 20.0)[1].frames == 11


def test_values_outside_0_to_1_are_clipped_and_counted():
    """-0.5 and 1.5 key as 0 and 1 and count as clipped; 0 and 1 themselves do not."""
    take = take_of(("jawOpen", "EyeBlinkLeft"), [0.0, 1.0, 2.0],
                   [[-0.5, 0.0], [1.5, 0.5], [0.5, 1.0]], rate=60.0)
    timeline, report = apply_take(Timeline(fps=1.0), take, ["jawOpen", "eyeBlink_L"])
    assert report.clipped == 2
    jaw = timeline.track("jawOpen")
    assert [(k.frame, k.value, k.interpolation) for k in jaw.keys] == [
        (0.0, 0.0, "linear"), (1.0, 1.0, "linear"), (2.0, 0.5, "linear")]
    assert report.keys == 5  # three on jawOpen, two on the straight eyeBlink_L
    assert (report.rate, report.fps, report.frames, report.samples) == (60.0, 1.0, 3, 3)
    assert report.duration == 2.0


def test_other_tracks_keep_their_time_from_the_start_frame_and_kind():
    """Rescaled about the start frame, other keys keep their interpolation; the take starts
    at the start frame."""
    old = Timeline([Track("frown", [Key(34.0, 0.7, "linear"), Key(40.0, 0.2, "constant")])],
                   fps=24.0, start=10, end=50)
    take = take_of(("jawOpen",), [0.0, 1.0], [[0.0], [1.0]])
    timeline, _ = apply_take(old, take, ["jawOpen", "frown"], fps=48.0)
    frown = timeline.track("frown")
    assert [(k.frame, k.value, k.interpolation) for k in frown.keys] == [
        (58.0, 0.7, "linear"), (70.0, 0.2, "constant")]
    jaw = timeline.track("jawOpen")
    assert [(k.frame, k.value) for k in jaw.keys] == [(10.0, 0.0), (58.0, 1.0)]
    assert (timeline.start, timeline.end) == (10, 58)


@pytest.mark.parametrize(("times", "frames"), [([0.0], 1), ([0.0, 1 / 24], 2)])
def test_a_take_of_one_or_two_frames_spans_one_frame(times, frames):
    """The timeline's range is never empty: a take of one or two frames spans one frame."""
    take = take_of(("jawOpen",), times, [[0.5]] * len(times))
    timeline, report = apply_take(Timeline(fps=24.0, start=5), take, ["jawOpen"])
    assert report.frames == frames
    assert (timeline.start, timeline.end) == (5, 6)


# --- the report -----------------------------------------------------------------------------

def report(**changes: object) -> CaptureReport:
    fields = dict(path=Path("/takes/take.csv"),
                  matched=(("jawOpen", "jawOpen"), ("BrowDownLeft", "browDown_L")),
                  unmatched=("TongueOut", "Smile"), ignored=("HeadYaw", "HeadRoll"),
                  missing=("eyeSquint_R", "frown"), samples=181, rate=60.0, fps=24.0,
                  frames=73, duration=3.0, keys=40, clipped=3)
    fields.update(changes)
    return CaptureReport(**fields)  # type: ignore[arg-type]


def test_the_report_lines_word_for_word():
    """Every line of a report, exactly as the command prints it."""
    assert report().lines() == [
        "take.csv: 181 samples at 60 fps, 3.000 s → 73 frames at 24 fps, 40 keys on 2 tracks",
        "matched (2): jawOpen, BrowDownLeft → browDown_L",
        "columns without a pose (2): TongueOut, Smile",
        "ignored, not blend shapes (2): HeadYaw, HeadRoll",
        "poses without a column (2), left as they were: eyeSquint_R, frown",
        "3 values outside 0–1 were clipped"]


def test_a_report_without_rate_or_extras_has_two_lines():
    """A glTF take has no rate; nothing unmatched, ignored, missing or clipped: two lines."""
    assert report(path=Path("a.glb"), rate=0.0, unmatched=(), ignored=(), missing=(),
                  clipped=0, matched=(("jawOpen", "jawOpen"),), duration=1.25).lines() == [
        "a.glb: 181 samples, 1.250 s → 73 frames at 24 fps, 40 keys on 1 tracks",
        "matched (1): jawOpen"]


def test_import_capture_passes_the_take_rate_and_timeline_rate(tmp_path):
    """import_capture reads a CSV at the given take rate and keys it at the given fps."""
    path = write(tmp_path, HEADER, "00:00:00:00.000,61,0", "00:00:00:20.000,61,1")
    timeline, rep = import_capture(path, Timeline(fps=24.0), ["jawOpen"], fps=10.0, rate=40.0)
    assert (rep.rate, rep.fps, rep.duration, rep.frames) == (40.0, 10.0, 0.5, 6)
    assert timeline.fps == 10.0
    assert [(k.frame, k.value) for k in timeline.track("jawOpen").keys] == [(0.0, 0.0),
                                                                            (5.0, 1.0)]


# --- glTF takes -----------------------------------------------------------------------------

def gltf(tmp_path: Path, times: list[float], names: list[str] | None = None) -> Path:
    """A glTF take with four targets; ``names`` renames them."""
    path = tmp_path / "take.gltf"
    weights = np.linspace(0.0, 1.0, 4 * len(times)).reshape(len(times), 4)
    write_gltf_take(path, np.array(times), weights)
    if names is not None:
        doc = json.loads(path.read_text())
        doc["meshes"][0]["extras"]["targetNames"] = names
        path.write_text(json.dumps(doc))
    return path


def test_a_gltf_take_starts_at_its_first_key_with_no_rate_or_rotations(tmp_path):
    """Times from the first key; repeated key times are kept; no rate, nothing ignored."""
    take = read_gltf_take(gltf(tmp_path, [0.5, 1.0, 1.0, 2.0]))
    assert take.times.tolist() == [0.0, 0.5, 0.5, 1.5]
    assert take.rate == 0.0 and take.ignored == ()
    assert take.columns == ("browInnerUp", "browDown_L", "jawOpen", "tongueOut")
    _, rep = apply_take(Timeline(), take, ["jawOpen"])
    assert "samples, 1.500 s" in rep.lines()[0]


def test_gltf_targets_sharing_a_name_or_keys_going_back_are_refused(tmp_path):
    """Two targets named alike (any case) or key times going back are CaptureErrors."""
    path = gltf(tmp_path, [0.0, 1.0], ["jawOpen", "JAWOPEN", "a", "b"])
    with pytest.raises(CaptureError) as info:
        read_gltf_take(path)
    assert info.value.path == path
    assert info.value.problem == "two morph targets of the animated mesh share a name"
    path = gltf(tmp_path, [0.0, 2.0, 1.0])
    with pytest.raises(CaptureError) as info:
        read_gltf_take(path)
    assert info.value.path == path
    assert info.value.problem == "the animation's key times go back in time"
