"""What the parts of technique 1's panels ask of the widgets that hold them.

The Areas panel's rows (``area_row``) and links box (``area_links``) call back into the panel,
and the UV canvas's view (``paint_view``) into the canvas; the panel and the canvas import them
to build themselves. Declaring what the parts use here, as protocols, lets them name their
holder's type without importing it (no import cycle), and says in one place what a part may
ask of its holder.
"""

from __future__ import annotations

from typing import Protocol

from PySide6.QtCore import QPointF, QRectF, SignalInstance
from PySide6.QtWidgets import QGraphicsScene, QLabel

from studio.core.wrinkles.influence import InfluenceArea
from studio.widgets.document import Document
from studio.widgets.paint.paint_state import PaintState


class AreasHost(Protocol):
    """The Areas panel, as its rows and its links box see it."""

    doc: Document
    state: PaintState
    said: SignalInstance  # a line for the status bar

    def active_area(self) -> InfluenceArea | None: ...
    def auto_mask(self) -> None: ...
    def say_taken(self, name: str) -> None: ...


class CanvasHost(Protocol):
    """The UV canvas, as the view that turns gestures into strokes sees it."""

    doc: Document
    state: PaintState
    scene: QGraphicsScene
    hint: QLabel
    previewing: SignalInstance  # the area a stroke paints now, -1 once it ends

    def tile_rect(self) -> QRectF: ...
    def update_cursor(self, p: QPointF) -> None: ...
