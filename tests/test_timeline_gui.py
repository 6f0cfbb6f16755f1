"""The timeline dock driven like a user: clicking keys in, dragging them, scrubbing, playing,
undo, saving, and exporting the animation from the window."""

from __future__ import annotations

import time

import numpy as np
import pytest
from PIL import Image
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from studio.core.animation.timeline import Timeline
from studio.core.project.reader import load_project
from studio.widgets.export_dialog import ExportDialog, ExportOptions, export_animation
from studio.widgets.timeline.panel import activation_curves
from tests.gui_helpers import viewport_image, viewport_marks
from tests.regions import region_difference


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1200, 900)


@pytest.fixture
def blank(open_window, sample):
    """The sample face with an empty timeline (frames 0 to 96 at 24 fps)."""
    sample.timeline = Timeline()
    return open_window(sample)


def track_point(panel, pose: str, frame: float, value: float) -> QPoint:
    """Where a key at (frame, value) of a pose's track is, in the track view's pixels."""
    return panel.key_widget_pos(pose, frame, value)


def wheel(widget, pos: QPoint, steps: int, modifiers=Qt.KeyboardModifier.NoModifier) -> None:
    """Turn the mouse wheel ``steps`` notches (positive: away from the user) over ``pos``."""
    event = QWheelEvent(QPointF(pos), QPointF(widget.mapToGlobal(pos)), QPoint(),
                        QPoint(0, 120 * steps), Qt.MouseButton.NoButton, modifiers,
                        Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(widget, event)


def show_row(qtbot, panel, pose: str) -> None:
    """Scroll the rows with Shift+wheel over them until ``pose``'s row is on screen."""
    for _ in range(len(panel.poses)):
        if pose in panel.visible_rows():
            return
        below = panel.poses.index(pose) > panel.poses.index(panel.visible_rows()[0])
        centre = panel.view.mapFromScene(panel.track_box.sceneBoundingRect().center())
        wheel(panel.view.viewport(), centre, -1 if below else 1, Qt.KeyboardModifier.ShiftModifier)
        qtbot.wait(1)
    assert pose in panel.visible_rows()


def click_track(qtbot, panel, pose: str, frame: float, value: float) -> None:
    show_row(qtbot, panel, pose)
    qtbot.mouseClick(panel.view.viewport(), Qt.MouseButton.LeftButton,
                     pos=track_point(panel, pose, frame, value))


def drag_track(qtbot, panel, start: QPoint, end: QPoint) -> None:
    """Press, move in small steps (so it reads as a drag), release: like a hand."""
    viewport = panel.view.viewport()
    qtbot.mousePress(viewport, Qt.MouseButton.LeftButton, pos=start)
    for i in range(1, 11):
        qtbot.mouseMove(viewport, start + (end - start) * (i / 10))
    qtbot.mouseRelease(viewport, Qt.MouseButton.LeftButton, pos=end)


def keys(window, pose: str) -> list[tuple[float, float, str]]:
    track = window.doc.project.timeline.track(pose)
    return [(k.frame, k.value, k.interpolation) for k in track.keys]


def test_the_sample_opens_animated_in_a_bottom_timeline(window):
    panel = window.timeline_panel
    assert window.docks["Timeline"].isVisible()
    bottom = Qt.DockWidgetArea.BottomDockWidgetArea
    assert window.dockWidgetArea(window.docks["Timeline"]) == bottom
    assert len(panel.keys_item.data) == 5 * 4  # sequence all poses: four keys per pose
    assert "Export" in window.export_animation_action.text()
    assert window.export_animation_action.shortcut().toString() == "Ctrl+E"


def test_clicking_in_a_track_adds_keys_whose_height_is_the_weight(blank, qtbot):
    panel = blank.timeline_panel
    click_track(qtbot, panel, "surprise", 0, 0.0)
    click_track(qtbot, panel, "surprise", 24, 1.0)
    # the track goes back to 0 at the range's end: a new key does not hold to the end
    assert keys(blank, "surprise") == [(0.0, 0.0, "cosine"), (24.0, 1.0, "cosine"),
                                       (96.0, 0.0, "cosine")]
    assert blank.doc.undo_stack.count() == 2
    assert panel.selection == {("surprise", 1)}
    # Parke's cosine: half-way in time is half the weight, a quarter is (1 − cos(π/4)) / 2
    blank.doc.show_frame(12)
    assert blank.doc.pose_weights["surprise"] == pytest.approx(0.5)
    blank.doc.show_frame(6)
    assert blank.doc.pose_weights["surprise"] == pytest.approx((1 - np.cos(np.pi / 4)) / 2)
    # the interpolation combo changes the selected key's way to the next key... none after it
    panel._select({("surprise", 0)})
    panel.interpolation.setCurrentIndex(panel.interpolation.findData("linear"))
    panel.interpolation.activated.emit(panel.interpolation.currentIndex())
    blank.doc.show_frame(6)
    assert blank.doc.pose_weights["surprise"] == pytest.approx(0.25)
    blank.doc.undo_stack.undo()
    assert keys(blank, "surprise")[0] == (0.0, 0.0, "cosine")


def test_dragging_a_key_retimes_it_in_one_undo_step(blank, qtbot):
    panel = blank.timeline_panel
    edits = panel.edits
    edits.add_key("frown", 0, 0.0, "linear")
    edits.add_key("frown", 24, 1.0, "linear")
    blank.doc.show_frame(12)
    assert blank.doc.pose_weights["frown"] == pytest.approx(0.5)
    steps = blank.doc.undo_stack.count()
    show_row(qtbot, panel, "frown")
    drag_track(qtbot, panel, track_point(panel, "frown", 24, 1.0),
               track_point(panel, "frown", 48, 1.0))
    frame = keys(blank, "frown")[1][0]
    assert 44 <= frame <= 52 and frame == round(frame)
    assert keys(blank, "frown")[1][1] == 1.0  # a sideways drag keeps the weight
    assert blank.doc.undo_stack.count() == steps + 1
    blank.doc.show_frame(12)
    assert blank.doc.pose_weights["frown"] == pytest.approx(12 / frame)
    qtbot.keyClick(blank, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert keys(blank, "frown")[1] == (24.0, 1.0, "linear")


def test_scrubbing_the_playhead_moves_the_face_and_wrinkles(window, qtbot):
    panel = window.timeline_panel
    marks = viewport_marks(window)
    before = viewport_image(window)
    assert window.doc.frame == 0
    # the sample's surprise holds at full weight from frame 84 to 96: scrub there
    show_row(qtbot, panel, "frown")
    drag_track(qtbot, panel, track_point(panel, "frown", 0, 0.5),
               track_point(panel, "frown", 90, 0.5))
    assert window.doc.frame == pytest.approx(90, abs=1)
    assert window.doc.pose_weights["surprise"] == 1.0
    assert panel.playhead.value() == window.doc.frame
    assert window.doc.undo_stack.count() == 0  # scrubbing is not an edit
    after = viewport_image(window)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    assert region_difference(before, after, marks["chin"]) < 1.0


def test_transport_keys_step_jump_and_play(window, qtbot):
    panel = window.timeline_panel
    panel.view.setFocus()
    qtbot.keyClick(panel.view, Qt.Key.Key_Right)
    qtbot.keyClick(panel.view, Qt.Key.Key_Right)
    assert window.doc.frame == 2
    qtbot.keyClick(panel.view, Qt.Key.Key_Left)
    assert window.doc.frame == 1
    qtbot.keyClick(panel.view, Qt.Key.Key_End)
    assert window.doc.frame == window.doc.project.timeline.end
    qtbot.keyClick(panel.view, Qt.Key.Key_Home)
    assert window.doc.frame == 0
    qtbot.keyClick(panel.view, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert window.doc.frame == window.doc.project.timeline.end
    began = time.perf_counter()
    qtbot.keyClick(panel.view, Qt.Key.Key_Space)  # from the end: starts again at the top
    assert panel.player.playing
    qtbot.wait(600)
    qtbot.keyClick(panel.view, Qt.Key.Key_Space)
    elapsed = time.perf_counter() - began
    assert not panel.player.playing
    # real time at 24 fps, however slow each frame was to draw (slow frames are skipped)
    assert 4 <= window.doc.frame <= elapsed * 24 + 1


def test_playback_loops_at_the_end(window, qtbot):
    timeline = window.doc.project.timeline
    window.doc.show_frame(timeline.end - 2)
    player = window.timeline_panel.player
    player.loop = True
    player.play()
    qtbot.waitUntil(lambda: window.doc.frame < timeline.end - 2, timeout=3000)
    player.stop()
    assert timeline.start <= window.doc.frame < timeline.end - 2


def test_t1_linked_activations_follow_the_pose(window, qtbot):
    doc = window.doc
    doc.set_view(technique="t1")
    areas = [a.name for a in doc.project.influence.areas]
    right, left = areas.index("forehead right"), areas.index("forehead left")
    marks = viewport_marks(window)
    doc.show_frame(72)  # surprise starts rising
    neutral = viewport_image(window)
    assert doc.activations()[[right, left]] == pytest.approx([0.0, 0.0])
    doc.show_frame(78)  # half-way, cosine
    assert doc.activations()[[right, left]] == pytest.approx([0.5, 0.5], abs=1e-6)
    doc.show_frame(90)
    assert doc.activations()[[right, left]] == pytest.approx([1.0, 1.0])
    full = viewport_image(window)
    assert region_difference(neutral, full, marks["forehead left"]) > 2.0
    # the curve view computes the same activations for every frame at once
    frames = np.array([0.0, 6, 72, 78, 90, 130])
    _, act = activation_curves(doc.project, frames, doc.pose_weights)
    for frame, row in zip(frames, act, strict=True):
        weights = doc.project.timeline.weights_at(frame)
        assert row == pytest.approx(doc.project.influence.activations(weights))


def test_delete_copy_paste_and_sequence_all_poses_undo(blank, qtbot):
    panel = blank.timeline_panel
    click_track(qtbot, panel, "squeeze", 10, 0.0)
    click_track(qtbot, panel, "squeeze", 20, 1.0)
    panel.view.setFocus()
    panel._select({("squeeze", 0), ("squeeze", 1)})
    qtbot.keyClick(panel.view, Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier)
    blank.doc.show_frame(40)
    qtbot.keyClick(panel.view, Qt.Key.Key_V, Qt.KeyboardModifier.ControlModifier)
    assert [k[:2] for k in keys(blank, "squeeze")] == [(10, 0), (20, 1), (40, 0), (50, 1),
                                                       (96, 0)]
    assert panel.selection == {("squeeze", 2), ("squeeze", 3)}
    qtbot.keyClick(panel.view, Qt.Key.Key_Delete)
    assert [k[:2] for k in keys(blank, "squeeze")] == [(10, 0), (20, 1), (96, 0)]
    blank.doc.undo_stack.undo()
    assert len(keys(blank, "squeeze")) == 5
    qtbot.mouseClick(panel.sequence, Qt.MouseButton.LeftButton)
    timeline = blank.doc.project.timeline
    assert [t.pose for t in timeline.tracks] == [p.name for p in blank.doc.project.poses]
    assert timeline.end == 5 * 36
    assert panel.end.value() == 5 * 36
    blank.doc.undo_stack.undo()
    assert len(keys(blank, "squeeze")) == 5 and timeline.end == 96
    # frame rate and range are edits too
    panel.fps.setValue(30.0)
    assert timeline.fps == 30.0
    blank.doc.undo_stack.undo()
    assert timeline.fps == 24.0 and panel.fps.value() == 24.0


def test_a_blocked_out_animation_saves_and_reopens(blank, qtbot, tmp_path):
    """The issue's 'done when': surprise → squeeze → frown over 4 seconds, saved and reopened."""
    panel = blank.timeline_panel
    panel.end.setValue(96)
    for pose, peak in (("surprise", 16), ("squeeze", 48), ("frown", 80)):
        for frame, value in ((peak - 16, 0.0), (peak, 1.0), (peak + 16, 0.0)):
            click_track(qtbot, panel, pose, frame, value)
    timeline = blank.doc.project.timeline
    blank.doc.show_frame(48)
    assert blank.doc.pose_weights == {"surprise": 0.0, "squeeze": 1.0, "frown": 0.0,
                                      **{p: w for p, w in blank.doc.pose_weights.items()
                                         if p not in ("surprise", "squeeze", "frown")}}
    path = tmp_path / "blocked.wrinkle"
    assert blank.save_to(path)
    assert load_project(path).timeline.to_dict() == timeline.to_dict()
    saved = timeline.to_dict()
    assert blank.open_path(path)
    assert blank.doc.project.timeline.to_dict() == saved
    # nine keys clicked, and the ways back to 0 at the range's end of the two poses whose last
    # click was not on it
    assert len(blank.timeline_panel.keys_item.data) == 11
    assert blank.timeline_panel.end.value() == 96


def test_export_gif_and_frames_from_the_window(window, qtbot, tmp_path):
    dialog = ExportDialog(window)
    assert dialog.start.value() == 0 and dialog.end.value() == window.doc.project.timeline.end
    dialog.close()
    gif = tmp_path / "surprise.gif"
    assert export_animation(window, ExportOptions("gif", gif, 120, 90, "t2", 72, 84, 4))
    with Image.open(gif) as image:
        assert image.n_frames == 4 and image.size == (120, 90)
    folder = tmp_path / "frames"
    assert export_animation(window, ExportOptions("frames", folder, 96, 72, "t1", 0, 8, 4))
    assert sorted(p.name for p in folder.iterdir()) == [
        "frame_0000.png", "frame_0004.png", "frame_0008.png"]
    # the viewport still draws with its own context afterwards
    drawn = window.viewport.frames_rendered
    window.doc.show_frame(90)
    qtbot.waitUntil(lambda: window.viewport.frames_rendered > drawn, timeout=5000)
    assert viewport_image(window).std() > 10


def test_cancelling_the_export_stops_it_and_writes_no_gif(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QProgressDialog

    calls = []

    def cancelled_after_two(self) -> bool:
        calls.append(1)
        return len(calls) > 2

    monkeypatch.setattr(QProgressDialog, "wasCanceled", cancelled_after_two)
    gif = tmp_path / "never.gif"
    assert not export_animation(window, ExportOptions("gif", gif, 64, 48, "t2", 0, 40, 1))
    assert not gif.exists()
    calls.clear()
    frames = tmp_path / "some"
    assert not export_animation(window, ExportOptions("frames", frames, 64, 48, "t2", 0, 40, 1))
    assert 0 < len(list(frames.iterdir())) < 41  # what was rendered before Cancel stays
