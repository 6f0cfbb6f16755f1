"""A small square of an area's colour, for the lists and buttons of both techniques' panels.

Why its own module: the Areas panel and the Wrinkle vectors panel draw the same swatch.
"""

from __future__ import annotations

from PySide6.QtGui import QColor, QIcon, QPixmap


def swatch(colour: tuple[int, int, int], size: int = 14) -> QIcon:
    pixmap = QPixmap(size, size)
    pixmap.fill(QColor(*colour))
    return QIcon(pixmap)
