"""The "Wrinkle vectors" dock: technique-2 areas, vertex selection and Create.

A thin view: it shows the document's WDV areas and selection and turns every click into an undo
command (studio/widgets/wdv/edits.py). Workflow: pick an area, its pose, select the vertices in
the viewport (S), press Create, move the pose slider to preview.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QAction, QColor, QKeySequence
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QColorDialog,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QScrollArea,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from studio.core.mesh import selection as sel
from studio.core.wrinkles.flat_reveal import reveal_maps, t2_reveal
from studio.widgets.flow_layout import FlowLayout, button, flow
from studio.widgets.layer_list_model import solo
from studio.widgets.slider_row import SliderRow
from studio.widgets.swatch import swatch
from studio.widgets.wdv import edits
from studio.widgets.wdv.comb_tool import CombControls, install_comb
from studio.widgets.wdv.select_box import SelectBox
from studio.widgets.wdv.tools import WdvTools
from studio.widgets.wdv.wdv_model import (
    area_tooltip,
    colour_text,
    create_refused,
    created_text,
    flat_text,
    pose_choices,
    selection_text,
    suggested_text,
)

SAY_MS = 8000  # a status line a person has time to read
FLAT_CHECK_MS = 300  # the flat-map check waits for the window to show and edits to settle


class WdvPanel(QScrollArea):
    message = Signal(str)

    def __init__(self, doc, tools: WdvTools, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.tools = tools
        self.setWidgetResizable(True)
        self.setMinimumHeight(300)  # the area list and the main buttons stay in sight
        self._updating = False
        # measuring a real head's maps takes about a second: once the window is up and the
        # edits settle, not on the path of opening it or of each change
        self._flat_timer = QTimer(self)
        self._flat_timer.setSingleShot(True)
        self._flat_timer.setInterval(FLAT_CHECK_MS)
        self._flat_timer.timeout.connect(lambda: self._show_flat(self.tools.current_area))
        self._build()
        doc.wdvChanged.connect(self._refresh)
        doc.projectReplaced.connect(self._refresh)
        doc.posesChanged.connect(self._refresh)
        doc.texturesChanged.connect(self._refresh)
        doc.selectionChanged.connect(self._show_selection)
        doc.viewChanged.connect(self._show_view)
        tools.currentAreaChanged.connect(self._refresh)
        self._refresh()
        self._show_selection()

    # --- layout --------------------------------------------------------------------------------
    def _build(self) -> None:
        """Three boxes in the order of the work: the area and its pose, the vertices, Create."""
        body = QWidget()
        layout = QVBoxLayout(body)
        layout.addWidget(self._build_areas_box())
        self.select_box = box = SelectBox(self.doc, self.tools, self.cone_brush_button)
        layout.addWidget(box)
        self.tool_button, self.selection_label, self.mode_group = (box.tool_button,
                                                                   box.selection_label,
                                                                   box.mode_group)
        self.mode_buttons, self.radius, self.through = box.mode_buttons, box.radius, box.through
        self.op_buttons = box.op_buttons
        layout.addWidget(self._build_directions_box())
        hint = QLabel("1. Pick or add an area and its pose  2. S, then drag over the face "
                      "(Shift adds, Ctrl removes)  3. Create  4. Move the pose slider")
        hint.setWordWrap(True)
        hint.setStyleSheet("color: #888;")
        layout.addWidget(hint)
        layout.addStretch(1)
        self.setWidget(body)

    def _build_areas_box(self) -> QGroupBox:
        """The area list with its buttons, and the current area's pose, cone, colour and map."""
        areas = QGroupBox("Vector areas")  # (the Areas panel holds technique 1's masks)
        a_layout = QVBoxLayout(areas)
        self.area_list = QListWidget()
        self.area_list.setMaximumHeight(130)
        self.area_list.setEditTriggers(QAbstractItemView.EditTrigger.DoubleClicked
                                       | QAbstractItemView.EditTrigger.EditKeyPressed)
        self.area_list.setToolTip("Double-click to rename; the check box mutes an area")
        self.area_list.currentRowChanged.connect(self._row_changed)
        self.area_list.itemChanged.connect(self._item_changed)
        a_layout.addWidget(self.area_list)
        self.add_button = button("Add", "Add an empty area", self._add)
        self.delete_button = button("Delete", "Delete the current area", self._delete)
        self.up_button = self._tool_button("▲", "Move the area up", lambda: self._move(-1))
        self.down_button = self._tool_button("▼", "Move the area down", lambda: self._move(1))
        self.solo_button = button("Solo", "Show only this area's wrinkles (again: all)",
                                        self._solo)
        a_layout.addWidget(flow(self.add_button, self.delete_button, self.up_button,
                                self.down_button, self.solo_button))
        form = QFormLayout()
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.pose_combo = QComboBox()
        self.pose_combo.setToolTip("The key pose whose motion creates this area's wrinkles")
        self.pose_combo.activated.connect(self._pose_chosen)
        form.addRow("Pose", self.pose_combo)
        self.cone = SliderRow("", 1.0, 90.0, decimals=1, suffix="°")
        self.cone.label.hide()
        self.cone.setToolTip("Cone half-angle θ: motion further than this from the direction "
                             "shows no wrinkles")
        self.cone.edited.connect(self._cone_edited)
        form.addRow("Cone angle", self.cone)
        form.addRow("Painted θ", self._build_cone_paint_row())
        self.colour_button = QPushButton()
        self.colour_button.setToolTip("The colour the area's vertices and vectors are drawn in")
        self.colour_button.clicked.connect(self._choose_colour)
        form.addRow("Colour", self.colour_button)
        self.map_combo = QComboBox()
        self.map_combo.setToolTip("The wrinkled normal map this area reveals (Maps menu: add "
                                  "more)")
        self.map_combo.activated.connect(self._map_chosen)
        form.addRow("Wrinkle map", self.map_combo)
        a_layout.addLayout(form)
        self.flat_label = QLabel()  # the current area reveals a flat part of its map: why
        self.flat_label.setWordWrap(True)
        self.flat_label.setStyleSheet("color: #e0a030;")
        self.flat_label.hide()
        a_layout.addWidget(self.flat_label)
        return areas

    def _build_cone_paint_row(self) -> QWidget:
        """Per-vertex cone angles: the value, the brush, to the selection, clear."""
        self.cone_paint = QDoubleSpinBox()
        self.cone_paint.setRange(0.5, 90.0)
        self.cone_paint.setDecimals(1)
        self.cone_paint.setSuffix("°")
        self.cone_paint.setValue(self.tools.cone_paint_value)
        self.cone_paint.setToolTip("The cone angle the cone brush paints")
        self.cone_paint.valueChanged.connect(
            lambda v: setattr(self.tools, "cone_paint_value", float(v)))
        self.cone_brush_button = QToolButton()
        self.cone_brush_button.setText("Paint")
        self.cone_brush_button.setCheckable(True)
        self.cone_brush_button.setToolTip("Paint a per-vertex cone angle on the face with the "
                                          "brush (Ctrl paints back the area's angle)")
        self.cone_brush_button.clicked.connect(lambda: self.select_box.set_mode("cone"))
        self.cone_selected_button = self._tool_button(
            "Selected", "Give the selected vertices this cone angle", self._cones_to_selection)
        self.cone_clear_button = self._tool_button(
            "Clear", "Remove the painted angles: every vertex uses the area's angle",
            self._clear_cones)
        return flow(self.cone_paint, self.cone_brush_button, self.cone_selected_button,
                    self.cone_clear_button)

    def _build_directions_box(self) -> QGroupBox:
        """Suggest, Create and Clear, what to show, and the status line."""
        create = QGroupBox("Wrinkle directions")
        c_layout = QVBoxLayout(create)
        suggest = FlowLayout()
        self.threshold = QDoubleSpinBox()
        self.threshold.setRange(0.0, 100.0)
        self.threshold.setValue(20.0)
        self.threshold.setSuffix(" %")
        self.threshold.setToolTip("Suggest selects vertices the pose moves by more than this "
                                  "share of its largest motion")
        self.suggest_button = button("Suggest", "Select where the area's pose moves the "
                                           "skin (as a start)", self._suggest)
        suggest.addWidget(self.suggest_button)
        suggest.addWidget(QLabel("over"))
        suggest.addWidget(self.threshold)
        c_layout.addLayout(suggest)
        buttons = FlowLayout()
        self.create_button = button("Create", "Set d = normalize(P_pose − P_neutral) for "
                                          "the selected vertices; zero elsewhere in this area",
                                          self._create)
        self.create_button.setDefault(True)
        self.create_button.setStyleSheet("font-weight: bold;")
        self.clear_button = button("Clear", "Remove this area's vectors", self._clear)
        buttons.addWidget(self.create_button)
        buttons.addWidget(self.clear_button)
        c_layout.addLayout(buttons)
        self.comb_controls = CombControls(self.tools)  # draw directions instead (C)
        c_layout.addWidget(self.comb_controls)
        self.vectors_check = QCheckBox("Show vectors")
        self.vectors_check.setChecked(True)
        self.vectors_check.setToolTip("The current area's vectors over the face, while this "
                                      "panel is open")
        self.vectors_check.toggled.connect(self._show_vectors)
        self.all_areas_check = QCheckBox("All areas")
        self.all_areas_check.setToolTip("The other areas' vectors too, faint")
        self.all_areas_check.toggled.connect(self.tools.set_all_areas)
        heat = QCheckBox("Heat map")
        heat.setToolTip("Show each vertex's wrinkle visibility while you move the pose sliders")
        heat.toggled.connect(lambda on: self.doc.set_view(debug_view="heat" if on else "shaded"))
        self.heat_check = heat
        row2 = FlowLayout()
        row2.addWidget(self.vectors_check)
        row2.addWidget(self.all_areas_check)
        row2.addWidget(heat)
        c_layout.addLayout(row2)
        self.status = QLabel()
        self.status.setWordWrap(True)
        c_layout.addWidget(self.status)
        return create

    def _tool_button(self, text: str, tip: str, slot) -> QToolButton:
        b = QToolButton()
        b.setText(text)
        b.setToolTip(tip)
        b.clicked.connect(slot)
        return b

    # --- showing the document ------------------------------------------------------------------
    def _refresh(self) -> None:
        self._updating = True
        try:
            areas = self.doc.project.wdv.areas
            current = self.tools.current_area
            if self.area_list.count() != len(areas):
                # rebuilt only when the count changes: a rename or mute arrives from the item's
                # own itemChanged signal, and that item must not be deleted under it
                self.area_list.clear()
                for _ in areas:
                    item = QListWidgetItem()
                    item.setFlags(item.flags() | Qt.ItemFlag.ItemIsEditable
                                  | Qt.ItemFlag.ItemIsUserCheckable)
                    self.area_list.addItem(item)
            for row, area in enumerate(areas):
                item = self.area_list.item(row)
                item.setIcon(swatch(area.colour))
                item.setText(area.name)
                item.setCheckState(Qt.CheckState.Checked if area.enabled
                                   else Qt.CheckState.Unchecked)
                item.setToolTip(area_tooltip(area.name, area.pose, area.authored,
                                             area.cone_angle_deg, area.cone_angles_deg))
            if current is not None:
                self.area_list.setCurrentRow(areas.index(current))
            self.pose_combo.clear()
            for name in pose_choices(self.doc.project.pose_names):
                self.pose_combo.addItem(name, name)
            self.map_combo.clear()
            for name in self.doc.project.textures.wrinkle_map_names:
                self.map_combo.addItem(name, name)
            has = current is not None
            for w in (self.delete_button, self.up_button, self.down_button, self.solo_button,
                      self.pose_combo, self.cone, self.colour_button, self.create_button,
                      self.clear_button, self.suggest_button, self.map_combo,
                      self.cone_brush_button, self.cone_selected_button, self.cone_clear_button):
                w.setEnabled(has)
            if has:
                self.pose_combo.setCurrentIndex(self.pose_combo.findData(current.pose))
                textures = self.doc.project.textures
                self.map_combo.setCurrentIndex(textures.map_index(current.wrinkle_map))
                self.cone.set_value(current.cone_angle_deg)
                self.colour_button.setIcon(swatch(current.colour, 16))
                self.colour_button.setText(colour_text(current.colour))
                self.create_button.setText(f"Create for “{current.name}”")
            self._flat_timer.start()
        finally:
            self._updating = False

    def _show_flat(self, current) -> None:
        """Say when the current area's weight lands on a flat part of its wrinkled map: the
        heat of the weight is hot there, the picture does not change."""
        project = self.doc.project
        known = current is not None and current.pose in project.pose_names
        reveal = None if not known else t2_reveal(
            reveal_maps(project.textures), project.skin_mesh(), current,
            project.pose(current.pose).positions, project.wdv.expression_factor,
            project.wdv.scale_free)
        text = flat_text(current.name, reveal.reason(), current.pose) \
            if reveal is not None and reveal.flagged else ""
        self.flat_label.setText(text)
        self.flat_label.setVisible(bool(text))

    def _show_view(self) -> None:
        self.heat_check.blockSignals(True)
        self.heat_check.setChecked(self.doc.view.debug_view in ("heat", "heat-shows"))
        self.heat_check.blockSignals(False)

    def _show_selection(self) -> None:
        self.selection_label.setText(selection_text(self.doc.selection))

    def tool_active(self, on: bool) -> None:
        if self.tool_button.isChecked() != on:
            self.tool_button.setChecked(on)

    def _say(self, text: str, warning: bool = False) -> None:
        self.status.setStyleSheet("color: #e0a030;" if warning else "")
        self.status.setText(text)
        self.message.emit(text)
        window = self.window()
        if hasattr(window, "statusBar"):
            window.statusBar().showMessage(text, 6000)

    # --- area edits ----------------------------------------------------------------------------
    def _area(self):
        return self.tools.current_area

    def _row_changed(self, row: int) -> None:
        if self._updating:
            return
        areas = self.doc.project.wdv.areas
        self.tools.set_current_area(areas[row] if 0 <= row < len(areas) else None)

    def _item_changed(self, item: QListWidgetItem) -> None:
        if self._updating:
            return
        row = self.area_list.row(item)
        area = self.doc.project.wdv.areas[row]
        enabled = item.checkState() == Qt.CheckState.Checked
        try:
            if item.text() != area.name:
                edits.set_area_value(self.doc, area, "name", item.text(), "Rename")
            if enabled != area.enabled:
                edits.set_area_value(self.doc, area, "enabled", enabled,
                                     "Show" if enabled else "Mute")
        except ValueError as exc:
            self._say(str(exc), warning=True)
            self._refresh()

    def _add(self) -> None:
        current = self._area()
        pose = current.pose if current is not None else None
        area = edits.add_area(self.doc, "area", pose)
        self.tools.set_current_area(area)

    def _delete(self) -> None:
        area = self._area()
        if area is not None:
            edits.delete_area(self.doc, self.doc.project.wdv.areas.index(area))

    def _move(self, step: int) -> None:
        area = self._area()
        if area is not None:
            i = self.doc.project.wdv.areas.index(area)
            edits.move_area(self.doc, i, i + step)

    def _solo(self) -> None:
        area = self._area()
        areas = self.doc.project.wdv.areas
        if area is None:
            return
        edits.set_enabled_all(self.doc, *solo(tuple(a.enabled for a in areas),
                                              areas.index(area), area.name))

    def _pose_chosen(self, index: int) -> None:
        area = self._area()
        if area is not None and index >= 0:
            edits.set_area_value(self.doc, area, "pose", self.pose_combo.itemData(index), "Pose")

    def _map_chosen(self, index: int) -> None:
        area = self._area()
        if area is not None and index >= 0:
            edits.set_area_value(self.doc, area, "wrinkle_map", self.map_combo.itemData(index),
                                 "Wrinkled map")

    def _cones_to_selection(self) -> None:
        area = self._area()
        if area is not None and self.doc.selection.any():
            edits.set_cone_angles(self.doc, area, self.doc.selection.copy(),
                                  self.tools.cone_paint_value)

    def _clear_cones(self) -> None:
        area = self._area()
        if area is not None:
            edits.set_cone_angles(self.doc, area, None, 0.0)

    def _cone_edited(self, value: float, gesture) -> None:
        area = self._area()
        if area is not None and not self._updating:
            edits.set_area_value(self.doc, area, "cone_angle_deg", float(value), "Cone angle",
                                 gesture)

    def _choose_colour(self) -> None:
        area = self._area()
        if area is None:
            return
        colour = QColorDialog.getColor(QColor(*area.colour), self, f"Colour of {area.name}")
        if colour.isValid():
            edits.set_area_value(self.doc, area, "colour",
                                 (colour.red(), colour.green(), colour.blue()), "Colour")

    # --- selection -----------------------------------------------------------------------------
    def _suggest(self) -> None:
        area = self._area()
        if area is None:
            return
        project = self.doc.project
        hits = sel.suggest(project.mesh.rest, project.pose(area.pose).positions,
                           self.threshold.value() / 100.0)
        edits.set_selection(self.doc, hits, f"Suggest for {area.name}")
        self._say(suggested_text(hits, area.pose))

    # --- vectors -------------------------------------------------------------------------------
    def _create(self) -> None:
        area = self._area()
        n = int(self.doc.selection.sum())
        refused = create_refused(None if area is None else area.name, n)
        if refused:
            self._say(refused, warning=True)
            return
        still = edits.create_directions(self.doc, area)
        self._say(*created_text(n, len(still), area.name, area.pose))

    def _clear(self) -> None:
        area = self._area()
        if area is not None:
            edits.clear_directions(self.doc, area)
            self._say(f"Cleared the vectors of “{area.name}”.")

    def _show_vectors(self, on: bool) -> None:
        self.tools.overlay.show_vectors = on
        self.tools.viewport.update()


def install_wdv_tools(window) -> WdvTools:
    """Create the "Wrinkle vectors" dock, the select tool's toolbar action (S) and the overlay."""
    tools = WdvTools(window.doc, window.viewport)
    panel = WdvPanel(window.doc, tools)
    window._add_dock("Wrinkle vectors", panel, Qt.DockWidgetArea.RightDockWidgetArea)
    dock = window.docks["Wrinkle vectors"]
    dock.visibilityChanged.connect(tools.set_panel_open)  # raised tab: shown; hidden: not
    action = QAction("Select vertices", window)
    action.setCheckable(True)
    action.setShortcut(QKeySequence("S"))
    action.setToolTip("Select vertices for wrinkle direction vectors (S)\n"
                      "Click, drag a box / lasso, or paint; Shift adds, Ctrl removes")

    def toggled(on: bool) -> None:
        window.viewport.set_tool(tools.tool if on else None)
        tools.set_selecting(on)
        panel.tool_active(on)
        if on:  # the tool's options and the vectors it edits
            dock.show()
            dock.raise_()

    action.toggled.connect(toggled)
    window.tools.addAction(action)
    window.viewport.overlays.append(tools.overlay)
    tools.select_action = action
    tools.panel = panel
    # what a gesture selected, where the eye is (the picture's corner) and in the status bar
    tools.said.connect(lambda text: (window.statusBar().showMessage(text, SAY_MS),
                                     window.viewport.say(text, SAY_MS)))
    install_comb(window, tools, panel.comb_controls)
    window.wdv_tools = tools
    return tools
