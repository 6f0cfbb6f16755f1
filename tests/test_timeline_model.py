"""The timeline panel's model without Qt: rows, the weight a click keys, the time shown, paging
after the playhead, which way a key drag goes (studio/widgets/timeline/track_model.py)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.timeline import Key, Timeline, Track
from studio.widgets.timeline.track_model import (
    ROW_BAND,
    ROW_PAD,
    TrackRows,
    clamp_row_pixels,
    clicked_selection,
    drag_axis,
    drag_offset,
    frame_in_range,
    frame_text,
    framed_time,
    key_marks,
    paged_start,
    sample_frames,
    shared_interpolation,
)

pytestmark = pytest.mark.core

POSES = ["jawOpen", "Brow_Raise_L", "smile-wide"]  # the file's names, in the file's order


def _timeline(start: int = 10, end: int = 58, fps: float = 24.0) -> Timeline:
    timeline = Timeline(fps=fps, start=start, end=end)
    timeline.tracks = [Track("Brow_Raise_L",
                             [Key(4.0, 0.5, "linear"), Key(80.0, 1.0, "constant")])]
    return timeline


def test_the_first_pose_is_the_top_row_and_a_height_finds_its_pose():
    rows = TrackRows(POSES, 32)
    assert [rows.row_of(p) for p in POSES] == [2, 1, 0]
    assert rows.pose_at(2.5) == "jawOpen" and rows.pose_at(0.01) == "smile-wide"
    assert rows.pose_at(-0.2) is None and rows.pose_at(3.0) is None
    assert rows.key_y("Brow_Raise_L", 0.0) == pytest.approx(1 + ROW_PAD)
    assert rows.key_y("Brow_Raise_L", 1.0) == pytest.approx(1 + ROW_PAD + ROW_BAND)


@pytest.mark.parametrize("row_pixels", [18, 32, 120])
def test_a_click_on_the_drawn_baseline_or_top_keys_0_or_1_at_any_row_height(row_pixels):
    rows = TrackRows(POSES, row_pixels)
    three_pixels = 3.0 / row_pixels
    assert rows.value_at_y(1 + ROW_PAD + three_pixels) == 0.0
    assert rows.value_at_y(1 + ROW_PAD + ROW_BAND - three_pixels) == 1.0
    assert rows.value_at_y(1 + ROW_PAD - 0.05) == 0.0  # in the pad below the band
    assert rows.value_at_y(1 + ROW_PAD + ROW_BAND * 0.62) == pytest.approx(0.6)  # 0.05 steps


def test_rows_keep_their_height_and_scroll_when_they_do_not_fit():
    rows = TrackRows(POSES, 40)
    assert rows.fit(200.0) == (5, 5.0)  # all fit: no scrolling
    fit, shown = rows.fit(90.0)
    assert fit == 2 and shown == pytest.approx(2.25)
    assert rows.shown_heights(shown, 1) == pytest.approx((-0.25, 2.0))  # one row hidden above
    assert rows.visible(-0.25, 2.0) == ["Brow_Raise_L", "smile-wide"]
    assert rows.fit(5.0) == (1, 1.0)  # never less than a row


def test_the_current_pose_is_scrolled_into_view_only_when_hidden():
    rows = TrackRows([*POSES, "cheekPuff"], 32)
    assert rows.scrolled_to("Brow_Raise_L", top=0, fit=2, most=2) == 0
    assert rows.scrolled_to("cheekPuff", top=0, fit=2, most=2) == 2
    assert rows.scrolled_to("jawOpen", top=2, fit=2, most=2) == 0


def test_row_height_is_clamped_to_the_allowed_range():
    assert clamp_row_pixels(4) == 18 and clamp_row_pixels(500) == 120
    assert clamp_row_pixels(33.7) == 33


def test_key_marks_say_where_each_key_is_drawn_and_which_are_selected():
    rows = TrackRows(POSES, 32)
    tracks = (("Brow_Raise_L", ((4.0, 0.5, "linear"), (80.0, 1.0, "constant"))),
              ("gone", ((1.0, 1.0, "linear"),)))  # a track whose pose was deleted: not drawn
    marks = key_marks(tracks, rows, {("Brow_Raise_L", 1)})
    assert [(m.ref, m.frame, m.selected, m.held) for m in marks] == [
        (("Brow_Raise_L", 0), 4.0, False, False), (("Brow_Raise_L", 1), 80.0, True, True)]
    assert marks[0].y == pytest.approx(rows.key_y("Brow_Raise_L", 0.5))


def test_the_time_shown_covers_the_range_and_keys_beyond_it():
    timeline = _timeline()
    lo, hi = framed_time(timeline)
    assert lo == pytest.approx(4 - 1.52) and hi == pytest.approx(80 + 1.52)
    frames = sample_frames(timeline)
    assert frames[0] == pytest.approx(-6) and frames[-1] == pytest.approx(90)
    assert np.all(np.diff(frames) > 0) and len(frames) == 4 * 96 + 2


def test_the_view_pages_only_when_the_playhead_leaves_it():
    assert paged_start(0.0, 100.0, 50.0) is None
    assert paged_start(0.0, 100.0, 100.0) is None
    assert paged_start(0.0, 100.0, 130.0) == pytest.approx(125.0)  # a page on, just inside
    assert paged_start(200.0, 300.0, 10.0) == pytest.approx(5.0)


def test_scrubbing_lands_on_whole_frames_within_the_range_and_says_the_time():
    timeline = _timeline(start=10, end=58, fps=24.0)
    assert frame_in_range(timeline, 20.4) == 20 and frame_in_range(timeline, -3) == 10
    assert frame_in_range(timeline, 99.0) == 58
    assert frame_text(timeline, 34.0) == "Frame 34   ·   1.00 s"


def test_a_key_drag_picks_time_or_weight_from_its_first_clear_movement():
    assert drag_axis(3.0, 2.0) is None
    assert drag_axis(6.0, 2.0) == "time" and drag_axis(2.0, 6.0) == "value"
    assert drag_offset("time", 3.4, 0.9) == (3.0, 0.0)
    assert drag_offset("value", 3.4, ROW_BAND * 0.33) == (0.0, pytest.approx(0.35))


def test_clicking_keys_selects_and_ctrl_toggles():
    a, b = ("jawOpen", 0), ("jawOpen", 1)
    assert clicked_selection({a}, b, extend=False) == {b}
    assert clicked_selection({a}, b, extend=True) == {a, b}
    assert clicked_selection({a, b}, b, extend=True) == {a}


def test_the_interpolation_shown_is_the_selected_keys_shared_one():
    assert shared_interpolation([(0.0, 1.0, "smooth"), (5.0, 0.0, "smooth")]) == 2
    assert shared_interpolation([(0.0, 1.0, "smooth"), (5.0, 0.0, "linear")]) == -1
