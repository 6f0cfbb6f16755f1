"""The UV canvas's own graphics items: an RGBA buffer repainted a rectangle at a time, and a
wireframe drawn in one call.

Why their own module: they know nothing of masks or documents, only pixels and lines.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QLineF, QRectF
from PySide6.QtGui import QColor, QImage, QPainter, QPen
from PySide6.QtWidgets import QGraphicsItem

from studio.widgets.paint.uv_canvas_model import rgb8


def to_qimage(rgb: np.ndarray) -> QImage:
    """An 8-bit RGB copy of a texture (16-bit maps are shown at 8 bits)."""
    rgb = rgb8(rgb)
    h, w = rgb.shape[:2]
    return QImage(rgb.data, w, h, 3 * w, QImage.Format.Format_RGB888).copy()


class BufferItem(QGraphicsItem):
    """An RGBA image in scene pixels whose rectangles can be rewritten and repainted alone."""

    def __init__(self, w: int, h: int) -> None:
        super().__init__()
        self.resize(w, h)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemUsesExtendedStyleOption)

    def resize(self, w: int, h: int) -> None:
        self.prepareGeometryChange()
        self.buffer = np.zeros((h, w, 4), np.uint8)  # premultiplied RGBA
        self.image = QImage(self.buffer.data, w, h, 4 * w,
                            QImage.Format.Format_RGBA8888_Premultiplied)

    def boundingRect(self) -> QRectF:
        return QRectF(0, 0, self.buffer.shape[1], self.buffer.shape[0])

    def paint(self, painter: QPainter, option, widget=None) -> None:
        rect = option.exposedRect.intersected(self.boundingRect()).toAlignedRect()
        if rect.isEmpty():
            return
        painter.drawImage(rect, self.image, rect)

    def write(self, x: int, y: int, rgba: np.ndarray) -> None:
        h, w = rgba.shape[:2]
        self.buffer[y:y + h, x:x + w] = rgba
        self.update(QRectF(x, y, w, h))


class LinesItem(QGraphicsItem):
    """The UV wireframe: one drawLines call per repaint.

    (Not a QPainterPath built edge by edge: thousands of binding calls per rebuild are slow, and
    with PySide6 6.12 on Python 3.11 every void-returning call drops a reference to None.)
    """

    def __init__(self, colour: QColor | None = None) -> None:
        super().__init__()
        self.lines: list[QLineF] = []
        self.rect = QRectF()
        self.pen = QPen(colour if colour is not None else QColor(255, 255, 255, 110))
        self.pen.setCosmetic(True)
        self.pen.setWidthF(0.8)

    def set_lines(self, segments: np.ndarray, rect: QRectF) -> None:
        """segments: (E, 2, 2) endpoints in scene pixels."""
        self.prepareGeometryChange()
        self.lines = [QLineF(ax, ay, bx, by) for (ax, ay), (bx, by) in segments.tolist()]
        self.rect = rect
        self.update()

    def boundingRect(self) -> QRectF:
        return self.rect

    def paint(self, painter: QPainter, option, widget=None) -> None:
        painter.setPen(self.pen)
        painter.drawLines(self.lines)
