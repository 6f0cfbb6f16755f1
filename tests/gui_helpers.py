"""Driving the studio window like a user, and reading what the viewport shows."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QSlider

from tests.regions import landmark_pixels


def qimage_to_array(image: QImage) -> np.ndarray:
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    w, h, stride = image.width(), image.height(), image.bytesPerLine()
    data = np.frombuffer(image.constBits(), np.uint8, count=stride * h).reshape(h, stride)
    return data[:, : w * 3].reshape(h, w, 3).copy()


def viewport_image(window) -> np.ndarray:
    return qimage_to_array(window.viewport.grabFramebuffer())


def viewport_marks(window) -> dict[str, tuple[int, int]]:
    vp = window.viewport
    ratio = vp.devicePixelRatioF()
    w, h = round(vp.width() * ratio), round(vp.height() * ratio)
    return landmark_pixels(window.doc.project, window.doc.camera, w, h)


def drag_slider(qtbot, slider: QSlider, fraction: float) -> None:
    """Press on the handle at the left end and drag it to ``fraction`` of the groove."""
    assert slider.value() == slider.minimum()
    y = slider.height() // 2
    start = QPoint(4, y)
    end = QPoint(int(4 + (slider.width() - 8) * fraction), y)
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=start)
    for i in range(1, 11):
        qtbot.mouseMove(slider, QPoint(start.x() + (end.x() - start.x()) * i // 10, y))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=end)
