"""The Comb tool: drawing wrinkle directions on the face, as hair-grooming tools comb hair.

With a vector area current and vertices selected, a left-drag over the face bends the wrinkle
direction of the selected vertices under the brush toward the drag, projected onto each vertex's
tangent plane (studio/core/wrinkles/comb.py) on the face as it is drawn (posed), so the drawn
vectors land on the drag whatever the pose sliders show. Each mouse move is one dab, pushed as a
``VectorsCommand`` carrying the stroke's gesture token, so the vectors and the shading follow
the drag live and the whole stroke is one undo step. Combed vertices become authored.

The work per mouse move is vectorised: the screen view (pixels, visibility) and the area's
pose motion are computed once at the press; a dab is a circle test over the projected vertices
and the comb math over the few under the brush. Press C (or the panel's Comb button) to take
the tool, C again to leave it; S or B take the viewport from it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

import numpy as np
from PySide6.QtCore import QSignalBlocker, Qt, Signal
from PySide6.QtGui import QAction, QKeySequence, QMouseEvent
from PySide6.QtWidgets import QDoubleSpinBox, QFormLayout, QPushButton, QVBoxLayout, QWidget

from studio.core.mesh import selection as sel
from studio.core.wrinkles.comb import (
    CombBrush,
    comb_dab,
    combed_lengths,
    typical_length,
)
from studio.core.wrinkles.wdv import STILL_EPSILON
from studio.widgets.commands import new_gesture
from studio.widgets.wdv.edits import comb_directions
from studio.widgets.wdv.select_tool import (
    SelectionHost,
    circle,
    device_pixel,
    refused_in_split,
)

if TYPE_CHECKING:
    from studio.core.wrinkles.wdv import WdvArea
    from studio.widgets.viewport.viewport import Viewport

SPACING = 3.0  # device pixels the pointer moves between dabs: the stroke's direction is stable
SHORTCUT = "C"  # C for comb; free here (S selects, B paints), as in grooming tools' keymaps
HINT = ("Comb: drag over the selected vertices to lay their wrinkle directions along the drag "
        "(one undo step per stroke); C leaves the tool")


class CombHost(SelectionHost, Protocol):
    """What the comb needs from its owner (``WdvTools``) besides what selecting needs: the
    posed face as drawn, and its normals (cached there, refreshed when the pose changes)."""

    def posed(self) -> np.ndarray: ...

    def normals(self) -> np.ndarray: ...


class CombTool:
    """press / move / release from the viewport; changes the document only by undo commands."""

    def __init__(self, tools: CombHost) -> None:
        self.tools = tools
        self.brush = CombBrush()
        self.on_deactivate = None  # called when the viewport gives the mouse to another tool
        self._gesture: int | None = None
        self._view: sel.ScreenView | None = None
        self._last: tuple[float, float] | None = None
        self._combed: np.ndarray | None = None  # (W,) bool, the vertices this stroke changed

    def set_brush(self, **changes: float) -> None:
        self.brush = replace(self.brush, **changes)

    def _say(self, viewport: Viewport, text: str, ms: int = 5000) -> None:
        window = viewport.window()
        if hasattr(window, "statusBar"):
            window.statusBar().showMessage(text, ms)

    def _outline(self, viewport: Viewport, x: float, y: float) -> None:
        self.tools.overlay.set_outline(circle(x, y, self.brush.radius), closed=True)
        viewport.update()

    # --- gestures ------------------------------------------------------------------------------
    def press(self, viewport: Viewport, event: QMouseEvent) -> None:
        tools, doc = self.tools, self.tools.doc
        event.accept()
        if refused_in_split(doc, viewport, "Combing"):
            return
        area = tools.current_area
        if area is None:
            self._say(viewport, "Comb: pick or add a vector area in the Wrinkle vectors panel "
                      "first")
            return
        if not doc.selection.any():
            self._say(viewport, "Comb: select the vertices to comb first (S, then drag over the "
                      "face)")
            return
        project = doc.project
        rest = project.mesh.rest
        scale = float(np.ptp(rest, axis=0).max()) or 1.0
        motion = (np.linalg.norm(project.pose(area.pose).positions - rest, axis=1)
                  if area.pose in project.pose_names else np.zeros(len(rest)))
        self._stroke = (area, motion, typical_length(motion, scale), STILL_EPSILON * scale)
        self._view = tools.screen_view()
        view_matrix = doc.camera.view_matrix()
        self._frame = (doc.camera.eye(), view_matrix[0, :3], view_matrix[1, :3])
        self._candidates = doc.selection & self._view.select(
            np.ones(len(rest), bool), tools.select_through)
        self._combed = np.zeros(len(rest), bool)
        self._gesture = new_gesture()
        self._last = device_pixel(viewport, event)
        self._outline(viewport, *self._last)

    def move(self, viewport: Viewport, event: QMouseEvent) -> None:
        x, y = device_pixel(viewport, event)
        if self._gesture is not None and event.buttons() & Qt.MouseButton.LeftButton:
            self._dab(x, y)
        self._outline(viewport, x, y)  # hovering too: show where the comb would reach

    def release(self, viewport: Viewport, event: QMouseEvent) -> None:
        if self._gesture is None:
            return
        self._dab(*device_pixel(viewport, event))
        area, n = self._stroke[0], int(self._combed.sum())
        self._say(viewport, f"Combed {n} wrinkle directions of “{area.name}”" if n else
                  "Comb: no selected vertex under the brush; drag across the selection")
        self._end()

    def deactivate(self, viewport: Viewport) -> None:
        self._end()
        self.tools.overlay.set_outline(None)
        viewport.update()
        if self.on_deactivate is not None:
            self.on_deactivate()

    def _end(self) -> None:
        self._gesture, self._view, self._last = None, None, None

    def _dab(self, x: float, y: float) -> None:
        """Comb the candidates under the brush along the pointer's motion since the last dab."""
        lx, ly = self._last
        dx, dy = x - lx, y - ly
        if np.hypot(dx, dy) < SPACING:
            return
        self._last = (x, y)
        view, brush = self._view, self.brush
        idx = np.flatnonzero(self._candidates & sel.in_circle(view.pixels, (x, y), brush.radius))
        if len(idx) == 0:
            return
        area, motion, fallback, still = self._stroke
        tools = self.tools
        rows, directions = comb_dab(area.directions[idx], tools.posed()[idx],
                                    tools.normals()[idx], view.pixels[idx], (x, y), (dx, dy),
                                    brush, *self._frame)
        index = idx[rows]
        if len(index) == 0:
            return
        lengths = combed_lengths(area.lengths[index], motion[index], fallback, still)
        comb_directions(tools.doc, area, index, directions, lengths, self._gesture)
        self._combed[index] = True


class CombOwner(Protocol):
    """``WdvTools`` as the panel's controls and the action see it: the comb, the current
    area and its signal, and (once installed) the select and comb actions."""

    comb: CombTool
    currentAreaChanged: Signal

    @property
    def current_area(self) -> WdvArea | None: ...


class CombControls(QWidget):
    """The Comb button and its brush (radius, strength, hardness), for the Wrinkle vectors
    panel: the button toggles the tool's action, so the key, the toolbar and the panel agree."""

    def __init__(self, tools: CombOwner, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.tools = tools
        comb = tools.comb
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.button = QPushButton(f"Comb directions ({SHORTCUT})")
        self.button.setCheckable(True)
        self.button.setToolTip("Drag on the face to lay the selected vertices' wrinkle "
                               "directions along the drag, under a brush")
        self.button.clicked.connect(self._clicked)
        layout.addWidget(self.button)
        form = QFormLayout()
        self.radius = self._spin(2.0, 400.0, comb.brush.radius, " px", 0,
                                 "Comb radius on the screen", "radius")
        self.strength = self._spin(1.0, 100.0, 100.0 * comb.brush.strength, " %", 0,
                                   "How far each dab turns a direction toward the drag",
                                   "strength", 0.01)
        self.hardness = self._spin(0.0, 100.0, 100.0 * comb.brush.hardness, " %", 0,
                                   "Share of the radius combed at full strength; the rest "
                                   "fades out", "hardness", 0.01)
        form.addRow("Radius", self.radius)
        form.addRow("Strength", self.strength)
        form.addRow("Hardness", self.hardness)
        layout.addLayout(form)
        # like Create, the button waits for an area to comb (the key says why in the status bar)
        tools.currentAreaChanged.connect(self._show_area)
        self._show_area()

    def _show_area(self) -> None:
        self.button.setEnabled(self.tools.current_area is not None or self.button.isChecked())

    def _spin(self, low: float, high: float, value: float, suffix: str, decimals: int, tip: str,
              field: str, factor: float = 1.0) -> QDoubleSpinBox:
        spin = QDoubleSpinBox()
        spin.setRange(low, high)
        spin.setDecimals(decimals)
        spin.setSuffix(suffix)
        spin.setValue(value)
        spin.setToolTip(tip)
        spin.valueChanged.connect(lambda v: self.tools.comb.set_brush(**{field: v * factor}))
        return spin

    def _clicked(self, on: bool) -> None:
        action = getattr(self.tools, "comb_action", None)
        if action is not None:
            action.setChecked(on)

    def show_active(self, on: bool) -> None:
        blocker = QSignalBlocker(self.button)
        self.button.setChecked(on)
        del blocker
        self._show_area()


def install_comb(window, tools: CombOwner, controls: CombControls) -> QAction:
    """The Comb action (C) in the Tools toolbar, wired to the viewport and the panel's button."""
    viewport = window.viewport
    action = QAction("Comb directions", window)
    action.setCheckable(True)
    action.setShortcut(QKeySequence(SHORTCUT))
    action.setToolTip(f"Comb wrinkle directions ({SHORTCUT})\nDrag on the face over selected "
                      "vertices: their directions follow the drag")

    def dropped() -> None:  # another tool took the viewport
        blocker = QSignalBlocker(action)
        action.setChecked(False)
        del blocker
        controls.show_active(False)

    def toggled(on: bool) -> None:
        controls.show_active(on)
        if on:
            select = getattr(tools, "select_action", None)
            if select is not None and select.isChecked():
                select.setChecked(False)  # one tool at a time (it drops the viewport's tool)
            viewport.set_tool(tools.comb)
            window.statusBar().showMessage(HINT, 6000)
            dock = window.docks.get("Wrinkle vectors")
            if dock is not None:  # the area, the brush and the vectors it edits
                dock.show()
                dock.raise_()
        elif viewport.tool is tools.comb:
            viewport.set_tool(None)

    tools.comb.on_deactivate = dropped
    action.toggled.connect(toggled)
    window.tools.addAction(action)
    tools.comb_action = action
    return action
