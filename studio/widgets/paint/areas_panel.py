"""The Areas panel (technique 1 authoring): the influence areas as layers, the brush, whole-mask
operations, images in and out, pose links and the auto mask.

The panel owns no project data: every edit goes through studio.widgets.paint.edits onto the undo
stack, and the list is rebuilt from the document when ``areasChanged`` says so. ``PaintState`` is
the only state here — the brush and which area is being painted — shared by the UV canvas and
the viewport's paint tool, like the tool options bar of an image editor.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from PySide6.QtCore import QEvent, QObject, QSettings, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QComboBox,
    QCompleter,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QMessageBox,
    QPushButton,
    QScrollArea,
    QSlider,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.setup.pose_map import map_on_link, wrinkle_map_for_pose
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.brush import Brush, Mirror, UvMirror
from studio.core.wrinkles.flat_reveal import reveal_maps, t1_reveal
from studio.core.wrinkles.surface_mirror import SurfaceMirror
from studio.widgets.commands import new_gesture
from studio.widgets.document import Document
from studio.widgets.flow_layout import FlowLayout, flow, labelled
from studio.widgets.paint import edits as mask_edits
from studio.widgets.paint.link_editor import LinkEditor
from studio.widgets.rebuild import clear_form
from studio.widgets.timeline.pose_panel import pose_label
from studio.widgets.viewport.techniques import show_technique_1

IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga *.webp)"
MIRROR_MODES = {
    "off": ("Off", "Dabs land only under the brush"),
    "uv": ("In UV (u → 1 − u)", "Every dab also lands mirrored across the UV square's middle: "
           "right when the UV layout is itself symmetric"),
    "mesh": ("Through the mesh (x → −x)", "Every dab also lands at the mirrored point of the "
             "face's surface (across x = 0), whatever the UV layout"),
}
BRUSH_SETTINGS = ("radius", "hardness", "opacity", "flow")  # remembered between sessions
FLAT_CHECK_MS = 300  # a paint stroke's dabs settle this long before the flat-map check reruns
WARNING_STYLE = "color: #e0a030;"


class PaintState(QObject):
    """The brush and the area being painted: tool options, not project data."""

    changed = Signal()
    activeChanged = Signal(int)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.brush = Brush()
        self.active = -1
        self.mirror = "off"  # a key of MIRROR_MODES
        self.overlap = False
        self._surface: SurfaceMirror | None = None
        # (model axis, position) of the face's left–right symmetry plane, and the skin's
        # triangles (the mirror's only targets); the mask tools point these at the document
        self.mirror_plane: Callable[[], tuple[int, float]] = lambda: (0, 0.0)
        self.skin_triangles: Callable[[], np.ndarray | None] = lambda: None

    def set_brush(self, **values) -> None:
        for key, value in values.items():
            setattr(self.brush, key, value)
        self.changed.emit()

    def set_erase(self, erase: bool) -> None:
        self.set_brush(erase=bool(erase))

    def scale_radius(self, factor: float) -> None:
        self.set_brush(radius=float(min(max(self.brush.radius * factor, 1.0), 1000.0)))

    def set_active(self, index: int) -> None:
        if index != self.active:
            self.active = index
            self.activeChanged.emit(index)

    def set_option(self, **values) -> None:
        for key, value in values.items():
            setattr(self, key, value)
        self.changed.emit()

    def set_mirror(self, mode: str) -> None:
        if mode not in MIRROR_MODES:
            raise ValueError(f"unknown mirror mode {mode!r}")
        self.set_option(mirror=mode)

    # --- mirrors -------------------------------------------------------------------------------
    def surface_mirror(self, mesh: FaceMesh) -> SurfaceMirror:
        """The mirror through this mesh, built once per mesh (its lookups are precomputed)."""
        axis, plane = self.mirror_plane()
        skin = self.skin_triangles()
        if self._surface is None or self._surface.mesh is not mesh or \
                (self._surface.axis, self._surface.plane) != (axis, plane) or \
                self._surface.skin is not skin:
            self._surface = SurfaceMirror(mesh, axis, plane, skin)
        return self._surface

    def stroke_mirror(self, mesh: FaceMesh) -> Mirror | None:
        """What a new stroke mirrors its dabs with, in the current mode."""
        if self.mirror == "uv":
            return UvMirror()
        if self.mirror == "mesh":
            return self.surface_mirror(mesh)
        return None

    # --- remembered between sessions -----------------------------------------------------------
    def restore(self, settings: QSettings) -> None:
        """The brush as the user last left it; unreadable values keep the defaults."""
        for key in BRUSH_SETTINGS:
            try:
                value = float(settings.value(f"brush/{key}", getattr(self.brush, key)))
            except (TypeError, ValueError):
                continue
            lo, hi = (1.0, 1000.0) if key == "radius" else (0.0, 1.0)
            setattr(self.brush, key, min(max(value, lo), hi))
        mode = str(settings.value("brush/mirror", self.mirror))
        self.mirror = mode if mode in MIRROR_MODES else self.mirror
        self.changed.emit()

    def save(self, settings: QSettings) -> None:
        for key in BRUSH_SETTINGS:
            settings.setValue(f"brush/{key}", float(getattr(self.brush, key)))
        settings.setValue("brush/mirror", self.mirror)


def swatch(colour: tuple[int, int, int], size: int = 14) -> QIcon:
    pix = QPixmap(size, size)
    pix.fill(QColor(*colour))
    return QIcon(pix)


class AreaRow(QWidget):
    """One layer: visibility, colour, name and its own activation slider."""

    def __init__(self, panel: AreasPanel, index: int) -> None:
        super().__init__()
        self.panel, self.index = panel, index
        area = panel.doc.project.influence.areas[index]
        self.visible = QCheckBox()
        self.visible.setChecked(area.visible)
        self.visible.setToolTip("Show / hide this area (hidden areas give no wrinkles)")
        self.colour = QToolButton()
        self.colour.setIcon(swatch(area.colour))
        self.colour.setToolTip("Change the area's colour")
        self.colour.setAutoRaise(True)
        self.name = QLabel(area.name)
        self.name.setMinimumWidth(max(110, self.name.sizeHint().width()))  # never cut
        self.editor = QLineEdit(area.name)  # the name, renamed in place (F2, double-click)
        self.editor.hide()
        self.editor.returnPressed.connect(self._renamed)
        self.editor.editingFinished.connect(self._renamed)
        self.editor.installEventFilter(self)
        self.flag = QLabel("⚠")  # shown when the area reveals a flat part of its map
        self.flag.setStyleSheet(WARNING_STYLE)
        self.flag.hide()
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, 100)
        self.slider.setToolTip("The area's own activation (pose links add to it)")
        self.slider.setObjectName(f"activation:{area.name}")
        self.value = QLabel()
        self.value.setFixedWidth(34)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 1, 4, 1)
        for w in (self.visible, self.colour, self.name, self.editor, self.flag):
            layout.addWidget(w)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.value)
        self._gesture: int | None = None
        self.flagged = ""  # why the area shows nothing (AreasPanel._show_flat), or ""
        self.show_values()
        self.visible.toggled.connect(
            lambda v: mask_edits.set_area_visible(panel.doc, self.index, v))
        self.colour.clicked.connect(self._pick_colour)
        self.slider.sliderPressed.connect(self._begin)
        self.slider.sliderReleased.connect(self._end)
        self.slider.valueChanged.connect(self._moved)

    def rename(self) -> None:
        """Edit the name where it is, as the Wrinkle vectors panel and Blender's lists do:
        Return or a click elsewhere keeps it, Escape leaves it as it was."""
        self.name.hide()
        self.editor.setText(self.name.text())
        self.editor.show()
        self.editor.setFocus()
        self.editor.selectAll()

    def _renamed(self) -> None:
        if self.editor.isHidden():
            return  # (Return, then the focus leaving: one rename)
        self.editor.hide()
        self.name.show()
        name = self.editor.text().strip()
        if name and name != self.name.text() and not mask_edits.rename_area(
                self.panel.doc, self.index, name):
            self.panel.say_taken(name)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if (watched is self.editor and event.type() == QEvent.Type.KeyPress
                and event.key() == Qt.Key.Key_Escape):
            self.editor.setText(self.name.text())
            self.editor.hide()
            self.name.show()
            return True
        return super().eventFilter(watched, event)

    def _begin(self) -> None:
        self._gesture = new_gesture()

    def _end(self) -> None:
        self._gesture = None

    def _moved(self, value: int) -> None:
        self.panel.doc.set_area_activation(self.index, value / 100.0, self._gesture)

    def _pick_colour(self) -> None:
        area = self.panel.doc.project.influence.areas[self.index]
        colour = QColorDialog.getColor(QColor(*area.colour), self, f"Colour of {area.name}")
        if colour.isValid():
            mask_edits.set_area_colour(self.panel.doc, self.index,
                                       (colour.red(), colour.green(), colour.blue()))

    def show_values(self) -> None:
        doc = self.panel.doc
        area = doc.project.influence.areas[self.index]
        self.slider.blockSignals(True)
        self.slider.setValue(round(area.activation * 100))
        self.slider.blockSignals(False)
        total = doc.activations()[self.index]
        self.value.setText(f"{total:.2f}")
        self.value.setToolTip("Activation now, pose links included")


class AreasPanel(QScrollArea):
    said = Signal(str)  # a line for the status bar: what a gesture did beyond the obvious

    def __init__(self, document: Document, state: PaintState, parent: QWidget | None = None
                 ) -> None:
        super().__init__(parent)
        self.doc = document
        self.state = state
        self.rows: list[AreaRow] = []
        self.link_spins: dict[str, QDoubleSpinBox] = {}
        self.link_editors: dict[str, LinkEditor] = {}
        self._links_key: tuple | None = None  # what the links form shows (_show_links)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setFrameShape(QScrollArea.Shape.NoFrame)
        body = QWidget()
        layout = QVBoxLayout(body)
        # the area list and what drives the selected area together at the top, in sight
        # without scrolling (MetaHuman's and Substance's layer stacks keep their properties
        # beside the list); the brush and whole-mask tools below
        layout.addWidget(self._build_layers())
        layout.addWidget(self._build_links())
        layout.addWidget(self._build_brush())
        layout.addWidget(self._build_adjust())
        layout.addWidget(self._build_images())
        layout.addStretch(1)
        self.setWidget(body)
        document.projectReplaced.connect(self._rebuild)
        document.areasChanged.connect(self._rebuild)
        document.texturesChanged.connect(self._show_links)
        document.masksChanged.connect(self._show_resolution)
        document.activationsChanged.connect(self._show_values)
        document.curvesChanged.connect(self._show_curves)
        document.poseWeightsChanged.connect(self._show_values)
        document.posesChanged.connect(self._rebuild)
        state.changed.connect(self._show_brush)
        self._flat_timer = QTimer(self)  # painting: check once the dabs settle, not per dab
        self._flat_timer.setSingleShot(True)
        self._flat_timer.setInterval(FLAT_CHECK_MS)
        self._flat_timer.timeout.connect(self._show_flat)
        document.texturesChanged.connect(self._show_flat)
        document.masksChanged.connect(self._show_flat)
        document.maskRegionChanged.connect(lambda *_: self._flat_timer.start())
        self._rebuild()
        if self.doc.project.influence.areas:
            self.select(0)

    # --- building ------------------------------------------------------------------------------
    def _button(self, text: str, tip: str, slot) -> QPushButton:
        b = QPushButton(text)
        b.setToolTip(tip)
        b.clicked.connect(slot)
        return b

    def _build_layers(self) -> QGroupBox:
        box = QGroupBox("Influence areas")
        v = QVBoxLayout(box)
        self.list = QListWidget()
        # with Add pose… below it, above the fold at 720 pixels
        self.list.setMinimumHeight(150)
        # rows as wide as the list (their sliders give way), never a sideways scroll bar
        # over the activation values
        self.list.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.list.currentRowChanged.connect(self._row_selected)
        self.list.itemDoubleClicked.connect(lambda _: self.rename())
        self.list.installEventFilter(self)  # F2 renames, as in the Wrinkle vectors list
        v.addWidget(self.list)
        specs = [("Add", "A new empty area", self.add),
                 ("Duplicate", "Copy the selected area", self.duplicate),
                 ("Rename", "Rename the selected area in the list (F2, or double-click it)",
                  self.rename),
                 ("Delete", "Delete the selected area", self.delete),
                 ("Up", "Move the selected area up", lambda: self.move(-1)),
                 ("Down", "Move the selected area down", lambda: self.move(1)),
                 ("Mirror", "Mirror the selected area to the other side of the face, through "
                            "the mesh: …_L becomes …_R, linked to the paired poses",
                  self.mirror_to_other_side),
                 ("Solo", "Show only the selected area's wrinkles (again: all)", self.solo)]
        v.addWidget(flow(*(self._button(text, tip, slot) for text, tip, slot in specs)))
        res = QHBoxLayout()
        res.addWidget(QLabel("Mask resolution"))
        self.resolution = QComboBox()
        for size in mask_ops.RESOLUTIONS:
            self.resolution.addItem(f"{size} × {size}", size)
        self.resolution.setToolTip("Every area's mask is resampled to this size (one texture "
                                   "array; masks need not match the normal maps)")
        self.resolution.activated.connect(self._resolution_chosen)
        res.addWidget(self.resolution, 1)
        v.addLayout(res)
        return box

    def _build_brush(self) -> QGroupBox:
        box = QGroupBox("Brush (UV canvas and face)")
        form = QFormLayout(box)
        self.radius = QSpinBox()
        self.radius.setRange(1, 1000)
        self.radius.setSuffix(" px")
        self.radius.setToolTip("Radius in mask pixels ([ and ] on the canvas)")
        self.hardness = QDoubleSpinBox()
        self.opacity = QDoubleSpinBox()
        self.flow = QDoubleSpinBox()
        for spin, tip in ((self.hardness, "Fraction of the radius at full strength; the rest "
                           "fades smoothly (soft edges)"),
                          (self.opacity, "The most one stroke builds up to"),
                          (self.flow, "How much each dab adds")):
            spin.setRange(0.0, 1.0)
            spin.setSingleStep(0.05)
            spin.setToolTip(tip)
        self.eraser = QCheckBox("Eraser (X)")
        self.mirror = QComboBox()
        for i, (key, (label, tip)) in enumerate(MIRROR_MODES.items()):
            self.mirror.addItem(label, key)
            self.mirror.setItemData(i, tip, Qt.ItemDataRole.ToolTipRole)
        self.mirror.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.mirror.setMinimumContentsLength(12)
        self.mirror.setToolTip("Mirror painting across the face's symmetry: in UV, or through "
                               "the mesh for any UV layout")
        self.overlap = QCheckBox("Overlap view on the canvas")
        self.overlap.setToolTip("Red: the weighted sum of masks exceeds 1 (the clamp hides a "
                                "conflict). Dark: no area reaches. Uses the current "
                                "activations, or every area at 1 on a neutral face.")
        for label, widget in (("Radius", self.radius), ("Hardness", self.hardness),
                              ("Opacity", self.opacity), ("Flow", self.flow),
                              ("Mirror", self.mirror)):
            form.addRow(label, widget)
        form.addRow(self.eraser)
        form.addRow(self.overlap)
        self._show_brush()
        self.radius.valueChanged.connect(lambda v: self.state.set_brush(radius=float(v)))
        self.hardness.valueChanged.connect(lambda v: self.state.set_brush(hardness=v))
        self.opacity.valueChanged.connect(lambda v: self.state.set_brush(opacity=v))
        self.flow.valueChanged.connect(lambda v: self.state.set_brush(flow=v))
        self.eraser.toggled.connect(self.state.set_erase)
        self.mirror.currentIndexChanged.connect(
            lambda _: self.state.set_mirror(self.mirror.currentData()))
        self.overlap.toggled.connect(lambda v: self.state.set_option(overlap=v))
        return box

    def _build_adjust(self) -> QGroupBox:
        box = QGroupBox("Adjust the selected mask")
        v = QVBoxLayout(box)
        self.blur_radius = QSpinBox()
        self.blur_radius.setRange(1, 256)
        self.blur_radius.setValue(8)
        self.blur_radius.setSuffix(" px")
        self.blur_radius.setToolTip("How far Blur softens")
        v.addWidget(flow(
            self._button("Fill", "Fill with the brush opacity", lambda: self.apply(
                "Fill", lambda m: mask_ops.fill(m, self.state.brush.opacity))),
            self._button("Clear", "Set to 0", lambda: self.apply(
                "Clear", lambda m: mask_ops.fill(m, 0))),
            self._button("Invert", "1 − mask", lambda: self.apply("Invert", mask_ops.invert)),
            self._button("Mirror L→R", "Copy the image's left half onto the right",
                         lambda: self.apply("Mirror", lambda m: mask_ops.mirror_u(m, "left"))),
            self._button("Blur", "Soften the mask's edges", lambda: self.apply(
                "Blur", lambda m: mask_ops.blur(m, self.blur_radius.value()))),
            self.blur_radius))
        self.black = QDoubleSpinBox()
        self.white = QDoubleSpinBox()
        self.gamma = QDoubleSpinBox()
        for spin, value, lo, hi in ((self.black, 0.0, 0, 1), (self.white, 1.0, 0, 1),
                                    (self.gamma, 1.0, 0.1, 5.0)):
            spin.setRange(lo, hi)
            spin.setSingleStep(0.05)
            spin.setValue(value)
        v.addWidget(flow(*(labelled(text, spin) for text, spin in (
            ("black", self.black), ("white", self.white), ("γ", self.gamma))),
            self._button("Levels", "Map black…white to 0…1, then gamma",
                         lambda: self.apply("Levels", lambda m: mask_ops.levels(
                             m, self.black.value(), self.white.value(),
                             self.gamma.value())))))
        return box

    def _build_links(self) -> QGroupBox:
        """The selected area's map and the poses that drive it: only the linked ones, each
        with its gain and response curve, and "Add pose…" to link another by typing part of
        its name (MetaHuman's and Character Creator's "driven by" lists), not one field per
        pose of the rig."""
        box = QGroupBox("Selected area: wrinkled map, driven by")
        v = QVBoxLayout(box)
        self.flat_note = QLabel()
        self.flat_note.setWordWrap(True)
        self.flat_note.setStyleSheet(WARNING_STYLE)
        self.flat_note.hide()
        v.addWidget(self.flat_note)
        self.add_pose = QComboBox()
        self.add_pose.setEditable(True)
        self.add_pose.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        self.add_pose.lineEdit().setPlaceholderText("Add pose… (type to search)")
        self.add_pose.setToolTip("Link another key pose to this area (gain 1; change it "
                                 "below). Type part of a name, then Return")
        completer = self.add_pose.completer()
        completer.setFilterMode(Qt.MatchFlag.MatchContains)
        completer.setCompletionMode(QCompleter.CompletionMode.PopupCompletion)
        self.add_pose.activated.connect(self._pose_added)
        v.addWidget(self.add_pose)  # first: in sight under the list, however many links
        self.map_said = QLabel()  # which map a link made the area reveal, and why
        self.map_said.setWordWrap(True)
        self.map_said.hide()
        v.addWidget(self.map_said)
        self.links_form = QFormLayout()
        self.links_form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapAllRows)
        v.addLayout(self.links_form)
        note = QLabel("Moving toward a pose raises this area's activation by gain × "
                      "curve(weight); the curve shapes how (linear unless chosen).")
        note.setWordWrap(True)
        v.addWidget(note)
        auto = FlowLayout()
        auto.addWidget(QLabel("From pose"))
        self.auto_pose = QComboBox()
        self.auto_pose.setToolTip("The key pose whose skin compression becomes the new area")
        self.auto_pose.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.auto_pose.setMinimumContentsLength(10)
        auto.addWidget(self.auto_pose)
        auto.addWidget(self._button("Auto mask", "A new soft area where this pose compresses "
                                    "the skin, linked to the pose, revealing the wrinkled map "
                                    "whose furrows belong to it", self.auto_mask))
        v.addLayout(auto)
        return box

    def _build_images(self) -> QGroupBox:
        box = QGroupBox("Images")
        v = QVBoxLayout(box)
        self.dark_strong = QCheckBox("Dark = strong (the thesis's masks)")
        self.dark_strong.setToolTip("Invert on import: black becomes full influence")
        v.addWidget(self.dark_strong)
        self.bits = QComboBox()
        self.bits.addItem("16-bit PNG", 16)
        self.bits.addItem("8-bit PNG", 8)
        self.bits.setToolTip("The depth exported masks are written with")
        v.addWidget(flow(
            self._button("Import images…", "Each image becomes an area, resampled to the mask "
                         "resolution", self.import_dialog),
            self._button("Import folder…", "Every image in a folder becomes an area",
                         self.import_folder_dialog),
            self._button("Export selected…", "Save the selected mask as a PNG (white = "
                         "strong)", self.export_dialog),
            self._button("Export all…", "Save every mask into a folder",
                         self.export_all_dialog),
            self.bits))
        return box

    # --- reflecting the document ---------------------------------------------------------------
    def _rebuild(self) -> None:
        areas = self.doc.project.influence.areas
        current = self.state.active
        self.list.blockSignals(True)
        self.list.clear()
        self.rows = []
        for i, _area in enumerate(areas):
            item = QListWidgetItem()
            row = AreaRow(self, i)
            item.setSizeHint(QSize(0, row.sizeHint().height()))  # the list's width
            self.list.addItem(item)
            self.list.setItemWidget(item, row)
            self.rows.append(row)
        self.list.blockSignals(False)
        current = min(max(current, 0), len(areas) - 1) if areas else -1
        self.list.blockSignals(True)
        self.list.setCurrentRow(current)
        self.list.blockSignals(False)
        self.state.active = current
        self.state.activeChanged.emit(current)  # names or order may have changed under it
        poses = [p.name for p in self.doc.project.poses]
        if [self.auto_pose.itemText(i) for i in range(self.auto_pose.count())] != poses:
            self.auto_pose.clear()
            self.auto_pose.addItems(poses)
        self._show_links()
        self._show_resolution()
        # measuring a real head's maps takes about a second: off the path of opening the window
        # or a project, once the first frame is up
        self._flat_timer.start()

    def _show_flat(self) -> None:
        """Flag each area whose weight lands on a flat part of its wrinkled map (the heat of
        the weight is hot there while the picture shows nothing), with the reason."""
        areas = self.doc.project.influence.areas
        if not self.rows or len(self.rows) != len(areas):
            self.flat_note.hide()
            return
        maps = reveal_maps(self.doc.project.textures)
        for row, area in zip(self.rows, areas, strict=True):
            reveal = t1_reveal(maps, area)
            row.flagged = reveal.reason() if reveal is not None and reveal.flagged else ""
            row.flag.setVisible(bool(row.flagged))
            row.flag.setToolTip(f"{area.name} {row.flagged}: its heat of the weight is hot, "
                                "the picture does not change. Paint where the map has "
                                "wrinkles, or choose another map" if row.flagged else "")
        active = self.rows[self.state.active].flagged if 0 <= self.state.active < len(
            self.rows) else ""
        self.flat_note.setText(f"This area {active}." if active else "")
        self.flat_note.setVisible(bool(active))

    def _show_values(self) -> None:
        for row in self.rows:
            if row.index < len(self.doc.project.influence.areas):
                row.show_values()

    def _show_resolution(self) -> None:
        res = self.doc.project.influence.resolution
        self.resolution.setEnabled(res is not None)
        if res is not None:
            i = self.resolution.findData(res[1])
            if i < 0:
                self.resolution.addItem(f"{res[1]} × {res[0]}", res[1])
                i = self.resolution.count() - 1
            self.resolution.setCurrentIndex(i)

    def _show_brush(self) -> None:
        b = self.state.brush
        for widget, value in ((self.radius, round(b.radius)), (self.hardness, b.hardness),
                              (self.opacity, b.opacity), (self.flow, b.flow),
                              (self.eraser, b.erase), (self.mirror, self.state.mirror),
                              (self.overlap, self.state.overlap)):
            widget.blockSignals(True)
            if isinstance(widget, QCheckBox):
                widget.setChecked(bool(value))
            elif isinstance(widget, QComboBox):
                widget.setCurrentIndex(widget.findData(value))
            else:
                widget.setValue(value)
            widget.blockSignals(False)

    def _show_links(self) -> None:
        """The selected area's map and the poses that drive it. The same area driven by the
        same poses is shown in place, so the field a person is typing in stays where it is (and
        alive: this runs inside that field's own signal); anything else makes the form again
        (its widgets deleted once the event that asked is over)."""
        area = self.active_area()
        textures = self.doc.project.textures
        linked = [] if area is None else [
            p for p in self.doc.project.pose_names
            if self.doc.project.influence.links.get(p, {}).get(area.name)]
        key = None if area is None else (self.state.active, area.name, tuple(linked),
                                         tuple(self.doc.project.pose_names),
                                         tuple(textures.wrinkle_map_names))
        if area is not None and key == self._links_key:
            self.map_combo.blockSignals(True)
            self.map_combo.setCurrentIndex(textures.map_index(area.wrinkle_map))
            self.map_combo.blockSignals(False)
            for editor in self.link_editors.values():
                editor.show_link()
            return
        self._links_key = key
        clear_form(self.links_form)
        self.link_spins = {}
        self.link_editors = {}
        self.add_pose.setEnabled(area is not None)
        if area is None:
            self.links_form.addRow(QLabel("No area selected."))
            return
        self.map_combo = QComboBox()
        self.map_combo.setToolTip("The wrinkled normal map this area reveals (Maps menu: add "
                                  "more)")
        for name in textures.wrinkle_map_names:
            self.map_combo.addItem(name, name)
        self.map_combo.setCurrentIndex(textures.map_index(area.wrinkle_map))
        index = self.state.active
        self.map_combo.activated.connect(lambda i: self._map_chosen(index, i))
        self.links_form.addRow("Wrinkled map", self.map_combo)
        if not linked:
            hint = QLabel("Driven by no pose yet: add one above, or move the area's own "
                          "activation slider.")
            hint.setWordWrap(True)
            self.links_form.addRow(hint)
        for pose in linked:
            editor = LinkEditor(self.doc, pose, area.name)
            self.links_form.addRow(pose_label(pose), editor)
            self.link_editors[pose] = editor
            self.link_spins[pose] = editor.spin
        self.add_pose.blockSignals(True)
        self.add_pose.clear()
        self.add_pose.addItems([p for p in self.doc.project.pose_names[1:] if p not in linked])
        self.add_pose.setCurrentIndex(-1)
        self.add_pose.blockSignals(False)

    def _pose_added(self, row: int) -> None:
        """Link the pose (gain 1) and, for an area whose map nobody chose, reveal the pose's
        own map in the same undo step — a frown's area shows the frown's lines, not the first
        map's forehead furrows — and show technique 1, where areas show; say both."""
        area = self.active_area()
        pose = self.add_pose.itemText(row)
        if area is None or pose not in self.doc.project.pose_names:
            return
        index = self.state.active
        project = self.doc.project
        chosen = map_on_link(project, area, pose)
        stack = self.doc.undo_stack
        stack.beginMacro(f"Link {pose} → {area.name}")
        mask_edits.set_link(self.doc, pose, area.name, 1.0)
        if chosen is not None:
            mask_edits.set_area_map(self.doc, index, chosen)
        stack.endMacro()
        said = []
        if chosen is not None:
            said.append(f"“{area.name}” reveals “{chosen}”, the map of {pose} (choose "
                        "another under Wrinkled map).")
        self.map_said.setText(said[0] if said else "")
        self.map_said.setVisible(bool(said))
        switched = show_technique_1(self.doc)
        if switched:
            said.append(switched)
        if said:
            self.said.emit(" ".join(said))
        editor = self.link_editors.get(pose)
        if editor is not None:  # on to its gain, as a person goes on to set it
            editor.spin.setFocus()
            editor.spin.selectAll()

    def _show_curves(self) -> None:
        for editor in self.link_editors.values():
            editor.refresh()

    def _map_chosen(self, index: int, row: int) -> None:
        mask_edits.set_area_map(self.doc, index, self.map_combo.itemData(row))

    # --- selection -----------------------------------------------------------------------------
    def select(self, index: int) -> None:
        self.list.setCurrentRow(index)

    def _row_selected(self, row: int) -> None:
        self.map_said.hide()  # (it spoke of the area that was selected)
        self.state.set_active(row)
        self._show_links()
        self._show_flat()

    def active_index(self) -> int:
        return self.state.active

    def active_area(self):
        areas = self.doc.project.influence.areas
        return areas[self.state.active] if 0 <= self.state.active < len(areas) else None

    # --- edits ---------------------------------------------------------------------------------
    def add(self) -> None:
        mask_edits.add_area(self.doc, "area")
        self.select(len(self.doc.project.influence.areas) - 1)

    def duplicate(self) -> None:
        if self.active_area() is not None:
            mask_edits.duplicate_area(self.doc, self.state.active)
            self.select(self.state.active + 1)

    def mirror_to_other_side(self) -> None:
        """The selected area, mirrored to the other side of the face (one undo step)."""
        if self.active_area() is None:
            return
        area = mask_edits.mirror_area(self.doc, self.state.active,
                                      self.state.surface_mirror(self.doc.project.mesh))
        self.select(self.doc.project.influence.areas.index(area))

    def solo(self) -> None:
        """Only the selected area shows; pressed again (or for an area already alone), all."""
        areas = self.doc.project.influence.areas
        index = self.active_index()
        if not 0 <= index < len(areas):
            return
        alone = tuple(i == index for i in range(len(areas)))
        if tuple(a.visible for a in areas) == alone:
            mask_edits.set_visible_all(self.doc, tuple(True for _ in areas), "Show all areas")
        else:
            mask_edits.set_visible_all(self.doc, alone, f"Solo {areas[index].name}")

    def delete(self) -> None:
        if self.active_area() is not None:
            mask_edits.delete_area(self.doc, self.state.active)

    def move(self, step: int) -> None:
        i = self.state.active
        if self.active_area() is not None and 0 <= i + step < len(self.rows):
            mask_edits.move_area(self.doc, i, i + step)
            self.select(i + step)

    def rename(self) -> None:
        """Rename the selected area in place in the list."""
        if 0 <= self.state.active < len(self.rows):
            self.rows[self.state.active].rename()

    def say_taken(self, name: str) -> None:
        QMessageBox.warning(self, "Rename area", f"There is already an area called “{name}”.")

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if (watched is self.list and event.type() == QEvent.Type.KeyPress
                and event.key() == Qt.Key.Key_F2):
            self.rename()
            return True
        return super().eventFilter(watched, event)

    def apply(self, text: str, op) -> None:
        if self.active_area() is not None:
            mask_edits.apply_mask_op(self.doc, self.state.active, text, op)

    def _resolution_chosen(self, _index: int) -> None:
        mask_edits.set_resolution(self.doc, int(self.resolution.currentData()))

    def auto_mask(self) -> None:
        pose = self.auto_pose.currentText()
        if not pose:
            return
        h, w = mask_edits.mask_shape(self.doc)
        project = self.doc.project
        mask = mask_ops.auto_mask(project.skin_mesh(), project.pose(pose).positions, w)
        if mask.shape != (h, w):
            mask = mask_ops.resample(mask, (w, h))
        if not mask.any():
            QMessageBox.information(self, "Auto mask",
                                    f"The pose “{pose}” compresses no skin; no area was made.")
            return
        mask_edits.add_area(self.doc, f"{pose} auto", mask, links={pose: 1.0},
                            wrinkle_map=wrinkle_map_for_pose(project, pose, mask))
        self.select(len(self.doc.project.influence.areas) - 1)

    # --- images --------------------------------------------------------------------------------
    def import_files(self, paths: list[Path]) -> int:
        """Import images as areas; errors in a dialog naming each file. Returns how many."""
        new, errors = mask_edits.import_masks(self.doc, [Path(p) for p in paths],
                                              self.dark_strong.isChecked())
        if new:
            self.select(len(self.doc.project.influence.areas) - 1)
        if errors:
            QMessageBox.critical(self, "Cannot import masks",
                                 "These images could not be imported:\n\n"
                                 + "\n".join(str(e) for e in errors))
        return len(new)

    def import_folder(self, folder: Path) -> int:
        files = mask_edits.image_files(Path(folder))
        if not files:
            QMessageBox.warning(self, "Import folder", f"{folder}: no images in this folder.")
            return 0
        return self.import_files(files)

    def export_active(self, path: Path, bits: int | None = None) -> bool:
        area = self.active_area()
        if area is None:
            return False
        try:
            mask_edits.export_mask(area, Path(path), bits or int(self.bits.currentData()))
        except StudioError as exc:
            QMessageBox.critical(self, "Cannot export mask", str(exc))
            return False
        return True

    def _folder(self) -> str:
        path = self.doc.path
        return str(path.parent) if path else str(Path.home())

    def import_dialog(self) -> None:
        names, _ = QFileDialog.getOpenFileNames(self, "Import masks", self._folder(),
                                                IMAGE_FILTER)
        if names:
            self.import_files([Path(n) for n in names])

    def import_folder_dialog(self) -> None:
        folder = QFileDialog.getExistingDirectory(self, "Import a folder of masks",
                                                  self._folder())
        if folder:
            self.import_folder(Path(folder))

    def export_dialog(self) -> None:
        area = self.active_area()
        if area is None:
            return
        start = str(Path(self._folder()) / mask_edits.file_name(area))
        name, _ = QFileDialog.getSaveFileName(self, "Export mask", start, "PNG (*.png)")
        if name:
            path = Path(name) if name.lower().endswith(".png") else Path(name + ".png")
            self.export_active(path)

    def export_all_dialog(self) -> None:
        folder = QFileDialog.getExistingDirectory(self, "Export every mask into", self._folder())
        if not folder:
            return
        bits = int(self.bits.currentData())
        try:
            for area in self.doc.project.influence.areas:
                mask_edits.export_mask(area, Path(folder) / mask_edits.file_name(area), bits)
        except StudioError as exc:
            QMessageBox.critical(self, "Cannot export masks", str(exc))
