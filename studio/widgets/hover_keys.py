"""Keys that act on the panel under the mouse, as in Blender: Space plays the timeline the
pointer is over, the arrows step its frames, Delete and Ctrl+C / Ctrl+V act on its keys, and F
frames the face the pointer is over, with no click first to give that panel the keyboard focus.

Why an application-wide event filter: a key goes to the focused widget (or to a shortcut of its
panel), which is wherever the user last clicked — a slider in the Poses panel, say — not where
they are looking. The filter sees the key first and hands it to the region under the mouse.
Typing keeps its keys: while a text field or a spin box has the focus, every key is its.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QKeyEvent, QKeySequence
from PySide6.QtWidgets import (
    QAbstractItemView,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QLineEdit,
    QPlainTextEdit,
    QTextEdit,
    QWidget,
)

TEXT_ENTRY = (QLineEdit, QAbstractSpinBox, QTextEdit, QPlainTextEdit)
#: Keys that act again while held (stepping frames); any other key acts once per press, so a
#: held Space does not toggle playing on and off
REPEATING = frozenset(int(k) for k in (Qt.Key.Key_Left, Qt.Key.Key_Right, Qt.Key.Key_Up,
                                       Qt.Key.Key_Down))
#: Keys a focused list, slider or drop-down moves through its items with: they stay with it
#: (the timeline gets them while the mouse is over it only when nothing of the kind is focused)
NAVIGATION = frozenset(int(k) for k in (
    Qt.Key.Key_Left, Qt.Key.Key_Right, Qt.Key.Key_Up, Qt.Key.Key_Down, Qt.Key.Key_Home,
    Qt.Key.Key_End, Qt.Key.Key_PageUp, Qt.Key.Key_PageDown, Qt.Key.Key_Delete,
    Qt.Key.Key_Backspace, Qt.Key.Key_C, Qt.Key.Key_V))
NAVIGATES = (QComboBox, QAbstractSlider, QAbstractItemView)
_MODIFIERS = (Qt.KeyboardModifier.ShiftModifier | Qt.KeyboardModifier.ControlModifier
              | Qt.KeyboardModifier.AltModifier | Qt.KeyboardModifier.MetaModifier)

Combo = tuple[int, int]  # (key, modifiers): keypad and other flags left out


def combo(key: Qt.Key | str) -> Combo:
    """``Qt.Key.Key_K`` or ``"Ctrl+C"`` as the (key, modifiers) an event is matched on."""
    if isinstance(key, str):
        first = QKeySequence(key)[0]
        return int(first.key().value), int(first.keyboardModifiers().value)
    return int(key.value if hasattr(key, "value") else key), 0


def event_combo(event: QKeyEvent) -> Combo:
    return int(event.key()), int((event.modifiers() & _MODIFIERS).value)


def typing_into(widget: QWidget | None) -> bool:
    """Whether ``widget`` (the focus) takes typed text: its keys are never taken from it."""
    if isinstance(widget, QComboBox):
        return widget.isEditable()
    return isinstance(widget, TEXT_ENTRY)


def navigating(widget: QWidget | None, key: int) -> bool:
    """Whether ``widget`` (the focus) moves through its items with ``key``: a drop-down's End,
    a slider's arrows, a list's Delete are its own, wherever the mouse rests."""
    return key in NAVIGATION and isinstance(widget, NAVIGATES)


class HoverKeys(QObject):
    """Regions of one window (a panel, the viewport), each with keys it answers while the
    mouse is over it, whatever has the keyboard focus."""

    def __init__(self, window: QWidget) -> None:
        super().__init__(window)
        self.window = window
        self._regions: list[tuple[QWidget, dict[Combo, Callable[[], None]]]] = []
        self._press_taken: int | None = None  # a key acted on at its shortcut override
        QApplication.instance().installEventFilter(self)

    def add(self, region: QWidget, keys: dict[Qt.Key | str, Callable[[], None]]) -> None:
        """Keys (``Qt.Key.Key_K`` or a sequence such as ``"Ctrl+C"``) for ``region``."""
        self._regions.append((region, {combo(k): slot for k, slot in keys.items()}))

    def slot_for(self, event: QKeyEvent) -> Callable[[], None] | None:
        """What the key does in the region under the mouse; None when it is not ours to take
        (typing into a field, a dialog or menu open, another window, a held key that does
        not repeat, or a key the region has no use for)."""
        if event.isAutoRepeat() and event.key() not in REPEATING:
            return None
        if QApplication.activeModalWidget() or QApplication.activePopupWidget():
            return None
        focus = QApplication.focusWidget()
        if not self.window.isActiveWindow() or typing_into(focus):
            return None
        pressed = event_combo(event)
        for region, keys in self._regions:
            slot = keys.get(pressed)
            if slot is not None and region.isVisible() and region.underMouse():
                if navigating(focus, pressed[0]) and not region.isAncestorOf(focus):
                    return None
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
