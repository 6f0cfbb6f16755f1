"""The viewport tool that selects vertices for technique-2 authoring.

Left-button gestures: a click picks the vertex under the cursor (an exact ray cast against the
posed face), a drag draws a box or a lasso, or paints with a brush of adjustable radius. Shift
adds to the selection, Ctrl removes from it; otherwise the gesture replaces it (the brush adds).
The "cone" mode is the same brush painting the current area's per-vertex cone angle instead
(Ctrl paints it back to the area's own angle).
Navigation keeps Alt+left and the middle button. The work per gesture is a few vectorised numpy
passes over the projected vertices, computed once when the gesture starts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QMouseEvent

from studio.core.mesh import selection as sel
from studio.core.mesh.picking import nearest_corner, ray_triangles
from studio.widgets.commands import new_gesture
from studio.widgets.wdv.edits import set_cone_angles, set_selection

if TYPE_CHECKING:
    from studio.core.wrinkles.wdv import WdvArea
    from studio.render.wdv_overlay import WdvOverlay
    from studio.widgets.document import Document
    from studio.widgets.viewport.viewport import Viewport

MODES = ("click", "box", "lasso", "brush", "cone")
BRUSHES = ("brush", "cone")  # modes that paint under a circle while dragging
CLICK_PIXELS = 4  # a gesture that never leaves the press by this much is a click, not a drag
CLICK_RADIUS = 12  # with "select through", a click takes the nearest vertex this close


def gesture_mode(modifiers: Qt.KeyboardModifier, brush: bool = False) -> str:
    if modifiers & Qt.KeyboardModifier.ControlModifier:
        return sel.REMOVE
    if modifiers & Qt.KeyboardModifier.ShiftModifier or brush:
        return sel.ADD
    return sel.REPLACE


class SelectionHost(Protocol):
    """What the tool needs from its owner (``WdvTools``): the document, the overlay it draws
    the brush on, the current area and options, and picking against the posed face."""

    doc: Document
    overlay: WdvOverlay
    select_through: bool
    cone_paint_value: float

    @property
    def current_area(self) -> WdvArea | None: ...

    def screen_view(self) -> sel.ScreenView: ...

    def pick(self, x: float, y: float) -> int | None: ...

    def say(self, text: str) -> None: ...


def selection_words(text: str, before: np.ndarray, after: np.ndarray) -> str:
    """What a gesture selected, in words: "Box select: 40 vertices added · 143 of 2172
    selected" (a count a person checks against what they meant to catch)."""
    added = int((after & ~before).sum())
    removed = int((before & ~after).sum())
    change = ", ".join(part for part in (
        f"{added} vertices added" if added else "",
        f"{removed} removed" if removed else "") if part) or "nothing changed"
    return f"{text}: {change} · {int(after.sum())} of {len(after)} selected"


class SelectTool:
    """press / move / release from the viewport; reads and writes only through the document."""

    def __init__(self, tools: SelectionHost) -> None:
        self.tools = tools
        self.mode = "box"
        self.brush_radius = 30.0  # pixels
        self._start: QPointF | None = None
        self._path: list[tuple[float, float]] = []
        self._view: sel.ScreenView | None = None
        self._op = sel.REPLACE
        self._gesture: int | None = None
        self._reach = 0.0  # the farthest the pointer went from the press, in logical pixels

    # --- helpers -------------------------------------------------------------------------------
    def _apply(self, hits: np.ndarray, text: str, gesture: int | None = None) -> None:
        doc = self.tools.doc
        before = doc.selection.copy()
        set_selection(doc, sel.combine(doc.selection, hits, self._op), text, gesture)
        if gesture is None:  # a brush's dabs are said once, when it is let go
            self.tools.say(selection_words(text, before, doc.selection))

    # --- gestures ------------------------------------------------------------------------------
    def press(self, viewport: Viewport, event: QMouseEvent) -> None:
        if refused_in_split(self.tools.doc, viewport, "Vertex selection"):
            return
        self._start = event.position()
        self._reach = 0.0
        self._op = gesture_mode(event.modifiers(), brush=self.mode in BRUSHES)
        self._path = [device_pixel(viewport, event)]
        self._view = self.tools.screen_view()
        if self.mode in BRUSHES:
            self._gesture = new_gesture()
            self._brush(viewport, event)
        event.accept()

    def move(self, viewport: Viewport, event: QMouseEvent) -> None:
        x, y = device_pixel(viewport, event)
        overlay = self.tools.overlay
        if self._start is None:  # hovering: show the brush where it would paint
            if self.mode in BRUSHES:
                overlay.set_outline(circle(x, y, self.brush_radius), closed=True)
                viewport.update()
            return
        self._reach = max(self._reach, (event.position() - self._start).manhattanLength())
        if self.mode in BRUSHES:
            self._path.append((x, y))
            self._brush(viewport, event)
            overlay.set_outline(circle(x, y, self.brush_radius), closed=True)
        elif self.mode == "lasso":
            self._path.append((x, y))
            overlay.set_outline(np.array(self._path), closed=True)
        else:
            x0, y0 = self._path[0]
            overlay.set_outline(np.array([(x0, y0), (x, y0), (x, y), (x0, y)]), closed=True)
        viewport.update()

    def release(self, viewport: Viewport, event: QMouseEvent) -> None:
        if self._start is None:
            return
        x, y = device_pixel(viewport, event)
        # how far the gesture went, not where it ended: a lasso is closed where it began
        moved = max(self._reach, (event.position() - self._start).manhattanLength())
        view = self._view
        through = self.tools.select_through
        if self.mode in BRUSHES:
            pass  # every dab was applied while moving
        elif moved < CLICK_PIXELS or self.mode == "click":
            self._click(viewport, x, y)
        elif self.mode == "lasso":
            self._path.append((x, y))
            self._apply(view.select(sel.in_lasso(view.pixels, np.array(self._path)), through),
                        "Lasso select")
        else:
            self._apply(view.select(sel.in_box(view.pixels, self._path[0], (x, y)), through),
                        "Box select")
        self._start, self._view, self._gesture = None, None, None
        self.tools.overlay.set_outline(
            circle(x, y, self.brush_radius) if self.mode in BRUSHES else None, closed=True)
        viewport.update()

    def _brush(self, viewport: Viewport, event: QMouseEvent) -> None:
        x, y = device_pixel(viewport, event)
        view = self._view
        hits = view.select(sel.in_circle(view.pixels, (x, y), self.brush_radius),
                           self.tools.select_through)
        if self.mode == "cone":
            area = self.tools.current_area
            if area is not None:
                value = 0.0 if self._op == sel.REMOVE else self.tools.cone_paint_value
                set_cone_angles(self.tools.doc, area, hits, value, self._gesture)
            return
        self._apply(hits, "Brush select", self._gesture)

    def _click(self, viewport: Viewport, x: float, y: float) -> None:
        self._apply(self.pick_mask(x, y), "Click select")

    def pick_mask(self, x: float, y: float) -> np.ndarray:
        """The vertex under a pixel as a mask (empty when the click missed the face)."""
        tools = self.tools
        hits = np.zeros(tools.doc.project.mesh.n_welded, dtype=bool)
        vertex = tools.pick(x, y)
        if vertex is not None:
            hits[vertex] = True
        return hits

    def deactivate(self, viewport: Viewport) -> None:
        self._start, self._view = None, None
        self.tools.overlay.set_outline(None)
        viewport.update()


def device_pixel(viewport: Viewport, event: QMouseEvent) -> tuple[float, float]:
    """The event's position in framebuffer pixels (what the camera projects to)."""
    ratio = viewport.devicePixelRatioF()
    p = event.position()
    return p.x() * ratio, p.y() * ratio


def refused_in_split(doc: Document, viewport: Viewport, what: str) -> bool:
    """The split view draws each half with its own aspect, so screen gestures on vertices would
    miss: say so in the status bar and refuse (True)."""
    if not doc.view.split:
        return False
    window = viewport.window()
    if hasattr(window, "statusBar"):
        window.statusBar().showMessage(f"{what} works in the single view: turn the "
                                       "side-by-side split off", 5000)
    return True


def circle(x: float, y: float, radius: float, segments: int = 48) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    return np.c_[x + radius * np.cos(a), y + radius * np.sin(a)]


def pick_vertex(positions: np.ndarray, welded_triangles: np.ndarray, origin: np.ndarray,
                direction: np.ndarray) -> int | None:
    """Exact pick: the nearest corner of the first triangle the ray hits."""
    hit = ray_triangles(origin, direction, positions, welded_triangles)
    if hit is None:
        return None
    return int(welded_triangles[hit.triangle][nearest_corner(hit)])
