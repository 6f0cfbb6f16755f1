"""The face-paint brush's cursor over the 3D viewport, drawn with QPainter on a transparent layer.

Why a child widget and not a GL overlay: the viewport re-renders the face whenever it repaints,
but a child widget's repaint is composed over the viewport's last frame, so following the mouse
redraws only the cursor's rectangle and never the face. The paint tool computes the rings (the
brush circle carried onto the surface, projected to widget pixels); this layer only draws them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, QRect, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPaintEvent, QPen, QPolygonF
from PySide6.QtWidgets import QWidget


@dataclass
class Ring:
    """One footprint in widget pixels: its edge, where full strength ends, and whether it is the
    mirror image (drawn dashed)."""

    outer: np.ndarray  # (N, 2)
    inner: np.ndarray | None  # (N, 2), or None for a brush without a hard core
    mirrored: bool = False

    def bounds(self) -> QRectF:
        lo, hi = self.outer.min(axis=0), self.outer.max(axis=0)
        return QRectF(float(lo[0]), float(lo[1]), float(hi[0] - lo[0]), float(hi[1] - lo[1]))


def polygon(points: np.ndarray) -> QPolygonF:
    return QPolygonF([QPointF(x, y) for x, y in points.tolist()])  # a few dozen corners


class BrushCursor(QWidget):
    """Covers its parent (the viewport), lets every mouse event through, draws the rings."""

    left = Signal()  # the mouse left the viewport: the rings are gone

    def __init__(self, viewport: QWidget) -> None:
        super().__init__(viewport)
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.setAttribute(Qt.WidgetAttribute.WA_NoSystemBackground)
        self.rings: list[Ring] = []
        self.setGeometry(viewport.rect())
        viewport.installEventFilter(self)
        self.show()
        self.raise_()

    def set_rings(self, rings: list[Ring]) -> None:
        """Show these rings (none: hidden); repaints only where the old and new ones lie."""
        dirty = self._bounds()
        self.rings = list(rings)
        dirty = dirty.united(self._bounds())
        if not dirty.isEmpty():
            self.update(dirty)

    def _bounds(self) -> QRect:
        rect = QRectF()
        for ring in self.rings:
            rect = rect.united(ring.bounds())
        return rect.toAlignedRect().adjusted(-3, -3, 3, 3) if not rect.isNull() else QRect()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        kind = event.type()
        if kind == QEvent.Type.Resize:
            self.setGeometry(self.parentWidget().rect())
        elif kind == QEvent.Type.Leave:
            self.set_rings([])
            self.left.emit()
        return False

    def paintEvent(self, event: QPaintEvent) -> None:
        if not self.rings:
            return
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        shadow = QPen(QColor(0, 0, 0, 150), 3.0)
        for ring in self.rings:
            outer = polygon(ring.outer)
            edge = QPen(QColor(255, 255, 255, 170 if ring.mirrored else 235), 1.5)
            if ring.mirrored:
                edge.setStyle(Qt.PenStyle.DashLine)
            # a dark halo under a light line: readable on pale skin and on the dark background
            for pen in (shadow, edge):
                painter.setPen(pen)
                painter.drawPolygon(outer)
            if ring.inner is not None:
                painter.setPen(QPen(QColor(255, 255, 255, 110), 1.0, Qt.PenStyle.DotLine))
                painter.drawPolygon(polygon(ring.inner))
        painter.end()
