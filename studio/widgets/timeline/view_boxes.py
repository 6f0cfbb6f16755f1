"""The timeline's three time views and what a mouse does in each (pyqtgraph view boxes).

Why their own module: they only turn pyqtgraph's mouse events into the panel's calls (scrub,
click a row, drag a key, drag a row edge); what those mean is ``track_model``'s and the panel's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

if TYPE_CHECKING:
    from studio.widgets.timeline.host import TimelineHost


class TimeViewBox(pg.ViewBox):
    """A time view: the wheel zooms time, a middle or right drag pans it (never before the first
    frame: see ``TimelinePanel.frame_all_time``), Shift+wheel scrolls the track rows."""

    def __init__(self, panel: TimelineHost) -> None:
        super().__init__(enableMenu=False)
        self.panel = panel
        self.setMouseEnabled(x=True, y=False)

    def wheelEvent(self, ev, axis=None) -> None:
        """Shift+wheel scrolls the rows (when they do not all fit); the wheel zooms time."""
        if ev.modifiers() & Qt.KeyboardModifier.ShiftModifier and self.panel.rows.isVisible():
            ev.accept()
            steps = -int(np.sign(ev.delta())) if ev.delta() else 0
            self.panel.rows.setValue(self.panel.rows.value() + steps)
            return
        super().wheelEvent(ev, 0)


class ScrubViewBox(TimeViewBox):
    """The ruler and the curves: a left click or drag moves the playhead (scrubs), as on
    Blender's timeline; it never pans the view."""

    def mouseClickEvent(self, ev) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseClickEvent(ev)
            return
        ev.accept()
        self.panel.player.stop()
        self.panel.scrub_to(self.mapSceneToView(ev.scenePos()).x())

    def mouseDragEvent(self, ev, axis=None) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseDragEvent(ev, 0)
            return
        ev.accept()
        if ev.isStart():
            self.panel.player.stop()
        self.panel.scrub_to(self.mapSceneToView(ev.scenePos()).x())


class TrackViewBox(TimeViewBox):
    """Left button edits keys and scrubs; a left drag in the names' column sets the rows'
    height (the row edge nearest the press follows the pointer)."""

    def mouseClickEvent(self, ev) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseClickEvent(ev)
            return
        ev.accept()
        if not self.sceneBoundingRect().contains(ev.scenePos()):
            return  # a click on the names' column (forwarded by the axis): nothing to add
        self.panel.track_clicked(self.mapSceneToView(ev.scenePos()), ev.modifiers())

    def hoverEvent(self, ev) -> None:
        """The weight a click would set, shown beside the pointer before the click."""
        if ev.isExit():
            self.panel.show_weight_under(None)
        else:
            self.panel.show_weight_under(self.mapSceneToView(ev.scenePos()))

    def mouseDragEvent(self, ev, axis=None) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseDragEvent(ev, 0)
            return
        ev.accept()
        if axis == 1:  # the names' column: resize the rows
            if ev.isStart():
                self.panel.row_drag_started(self.mapSceneToView(ev.buttonDownScenePos()).y())
            self.panel.row_drag_moved(ev.scenePos().y() - self.sceneBoundingRect().top())
            return
        if ev.isStart():
            self.panel.drag_started(self.mapSceneToView(ev.buttonDownScenePos()))
        self.panel.drag_moved(self.mapSceneToView(ev.scenePos()))
        if ev.isFinish():
            self.panel.drag_finished()
