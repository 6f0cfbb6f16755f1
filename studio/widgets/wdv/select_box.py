"""The Wrinkle vectors panel's "Select vertices" box: the select tool, its modes (click, box,
lasso, brush, and the cone brush's place among them), its brush and "select through", and the
selection operations (grow, shrink, invert, mirror, all, none, the area's).

Why its own module: a box of tool options and one-click operations, each an undoable selection
edit; the panel around it only lays it out.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QDoubleSpinBox,
    QGroupBox,
    QLabel,
    QPushButton,
    QToolButton,
    QVBoxLayout,
)

from studio.core.mesh import selection as sel
from studio.widgets.flow_layout import FlowLayout, button
from studio.widgets.wdv import edits
from studio.widgets.wdv.tools import WdvTools


class SelectBox(QGroupBox):
    """The select tool's options and the selection operations."""

    def __init__(self, doc, tools: WdvTools, cone_brush_button: QToolButton) -> None:
        super().__init__("Select vertices")
        self.doc, self.tools = doc, tools
        s_layout = QVBoxLayout(self)
        self.tool_button = QPushButton("Select tool (S)")
        self.tool_button.setCheckable(True)
        self.tool_button.setToolTip("Left-drag in the viewport selects; Alt+drag still orbits")
        self.tool_button.toggled.connect(self.tool_toggled)
        s_layout.addWidget(self.tool_button)
        self.selection_label = QLabel()  # under the tool, not at the box's (cut) bottom edge
        s_layout.addWidget(self.selection_label)
        modes = FlowLayout()
        self.mode_group = QButtonGroup(self)
        self.mode_buttons: dict[str, QToolButton] = {}
        for mode, tip in (("click", "Click a vertex"), ("box", "Drag a rectangle"),
                          ("lasso", "Draw around vertices"), ("brush", "Paint vertices")):
            b = QToolButton()
            b.setText(mode.capitalize())
            b.setCheckable(True)
            b.setToolTip(f"{tip}. Shift adds, Ctrl removes")
            b.clicked.connect(lambda _=False, m=mode: self.set_mode(m))
            self.mode_group.addButton(b)
            self.mode_buttons[mode] = b
            modes.addWidget(b)
        self.mode_group.addButton(cone_brush_button)
        self.mode_buttons["cone"] = cone_brush_button
        self.mode_buttons[self.tools.tool.mode].setChecked(True)
        s_layout.addLayout(modes)
        options = FlowLayout()
        self.radius = QDoubleSpinBox()
        self.radius.setRange(2.0, 300.0)
        self.radius.setDecimals(0)
        self.radius.setSuffix(" px")
        self.radius.setValue(self.tools.tool.brush_radius)
        self.radius.setToolTip("Brush radius on screen")
        self.radius.valueChanged.connect(lambda v: setattr(self.tools.tool, "brush_radius", v))
        options.addWidget(QLabel("Brush"))
        options.addWidget(self.radius)
        self.through = QCheckBox("Select through")
        self.through.setToolTip("Also pick vertices that face away or are hidden")
        self.through.toggled.connect(lambda on: setattr(self.tools, "select_through", on))
        options.addWidget(self.through)
        s_layout.addLayout(options)
        grid = FlowLayout()
        ops = [("Grow", "Add the neighbours of the selection", self._grow),
               ("Shrink", "Drop the selection's border", self._shrink),
               ("Invert", "Select what is not selected", self._invert),
               ("Mirror", "Add the mirror image across the face's symmetry plane", self._mirror),
               ("All", "Select every vertex", self._all),
               ("None", "Deselect everything", self._none),
               ("Area's", "Select the vertices the current area has vectors for",
                self._from_area)]
        self.op_buttons: dict[str, QPushButton] = {}
        for name, tip, slot in ops:
            b = button(name, tip, slot)
            self.op_buttons[name] = b
            grid.addWidget(b)
        s_layout.addLayout(grid)


    def tool_toggled(self, on: bool) -> None:
        action = getattr(self.tools, "select_action", None)
        if action is not None and action.isChecked() != on:
            action.setChecked(on)

    def set_mode(self, mode: str) -> None:
        self.tools.tool.mode = mode
        self.mode_buttons[mode].setChecked(True)
        self.tool_toggled(True)

    def _grow(self) -> None:
        edits.set_selection(self.doc, sel.grow(self.doc.selection, self.tools.edges()), "Grow")

    def _shrink(self) -> None:
        edits.set_selection(self.doc, sel.shrink(self.doc.selection, self.tools.edges()),
                            "Shrink")

    def _invert(self) -> None:
        edits.set_selection(self.doc, sel.invert(self.doc.selection), "Invert selection")

    def _mirror(self) -> None:
        edits.set_selection(self.doc, sel.mirror(self.doc.selection, self.tools.mirror_index()),
                            "Mirror selection")

    def _all(self) -> None:
        edits.set_selection(self.doc, np.ones_like(self.doc.selection), "Select all")

    def _none(self) -> None:
        edits.set_selection(self.doc, np.zeros_like(self.doc.selection), "Select none")

    def _from_area(self) -> None:
        area = self.tools.current_area
        if area is not None:
            edits.set_selection(self.doc, area.authored.copy(), f"Select {area.name}")
