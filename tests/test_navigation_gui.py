"""Viewport navigation with real mouse, wheel and key events, as in Blender: middle-drag
orbits, Shift+middle-drag pans, the wheel and Ctrl+middle-drag zoom, Alt+left-drag orbits on a
laptop, F frames the face — each checked on the camera and on the drawn image."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from tests.gui_helpers import viewport_image

NO = Qt.KeyboardModifier.NoModifier


def drag(qtbot, widget, button, modifiers, delta: QPoint, steps: int = 8) -> None:
    start = QPoint(widget.width() // 2, widget.height() // 2)
    qtbot.mousePress(widget, button, modifiers, pos=start)
    for i in range(1, steps + 1):
        qtbot.mouseMove(widget, start + delta * (i / steps))
    qtbot.mouseRelease(widget, button, modifiers, pos=start + delta)


def state(camera) -> tuple[float, float, np.ndarray, float]:
    return camera.yaw, camera.pitch, camera.target.copy(), camera.distance


def redrawn(window, qtbot) -> np.ndarray:
    drawn = window.viewport.frames_rendered
    qtbot.waitUntil(lambda: window.viewport.frames_rendered > drawn, timeout=10000)
    return viewport_image(window)


def test_orbit_pan_zoom_and_frame_with_the_mouse_and_keys(window, qtbot):
    vp, camera = window.viewport, window.doc.camera
    image = viewport_image(window)

    yaw, pitch, target, distance = state(camera)
    drag(qtbot, vp, Qt.MouseButton.MiddleButton, NO, QPoint(60, 0))
    assert camera.yaw != yaw  # orbit: the view turns around the target …
    np.testing.assert_array_equal(camera.target, target)  # … which stays
    assert camera.distance == distance
    orbited = redrawn(window, qtbot)
    assert np.abs(orbited.astype(int) - image).max() > 40

    yaw, pitch, target, distance = state(camera)
    drag(qtbot, vp, Qt.MouseButton.MiddleButton, Qt.KeyboardModifier.ShiftModifier,
         QPoint(50, 30))
    assert (camera.yaw, camera.pitch) == (yaw, pitch)  # pan: no turn …
    assert np.linalg.norm(camera.target - target) > 0.01 * distance  # … the target moves
    assert camera.distance == distance
    panned = redrawn(window, qtbot)
    assert np.abs(panned.astype(int) - orbited).max() > 40

    distance = camera.distance
    centre = QPointF(vp.width() / 2, vp.height() / 2)
    wheel = QWheelEvent(centre, vp.mapToGlobal(centre), QPoint(0, 0), QPoint(0, 120),
                        Qt.MouseButton.NoButton, NO, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(vp, wheel)  # one notch forward: closer
    assert camera.distance < distance
    distance = camera.distance
    drag(qtbot, vp, Qt.MouseButton.MiddleButton, Qt.KeyboardModifier.ControlModifier,
         QPoint(0, 40))
    assert camera.distance != distance and (camera.yaw, camera.pitch) == state(camera)[:2]

    yaw = camera.yaw
    drag(qtbot, vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.AltModifier, QPoint(-40, 0))
    assert camera.yaw != yaw  # Alt+left: orbit, for a laptop without a middle button

    vp.setFocus()
    qtbot.keyClick(vp, Qt.Key.Key_F)  # frame the face: back where a fresh window starts
    face = window.doc.face_frame()
    np.testing.assert_allclose(camera.target, np.mean(face.corners(), axis=0), atol=1e-9)
    qtbot.keyClick(vp, Qt.Key.Key_1, Qt.KeyboardModifier.KeypadModifier)
    framed = redrawn(window, qtbot)
    assert np.abs(framed.astype(int) - panned).max() > 40
