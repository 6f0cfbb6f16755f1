"""The UV canvas's view: zoom (wheel, around the cursor), pan (middle-drag or Space+left-drag),
F to fit, [ and ] for the brush size, X for the eraser, and painting with the mouse or a pen
(its pressure scales each dab).

Why its own module: it turns gestures into paint sessions and view moves; what is drawn is the
canvas's (``uv_canvas.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QKeyEvent, QMouseEvent, QTabletEvent, QWheelEvent
from PySide6.QtWidgets import QGraphicsView

from studio.widgets.paint.edits import PaintSession

if TYPE_CHECKING:
    from studio.widgets.paint.hosts import CanvasHost


class PaintView(QGraphicsView):
    """The canvas itself: navigation, the brush cursor and painting."""

    def __init__(self, canvas: CanvasHost) -> None:
        super().__init__(canvas.scene)
        self.canvas = canvas
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.AnchorUnderMouse)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.MinimalViewportUpdate)
        self.setBackgroundBrush(QColor(38, 38, 42))
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setCursor(Qt.CursorShape.CrossCursor)
        self._pan: QPointF | None = None
        self._space = False
        self._session: PaintSession | None = None
        self._fitted = True  # until the user zooms or pans

    # navigation
    def fit(self) -> None:
        """The chosen UV tile (or the whole UV square) in view; it stays fitted on resize until
        the user zooms or pans."""
        rect = self.canvas.tile_rect()
        margin = max(rect.width(), rect.height()) / 128.0
        self.fitInView(rect.adjusted(-margin, -margin, margin, margin),
                       Qt.AspectRatioMode.KeepAspectRatio)
        self._fitted = True

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self._fitted:
            self.fit()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        if self._fitted:
            self.fit()

    def wheelEvent(self, event: QWheelEvent) -> None:
        steps = event.angleDelta().y() / 120.0
        factor = 1.2 ** steps
        scale = self.transform().m11() * factor
        if 0.02 < scale < 64.0:
            self.scale(factor, factor)
            self._fitted = False
        self.canvas.update_cursor(self.mapToScene(event.position().toPoint()))

    def _start_pan(self, event: QMouseEvent) -> None:
        self._pan = event.position()
        self._fitted = False
        self.setCursor(Qt.CursorShape.ClosedHandCursor)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        button = event.button()
        if button == Qt.MouseButton.MiddleButton or (
                button == Qt.MouseButton.LeftButton and self._space):
            self._start_pan(event)
        elif button == Qt.MouseButton.LeftButton:
            self._begin(event.position(), 1.0)
        else:
            super().mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._pan is not None:
            delta = event.position() - self._pan
            self._pan = event.position()
            h, v = self.horizontalScrollBar(), self.verticalScrollBar()
            h.setValue(h.value() - round(delta.x()))
            v.setValue(v.value() - round(delta.y()))
            return
        self.canvas.update_cursor(self.mapToScene(event.position().toPoint()))
        if self._session is not None:
            self._continue(event.position(), 1.0)

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if self._pan is not None and event.button() in (Qt.MouseButton.MiddleButton,
                                                         Qt.MouseButton.LeftButton):
            self._pan = None
            self.setCursor(Qt.CursorShape.OpenHandCursor if self._space
                           else Qt.CursorShape.CrossCursor)
        elif event.button() == Qt.MouseButton.LeftButton:
            self._finish()

    def tabletEvent(self, event: QTabletEvent) -> None:
        """Pen input: the same stroke, each dab scaled by the pen's pressure."""
        kind = event.type()
        pressure = float(event.pressure())
        if kind == QTabletEvent.Type.TabletPress and not self._space:
            self._begin(event.position(), pressure)
        elif kind == QTabletEvent.Type.TabletMove:
            self.canvas.update_cursor(self.mapToScene(event.position().toPoint()))
            if self._session is not None:
                self._continue(event.position(), pressure)
        elif kind == QTabletEvent.Type.TabletRelease:
            self._finish()
        event.accept()

    def keyPressEvent(self, event: QKeyEvent) -> None:
        key = event.key()
        if key == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = True
            self.setCursor(Qt.CursorShape.OpenHandCursor)
        elif key == Qt.Key.Key_F:
            self.fit()
        elif key in (Qt.Key.Key_BracketLeft, Qt.Key.Key_BracketRight):
            self.canvas.state.scale_radius(0.8 if key == Qt.Key.Key_BracketLeft else 1.25)
        elif key == Qt.Key.Key_X:
            self.canvas.state.set_erase(not self.canvas.state.brush.erase)
        else:
            super().keyPressEvent(event)

    def keyReleaseEvent(self, event: QKeyEvent) -> None:
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
            if self._pan is None:
                self.setCursor(Qt.CursorShape.CrossCursor)
        else:
            super().keyReleaseEvent(event)

    # painting
    def _begin(self, pos: QPointF, pressure: float) -> None:
        state = self.canvas.state
        if state.active < 0 or state.active >= len(self.canvas.doc.project.influence.areas):
            self.canvas.hint.setText("Add or select an area in the Areas panel to paint.")
            return
        self._session = PaintSession(self.canvas.doc, state.active, state.brush,
                                     state.stroke_mirror(self.canvas.doc.project.mesh))
        p = self.mapToScene(pos.toPoint())
        self._session.jump(p.x(), p.y(), pressure)
        self.canvas.previewing.emit(state.active)  # the face shows what the mask reveals

    def _continue(self, pos: QPointF, pressure: float) -> None:
        p = self.mapToScene(pos.toPoint())
        self._session.to(p.x(), p.y(), pressure)

    def _finish(self) -> None:
        if self._session is not None:
            self._session.end()
            self._session = None
            self.canvas.previewing.emit(-1)
