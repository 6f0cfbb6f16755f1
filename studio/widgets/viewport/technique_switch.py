"""The viewport's technique label as a switch: a click offers the techniques in a menu.

Why: the studio opens in technique 2, and a person painting a technique-1 area saw nothing on
the face until they found the Shading panel's combo. The label in the picture's corner is where
they look; as in Blender's viewport header, it is the control. The menu lists what the Shading
panel's Technique combo lists (one list, ``TECHNIQUE_CHOICES``) and the choice is the same view
change.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QMouseEvent
from PySide6.QtWidgets import QLabel, QMenu, QWidget

from studio.widgets.document import Document
from studio.widgets.viewport.techniques import TECHNIQUE_CHOICES, choose_technique

STYLE = ("QLabel {{ color: #d8d8d8; background: rgba(20,20,24,{alpha}); padding: 3px 7px;"
         " border-radius: 3px; }}")


class TechniqueSwitch(QLabel):
    """The single view's "Technique N ▾" label; in the split view a plain label."""

    def __init__(self, document: Document, parent: QWidget) -> None:
        super().__init__(parent)
        self.doc = document
        self.menu = QMenu(self)
        for text, key in TECHNIQUE_CHOICES:
            action = QAction(text, self.menu)
            action.setCheckable(True)
            action.setData(key)
            action.triggered.connect(lambda _=False, k=key: choose_technique(document, k))
            self.menu.addAction(action)
        self.setStyleSheet(STYLE.format(alpha=150))
        self.set_switching(True)

    def set_switching(self, on: bool) -> None:
        """A switch in the single view; in the split view clicks go through to the face."""
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents, not on)
        self.setCursor(Qt.CursorShape.PointingHandCursor if on else Qt.CursorShape.ArrowCursor)
        self.setToolTip("Click to choose the technique shown (also Shading ▸ Technique)"
                        if on else "")

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton:
            return super().mousePressEvent(event)
        view = self.doc.view
        current = "split" if view.split else view.technique
        for action in self.menu.actions():
            action.setChecked(action.data() == current)
        self.menu.popup(self.mapToGlobal(self.rect().bottomLeft()))
        event.accept()
