"""Keys that act on the panel under the mouse, as in Blender: Space plays the timeline the
pointer is over and F frames the face the pointer is over, with no click first to give that
panel the keyboard focus.

Why an application-wide event filter: a key goes to the focused widget (or to a shortcut of its
panel), which is wherever the user last clicked — a slider in the Poses panel, say — not where
they are looking. The filter sees the key first and hands it to the region under the mouse.
Typing keeps its keys: while a text field or a spin box has the focus, every key is its.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QLineEdit,
    QPlainTextEdit,
    QTextEdit,
    QWidget,
)

TEXT_ENTRY = (QLineEdit, QAbstractSpinBox, QTextEdit, QPlainTextEdit)
_PLAIN = (Qt.KeyboardModifier.NoModifier, Qt.KeyboardModifier.KeypadModifier)


def typing_into(widget: QWidget | None) -> bool:
    """Whether ``widget`` (the focus) takes typed text: its keys are never taken from it."""
    if isinstance(widget, QComboBox):
        return widget.isEditable()
    return isinstance(widget, TEXT_ENTRY)


class HoverKeys(QObject):
    """Regions of one window (a panel, the viewport), each with keys it answers while the
    mouse is over it, whatever has the keyboard focus."""

    def __init__(self, window: QWidget) -> None:
        super().__init__(window)
        self.window = window
        self._regions: list[tuple[QWidget, dict[int, Callable[[], None]]]] = []
        self._press_taken: int | None = None  # a key acted on at its shortcut override
        QApplication.instance().installEventFilter(self)

    def add(self, region: QWidget, keys: dict[Qt.Key, Callable[[], None]]) -> None:
        self._regions.append((region, {int(k): slot for k, slot in keys.items()}))

    def slot_for(self, event: QKeyEvent) -> Callable[[], None] | None:
        """What the key does in the region under the mouse; None when it is not ours to take
        (a modifier held, typing into a field, a dialog or menu open, another window)."""
        if event.modifiers() not in _PLAIN or event.isAutoRepeat():
            return None
        if QApplication.activeModalWidget() or QApplication.activePopupWidget():
            return None
        if not self.window.isActiveWindow() or typing_into(QApplication.focusWidget()):
            return None
        for region, keys in self._regions:
            slot = keys.get(event.key())
            if slot is not None and region.isVisible() and region.underMouse():
                return slot
        return None

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        kind = event.type()
        if kind == QEvent.Type.ShortcutOverride:
            slot = self.slot_for(event)
            if slot is None:
                return False
            # accepted: no shortcut of the focused panel fires; the key press that follows is
            # ours too and is dropped
            event.accept()
            self._press_taken = event.key()
            slot()
            return True
        if kind == QEvent.Type.KeyPress:
            if self._press_taken is not None and event.key() == self._press_taken:
                self._press_taken = None
                return True
            self._press_taken = None
            slot = self.slot_for(event)
            if slot is None:
                return False
            slot()
            return True
        if kind == QEvent.Type.KeyRelease:
            self._press_taken = None  # its press never came (the focus went): forget it
        return False


def install_hover_keys(window: QWidget) -> HoverKeys:
    """The window's hover keys (one filter per window, made on first use)."""
    hover = getattr(window, "hover_keys", None)
    if hover is None:
        hover = HoverKeys(window)
        window.hover_keys = hover
    return hover
