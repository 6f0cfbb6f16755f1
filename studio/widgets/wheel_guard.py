"""The wheel scrolls a panel; it changes a field only when that field has the focus.

Why: Qt's spin boxes, combo boxes and sliders take the wheel whenever the pointer is over them,
so a person scrolling a long panel edits whatever field passes under the pointer (a painted
cone angle, an activation, six Ctrl+Z later). Blender and most tools let the wheel change a
field only once it was clicked. One filter on the application does it for every panel, rows a
panel makes later included: an unfocused field leaves the wheel to the scroll area around it,
which scrolls. (It is handed on here rather than left to Qt's propagation, which only carries
the wheel of a real device, not one an accessibility tool or a test sends.)
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QScrollBar,
    QWidget,
)

FIELDS = (QAbstractSpinBox, QComboBox, QAbstractSlider)


class WheelGuard(QObject):
    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() != QEvent.Type.Wheel or not isinstance(watched, FIELDS):
            return False
        if isinstance(watched, QScrollBar) or _focused(watched):
            return False
        area = _scroll_area(watched)
        if area is not None:
            bar = area.verticalScrollBar()
            QApplication.sendEvent(bar, event)  # the panel scrolls under the pointer
        return True  # the field never sees it


def _focused(widget: QWidget) -> bool:
    """The field, or its own line edit, has the keyboard focus."""
    focus = QApplication.focusWidget()
    return focus is not None and (focus is widget or widget.isAncestorOf(focus))


def _scroll_area(widget: QWidget) -> QAbstractScrollArea | None:
    parent = widget.parentWidget()
    while parent is not None and not isinstance(parent, QAbstractScrollArea):
        parent = parent.parentWidget()
    return parent


_installed: list[WheelGuard] = []


def install_wheel_guard() -> None:
    """Guard every field of the application (once per process)."""
    app = QApplication.instance()
    if app is None or _installed:
        return
    guard = WheelGuard(app)
    app.installEventFilter(guard)
    _installed.append(guard)
