"""How the face is shown: technique, split comparison, debug views, light, and technique 2's
expression factor and cone angle."""

from __future__ import annotations

import numpy as np
from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QGroupBox, QVBoxLayout, QWidget

from studio.widgets.document import Document
from studio.widgets.slider_row import SliderRow, fit_labels
from studio.widgets.viewport.techniques import TECHNIQUE_CHOICES, choose_technique

DEBUG_VIEWS = [("Shaded", "shaded"), ("Heat: weight", "heat"), ("Heat: what shows", "heat-shows"),
               ("Normals", "normals"), ("UV checker", "uv")]
COMBO_CHARACTERS = 16  # what a closed list shows of its choice before eliding it
RELIEF_RANGE = 0.05  # the relief depth slider's end, as a fraction of the face's size
RELIEFS = [("Off (normal maps only)", "off"), ("Displace (in silhouette)", "displace"),
           ("Parallax (cheaper)", "parallax")]


class ShadingPanel(QWidget):
    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = document
        layout = QVBoxLayout(self)
        view_box = QGroupBox("Display")
        form = QFormLayout(view_box)
        # each choice under its name, the column's whole width: "MikkTSpace (Blender,
        # Substance, engines)" reads in full in a 360-pixel column
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapAllRows)
        self.technique = QComboBox()
        for text, key in TECHNIQUE_CHOICES:
            self.technique.addItem(text, key)
        self.technique.setObjectName("technique")
        self.technique.activated.connect(self._technique_chosen)
        form.addRow("Technique", self.technique)
        self.debug_view = QComboBox()
        for text, key in DEBUG_VIEWS:
            self.debug_view.addItem(text, key)
        self.debug_view.activated.connect(
            lambda: document.set_view(debug_view=self.debug_view.currentData()))
        form.addRow("View", self.debug_view)
        self.blend = QComboBox()
        self.blend.addItem("Blend shaded colours (thesis)", "colour")
        self.blend.addItem("Blend normals, light once", "normal")
        self.blend.setToolTip("How the neutral and wrinkled normal maps are mixed")
        self.blend.activated.connect(lambda: document.set_view(blend=self.blend.currentData()))
        form.addRow("Blend", self.blend)
        self.relief = QComboBox()
        for text, key in RELIEFS:
            self.relief.addItem(text, key)
        self.relief.setObjectName("relief")
        self.relief.setToolTip("Wrinkles in depth. Displace moves the surface (tessellation, "
                               "OpenGL 4.0), so wrinkles show in the outline; parallax shifts "
                               "the maps per pixel, cheaper, not in the outline")
        self.relief.activated.connect(lambda: document.set_view(relief=self.relief.currentData()))
        form.addRow("Relief", self.relief)
        self.relief_depth = SliderRow("Relief depth", 0.0, 0.1, 4)
        self.relief_depth.setToolTip("Depth of the deepest wrinkle, in model units")
        self.relief_depth.edited.connect(lambda v, _g: document.set_view(relief_depth=v))
        form.addRow(self.relief_depth)
        self.tangent_frame = QComboBox()
        self.tangent_frame.setObjectName("tangent_frame")
        self.tangent_frame.addItem("MikkTSpace (Blender, engines)", "mikktspace")
        self.tangent_frame.addItem("Per-triangle sums (thesis)", "thesis")
        self.tangent_frame.setToolTip(
            "The tangent frame the normal maps were baked in (MikkTSpace: Blender, Substance, "
            "game engines); baking and the glTF export use "
            "it too. Maps from today's bakers need MikkTSpace")
        self.tangent_frame.activated.connect(
            lambda: document.set_view(tangent_frame=self.tangent_frame.currentData()))
        form.addRow("Tangent frame", self.tangent_frame)
        self.wireframe = QCheckBox("Wireframe overlay")
        self.wireframe.toggled.connect(lambda on: document.set_view(wireframe=on))
        form.addRow(self.wireframe)
        self.light_azimuth = SliderRow("Light azimuth", -180.0, 180.0, 0, "°")
        self.light_azimuth.edited.connect(lambda v, _g: document.set_view(light_azimuth=v))
        self.light_elevation = SliderRow("Light elevation", -90.0, 90.0, 0, "°")
        self.light_elevation.edited.connect(lambda v, _g: document.set_view(light_elevation=v))
        form.addRow(self.light_azimuth)
        form.addRow(self.light_elevation)
        layout.addWidget(view_box)

        t2_box = QGroupBox("Technique 2")
        t2_form = QFormLayout(t2_box)
        self.expression = SliderRow("Expression factor", 0.0, 2.0)
        self.expression.edited.connect(document.set_expression_factor)
        self.cone = SliderRow("Cone angle", 1.0, 90.0, 0, "°")
        self.cone.edited.connect(document.set_cone_angle)
        t2_form.addRow(self.expression)
        t2_form.addRow(self.cone)
        layout.addWidget(t2_box)
        layout.addStretch(1)
        fit_labels(self.findChildren(SliderRow))
        for combo in self.findChildren(QComboBox):  # a narrow column; the lists show in full
            combo.setSizeAdjustPolicy(
                QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
            combo.setMinimumContentsLength(COMBO_CHARACTERS)
        for signal in (document.viewChanged, document.wdvChanged, document.wdvSettingsChanged,
                       document.projectReplaced, document.currentWdvAreaChanged):
            signal.connect(self._show_values)
        self._show_values()

    def _technique_chosen(self) -> None:
        choose_technique(self.doc, self.technique.currentData())

    def _fit_relief_range(self) -> None:
        """The depth slider spans 0 to 5% of the face's size, whatever its units."""
        lo, hi = self.doc.project.mesh.bounds()
        top = max(RELIEF_RANGE * float(np.max(hi - lo)), self.doc.view.relief_depth, 1e-6)
        row = self.relief_depth
        row.maximum = top
        row.spin.setRange(0.0, top)
        row.spin.setSingleStep(top / 100.0)

    def _show_values(self) -> None:
        view = self.doc.view
        key = "split" if view.split else view.technique
        self.technique.setCurrentIndex(self.technique.findData(key))
        self.debug_view.setCurrentIndex(self.debug_view.findData(view.debug_view))
        self.blend.setCurrentIndex(self.blend.findData(view.blend))
        self.relief.setCurrentIndex(self.relief.findData(view.relief))
        self.tangent_frame.setCurrentIndex(self.tangent_frame.findData(view.tangent_frame))
        self._fit_relief_range()
        self.relief_depth.set_value(view.relief_depth)
        self.relief_depth.setEnabled(view.relief != "off")
        self.wireframe.blockSignals(True)
        self.wireframe.setChecked(view.wireframe)
        self.wireframe.blockSignals(False)
        self.light_azimuth.set_value(view.light_azimuth)
        self.light_elevation.set_value(view.light_elevation)
        wdv = self.doc.project.wdv
        self.expression.set_value(wdv.expression_factor)
        current = self.doc.current_wdv_area
        self.cone.set_value(current.cone_angle_deg if current is not None else 20.0)
        self.cone.setEnabled(current is not None)
        self.cone.setToolTip(f"Half-angle θ_max of the cone of the current technique-2 area"
                             f"{f' “{current.name}”' if current else ''} (Wrinkle vectors panel)")
