"""Driving the studio window like a user, and reading what the viewport shows."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, Qt, QTimer
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QApplication, QDialogButtonBox, QSlider

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


def bring_forward(widget) -> None:
    """Raise the dock a widget sits in, as a person clicks its tab first: panels share tabs,
    and the layout a window restores may have another one in front."""
    from PySide6.QtWidgets import QDockWidget

    parent = widget.parentWidget()
    while parent is not None and not isinstance(parent, QDockWidget):
        parent = parent.parentWidget()
    if parent is not None:
        parent.show()
        parent.raise_()
        QApplication.processEvents()


def drag_slider(qtbot, slider: QSlider, fraction: float) -> None:
    """Press on the handle at the left end and drag it to ``fraction`` of the groove."""
    bring_forward(slider)
    assert slider.value() == slider.minimum()
    y = slider.height() // 2
    start = QPoint(4, y)
    end = QPoint(int(4 + (slider.width() - 8) * fraction), y)
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=start)
    for i in range(1, 11):
        qtbot.mouseMove(slider, QPoint(start.x() + (end.x() - start.x()) * i // 10, y))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=end)


def fill_export_dialog(qtbot, seen: list, folder, presses: list[Qt.Key]) -> None:
    """When the dialog opens: pick the layout with the keyboard, type the folder, click Export."""
    def act() -> None:
        from studio.widgets.engine_export_dialog import EngineExportDialog

        dialog = QApplication.activeModalWidget()
        assert isinstance(dialog, EngineExportDialog)
        seen.append([dialog.layout_choice.itemText(i)
                     for i in range(dialog.layout_choice.count())])
        dialog.layout_choice.setFocus()
        for key in presses:
            qtbot.keyClick(dialog.layout_choice, key)
        qtbot.mouseClick(dialog.folder, Qt.MouseButton.LeftButton)
        qtbot.keyClick(dialog.folder, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(dialog.folder, str(folder))
        export = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
        qtbot.mouseClick(export, Qt.MouseButton.LeftButton)

    QTimer.singleShot(0, act)
