"""A small pyqtgraph plot of one link's response curve, whose handles the user drags.

x is the pose weight, y the response (both 0..1). A custom curve's points and a smooth step's
thresholds are handles: drag one to move it, double-click empty space to add a point, right-click
a point to remove it. The plot owns no data: it shows the curve it is given and emits
``edited(curve, gesture)`` with the curve an edit would make; the owner turns that into an undo
command and shows the result back. Every move of one drag carries the same gesture token, so the
drag is one undo step.

Mouse events are taken at the view rather than through pyqtgraph's scene: the scene rate-limits
moves and waits for a drag distance before it starts a drag, and a curve editor wants every
move — and the plot never pans or zooms.
"""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QPointF, Qt, Signal
from PySide6.QtGui import QContextMenuEvent, QMouseEvent
from PySide6.QtWidgets import QWidget

from studio.core.wrinkles import response_handles as edit
from studio.core.wrinkles.response import ResponseCurve
from studio.widgets.commands import new_gesture

REACH_PX = 9.0  # how near (in pixels) a press must be to grab a handle
SAMPLES = np.linspace(0.0, 1.0, 129)


class CurvePlot(pg.PlotWidget):
    edited = Signal(object, object)  # the new ResponseCurve, the gesture token (or None)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent, background=(30, 30, 34))
        self.curve = ResponseCurve()
        self._drag: int | None = None  # the handle being dragged
        self._gesture: int | None = None
        item = self.getPlotItem()
        item.setMenuEnabled(False)
        item.hideButtons()
        item.hideAxis("left")
        item.hideAxis("bottom")
        view = item.getViewBox()
        view.setMouseEnabled(False, False)
        view.setRange(xRange=(0.0, 1.0), yRange=(0.0, 1.0), padding=0.06)
        item.plot([0, 1, 1, 0, 0], [0, 0, 1, 1, 0], pen=pg.mkPen(90, 90, 96))  # the unit square
        item.plot([0, 1], [0, 1], pen=pg.mkPen(90, 90, 96, style=Qt.PenStyle.DashLine))
        self.line = item.plot(pen=pg.mkPen(255, 200, 40, width=2))
        self.points = pg.ScatterPlotItem(size=9, pen=pg.mkPen(20, 20, 20),
                                         brush=pg.mkBrush(255, 255, 255))
        item.addItem(self.points)
        self.setFixedHeight(110)
        self.setToolTip("x: pose weight, y: response. Drag a point (custom) or a threshold "
                        "(smooth step); double-click adds a point, right-click removes one")

    # --- showing -------------------------------------------------------------------------------
    def show_curve(self, curve: ResponseCurve) -> None:
        self.curve = curve
        xs = np.union1d(SAMPLES, [x for x, _ in curve.points])
        self.line.setData(xs, curve.evaluate(xs))
        handles = edit.handles(curve)
        self.points.setData([x for x, _ in handles], [y for _, y in handles])

    # --- the mouse -----------------------------------------------------------------------------
    def _at(self, event: QMouseEvent) -> tuple[float, float]:
        """The event's place in (weight, response) coordinates."""
        point = self.getViewBox().mapSceneToView(self.mapToScene(event.position().toPoint()))
        return point.x(), point.y()

    def _handle_at(self, x: float, y: float) -> int | None:
        px, py = self.getViewBox().viewPixelSize()
        return edit.nearest(self.curve, x, y, REACH_PX * px, REACH_PX * py)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        x, y = self._at(event)
        index = self._handle_at(x, y)
        if index is not None and event.button() == Qt.MouseButton.LeftButton:
            self._drag, self._gesture = index, new_gesture()
        elif index is not None and event.button() == Qt.MouseButton.RightButton:
            self.edited.emit(edit.removed(self.curve, index), None)
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._drag is not None:
            self.edited.emit(edit.moved(self.curve, self._drag, *self._at(event)), self._gesture)
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        self._drag = self._gesture = None
        event.accept()

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        x, y = self._at(event)
        if event.button() == Qt.MouseButton.LeftButton and self._handle_at(x, y) is None:
            self.edited.emit(edit.added(self.curve, x, y), None)
        event.accept()

    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        event.accept()  # right-click removes a point; no menu

    def handle_position(self, index: int) -> QPointF:
        """Where handle ``index`` is drawn, in viewport pixels (for tests and tool tips)."""
        x, y = edit.handles(self.curve)[index]
        return self.mapFromScene(self.getViewBox().mapViewToScene(QPointF(x, y))).toPointF()
