"""Hover-to-act keys, as in Blender: Space, K, the arrows, Home/End, Delete and Ctrl+C/V act on
the timeline and F on the viewport while the mouse is over them, whatever was clicked last; a
focused text field keeps every key."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QApplication

from tests.gui_helpers import drag_slider
from tests.test_timeline_gui import click_track, keys


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1200, 900)


def hover(qtbot, widget, pos: QPoint | None = None) -> None:
    """Move the mouse over ``widget`` (no button), as a hand on the way to the keyboard."""
    pos = pos if pos is not None else widget.rect().center()
    qtbot.mouseMove(widget, pos - QPoint(5, 5))
    qtbot.mouseMove(widget, pos)
    qtbot.wait(20)


def type_key(qtbot, key: Qt.Key, text: str = "") -> None:
    """Press a key as the keyboard does: it goes to whatever has the focus."""
    target = QApplication.focusWidget() or QApplication.activeWindow()
    if text:
        qtbot.keyClicks(target, text)
    else:
        qtbot.keyClick(target, key)


def click_ruler(qtbot, panel, frame: float) -> None:
    """A click on the time ruler at ``frame`` (it also gives the timeline the focus)."""
    ruler = panel.ruler.getViewBox()
    scene = ruler.mapViewToScene(ruler.mapSceneToView(ruler.sceneBoundingRect().center()))
    x = ruler.mapViewToScene(type(scene)(frame, 0.5)).x()
    qtbot.mouseClick(panel.view.viewport(), Qt.MouseButton.LeftButton,
                     pos=panel.view.mapFromScene(type(scene)(x, scene.y())))


def test_space_plays_the_timeline_under_the_mouse_while_the_viewport_has_the_focus(window, qtbot):
    """Red once: with the hover keys not installed (the ``hover.add(panel, …)`` line of
    timeline/tools.py removed) Space went to the focused viewport and nothing played."""
    panel = window.timeline_panel
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton,
                     pos=QPoint(10, window.viewport.height() - 10))
    assert QApplication.focusWidget() is window.viewport
    hover(qtbot, panel.view.viewport())
    type_key(qtbot, Qt.Key.Key_Space)
    assert panel.player.playing
    qtbot.waitUntil(lambda: window.doc.frame >= 3, timeout=3000)
    assert panel.frame_label.text().startswith(f"Frame {window.doc.frame:.0f}")
    type_key(qtbot, Qt.Key.Key_Space)
    assert not panel.player.playing
    assert QApplication.focusWidget() is window.viewport  # the focus never moved


def test_k_over_the_timeline_keys_the_pose_slider_just_moved(window, qtbot):
    """Red once: with ``poseEdited`` not connected to the timeline (timeline/tools.py) K keyed
    the first row, the one the timeline had as current, not the slider just moved."""
    panel = window.timeline_panel
    doc = window.doc
    click_ruler(qtbot, panel, 40)
    assert doc.frame == 40
    frown = window.pose_panel.pose_rows["frown"]
    drag_slider(qtbot, frown.slider, 0.6)
    moved = doc.pose_weights["frown"]
    assert 0.4 < moved < 0.8
    hover(qtbot, panel.view.viewport())
    before = keys(window, "frown")
    count = sum(len(t.keys) for t in doc.project.timeline.tracks)
    type_key(qtbot, Qt.Key.Key_K)
    assert before[0][0] > 40  # frown's keys come later: the track held 0 before them, and still
    # does from the range's start, up to the new key
    assert sorted(set(keys(window, "frown")) - set(before)) == [
        (0.0, 0.0, "cosine"), (40.0, pytest.approx(moved), "cosine")]
    assert sum(len(t.keys) for t in doc.project.timeline.tracks) == count + 2  # frown's only
    assert doc.pose_weights["frown"] == pytest.approx(moved)  # the face keeps what was set
    message = window.statusBar().currentMessage()
    assert "frown" in message and "40" in message and f"{moved:.2f}" in message
    # what is shown: the current-row marker spans frown's row, and frown's row is on screen
    row = panel.row_of("frown")
    assert panel.row_marker.isVisible() and panel.row_marker.getRegion() == (row, row + 1)
    assert "frown" in panel.visible_rows()


def test_f_over_the_viewport_frames_the_face_while_the_timeline_has_the_focus(window, qtbot):
    """Red once: with the viewport's ``hover.add`` removed (timeline/tools.py) F went to the
    focused timeline and the camera stayed turned; without its Space entry Space over the
    focused viewport played nothing."""
    vp = window.viewport
    centre = vp.rect().center()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.AltModifier, centre)
    for i in range(1, 11):
        qtbot.mouseMove(vp, centre + QPoint(12 * i, 4 * i))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.AltModifier,
                       centre + QPoint(120, 40))
    camera = window.doc.camera
    assert abs(camera.yaw) > 5
    # Space over the viewport plays, as in Blender's 3D view (red once without its entry)
    assert QApplication.focusWidget() is vp
    hover(qtbot, vp)
    type_key(qtbot, Qt.Key.Key_Space)
    assert window.timeline_panel.player.playing
    type_key(qtbot, Qt.Key.Key_Space)
    assert not window.timeline_panel.player.playing
    click_ruler(qtbot, window.timeline_panel, 10)
    assert window.timeline_panel.isAncestorOf(QApplication.focusWidget())
    hover(qtbot, vp)
    type_key(qtbot, Qt.Key.Key_F)
    assert (camera.yaw, camera.pitch) == (0.0, 0.0)
    assert window.timeline_panel.isAncestorOf(QApplication.focusWidget())


def test_a_focused_field_keeps_space_and_k_while_the_mouse_is_over_the_timeline(window, qtbot):
    """Red once: with ``typing_into`` answering False (hover_keys.py) the spin box lost its
    keys: Space played and K keyed."""
    panel = window.timeline_panel
    spin = panel.end
    qtbot.mouseClick(spin.lineEdit(), Qt.MouseButton.LeftButton)
    assert QApplication.focusWidget() in (spin, spin.lineEdit())
    hover(qtbot, panel.view.viewport())
    steps = window.doc.undo_stack.count()
    spin.selectAll()
    type_key(qtbot, Qt.Key.Key_K, "1 2k0")
    type_key(qtbot, Qt.Key.Key_Space)
    assert not panel.player.playing
    assert window.doc.undo_stack.count() == steps  # no key was added
    assert spin.lineEdit().text().replace(" ", "") in ("120", "12")  # digits reached the field
    type_key(qtbot, Qt.Key.Key_Return)
    assert window.doc.project.timeline.end in (120, 12)
    assert np.isfinite(window.doc.frame)


def test_a_focused_line_edit_keeps_space_and_k_while_the_mouse_is_over_the_timeline(
        open_window, sample, qtbot):
    """The Poses panel's filter (shown past eight poses) typed into with the mouse resting over
    the timeline. Red once: with ``typing_into`` answering False (hover_keys.py) the filter
    read "brow": its spaces and its k went to the timeline (play, key)."""
    from dataclasses import replace

    sample.poses = [*sample.poses, *(replace(p, name=f"{p.name} copy") for p in sample.poses)]
    window = open_window(sample)
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5000)
    panel = window.timeline_panel
    field = window.pose_panel.filter
    assert field.isVisible()
    qtbot.mouseClick(field, Qt.MouseButton.LeftButton)
    assert QApplication.focusWidget() is field
    hover(qtbot, panel.view.viewport())
    type_key(qtbot, Qt.Key.Key_K, "brow k")
    type_key(qtbot, Qt.Key.Key_Space)
    assert field.text() == "brow k "
    assert not panel.player.playing
    assert window.doc.undo_stack.count() == 0


def test_arrows_home_end_delete_and_copy_paste_act_on_the_timeline_under_the_mouse(
        open_window, sample, qtbot):
    """Blender's dope-sheet keys with the viewport focused and the mouse over the timeline.
    Red once: with only Space and K in the timeline's hover table (timeline/tools.py before)
    the arrows went to the focused viewport and the frame stayed put."""
    from studio.core.animation.timeline import Timeline

    sample.timeline = Timeline()
    window = open_window(sample)
    panel, doc = window.timeline_panel, window.doc
    timeline = doc.project.timeline
    click_track(qtbot, panel, "squeeze", 20, 0.8)  # a new key, selected
    assert [keys(window, "squeeze")[i][:2] for _, i in panel.selection] == [(20, 0.8)]
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton,
                     pos=QPoint(10, window.viewport.height() - 10))
    assert QApplication.focusWidget() is window.viewport
    hover(qtbot, panel.view.viewport())
    type_key(qtbot, Qt.Key.Key_Home)
    assert doc.frame == timeline.start
    type_key(qtbot, Qt.Key.Key_Right)
    type_key(qtbot, Qt.Key.Key_Right)
    type_key(qtbot, Qt.Key.Key_Left)
    assert doc.frame == timeline.start + 1
    qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert doc.frame == timeline.end
    qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier)
    type_key(qtbot, Qt.Key.Key_Home)
    for _ in range(40):  # held down: the arrow repeats
        type_key(qtbot, Qt.Key.Key_Right)
    assert doc.frame == timeline.start + 40
    before = keys(window, "squeeze")
    qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_V, Qt.KeyboardModifier.ControlModifier)
    pasted = sorted(set(keys(window, "squeeze")) - set(before))
    assert [k[:2] for k in pasted] == [(timeline.start + 40, pytest.approx(0.8))]
    type_key(qtbot, Qt.Key.Key_Delete)  # the pasted key is the selection now
    assert keys(window, "squeeze") == before
    assert QApplication.focusWidget() is window.viewport  # the focus never moved
    # a focused drop-down keeps its own End (red once, with ``navigating`` answering False)
    combo = window.shading_panel.technique
    combo.setFocus()
    hover(qtbot, panel.view.viewport())
    frame = doc.frame
    type_key(qtbot, Qt.Key.Key_End)
    assert combo.currentIndex() == combo.count() - 1 and doc.frame == frame
