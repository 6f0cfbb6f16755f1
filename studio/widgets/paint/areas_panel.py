"""The Areas panel (technique 1 authoring): the influence areas as layers, the brush, whole-mask
operations, images in and out, pose links and the auto mask.

The panel owns no project data: every edit goes through studio.widgets.paint.edits onto the undo
stack, and the list is rebuilt from the document when ``areasChanged`` says so. ``PaintState`` is
the only state here — the brush and which area is being painted — shared by the UV canvas and
the viewport's paint tool, like the tool options bar of an image editor.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QEvent, QObject, QSize, Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMessageBox,
    QScrollArea,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from studio.core.files.errors import StudioError
from studio.core.setup.pose_map import wrinkle_map_for_pose
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.flat_reveal import reveal_maps, t1_reveal
from studio.widgets.document import Document
from studio.widgets.flow_layout import button, flow, labelled
from studio.widgets.layer_list_model import can_move, kept_selection, solo
from studio.widgets.paint import edits as mask_edits
from studio.widgets.paint.area_links import AreaLinks
from studio.widgets.paint.area_row import AreaRow
from studio.widgets.paint.areas_model import flat_tooltip
from studio.widgets.paint.link_editor import LinkEditor
from studio.widgets.paint.paint_state import MIRROR_MODES, PaintState

IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga *.webp)"
FLAT_CHECK_MS = 300  # a paint stroke's dabs settle this long before the flat-map check reruns


class AreasPanel(QScrollArea):
    said = Signal(str)  # a line for the status bar: what a gesture did beyond the obvious

    def __init__(self, document: Document, state: PaintState, parent: QWidget | None = None
                 ) -> None:
        super().__init__(parent)
        self.doc = document
        self.state = state
        self.rows: list[AreaRow] = []
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setFrameShape(QScrollArea.Shape.NoFrame)
        body = QWidget()
        layout = QVBoxLayout(body)
        # the area list and what drives the selected area together at the top, in sight
        # without scrolling (MetaHuman's and Substance's layer stacks keep their properties
        # beside the list); the brush and whole-mask tools below
        layout.addWidget(self._build_layers())
        self.links = AreaLinks(self)
        layout.addWidget(self.links)
        self.flat_note, self.add_pose, self.map_said = (self.links.flat_note,
                                                        self.links.add_pose, self.links.map_said)
        self.links_form, self.auto_pose = self.links.links_form, self.links.auto_pose
        layout.addWidget(self._build_brush())
        layout.addWidget(self._build_adjust())
        layout.addWidget(self._build_images())
        layout.addStretch(1)
        self.setWidget(body)
        document.projectReplaced.connect(self._rebuild)
        document.areasChanged.connect(self._rebuild)
        document.texturesChanged.connect(self.links.show_links)
        document.masksChanged.connect(self._show_resolution)
        document.activationsChanged.connect(self._show_values)
        document.curvesChanged.connect(self.links.show_curves)
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

    @property
    def link_spins(self) -> dict[str, QDoubleSpinBox]:
        return self.links.link_spins

    @property
    def link_editors(self) -> dict[str, LinkEditor]:
        return self.links.link_editors

    @property
    def map_combo(self) -> QComboBox | None:
        return self.links.map_combo

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
        v.addWidget(flow(*(button(text, tip, slot) for text, tip, slot in specs)))
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
            button("Fill", "Fill with the brush opacity", lambda: self.apply(
                "Fill", lambda m: mask_ops.fill(m, self.state.brush.opacity))),
            button("Clear", "Set to 0", lambda: self.apply(
                "Clear", lambda m: mask_ops.fill(m, 0))),
            button("Invert", "1 − mask", lambda: self.apply("Invert", mask_ops.invert)),
            button("Mirror L→R", "Copy the image's left half onto the right",
                         lambda: self.apply("Mirror", lambda m: mask_ops.mirror_u(m, "left"))),
            button("Blur", "Soften the mask's edges", lambda: self.apply(
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
            button("Levels", "Map black…white to 0…1, then gamma",
                         lambda: self.apply("Levels", lambda m: mask_ops.levels(
                             m, self.black.value(), self.white.value(),
                             self.gamma.value())))))
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
            button("Import images…", "Each image becomes an area, resampled to the mask "
                         "resolution", self.import_dialog),
            button("Import folder…", "Every image in a folder becomes an area",
                         self.import_folder_dialog),
            button("Export selected…", "Save the selected mask as a PNG (white = "
                         "strong)", self.export_dialog),
            button("Export all…", "Save every mask into a folder",
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
        current = kept_selection(current, len(areas))
        self.list.blockSignals(True)
        self.list.setCurrentRow(current)
        self.list.blockSignals(False)
        self.state.active = current
        self.state.activeChanged.emit(current)  # names or order may have changed under it
        poses = [p.name for p in self.doc.project.poses]
        if [self.auto_pose.itemText(i) for i in range(self.auto_pose.count())] != poses:
            self.auto_pose.clear()
            self.auto_pose.addItems(poses)
        self.links.show_links()
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
            row.flag.setToolTip(flat_tooltip(area.name, row.flagged))
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

    # --- selection -----------------------------------------------------------------------------
    def select(self, index: int) -> None:
        self.list.setCurrentRow(index)

    def _row_selected(self, row: int) -> None:
        self.map_said.hide()  # (it spoke of the area that was selected)
        self.state.set_active(row)
        self.links.show_links()
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
        mask_edits.set_visible_all(self.doc, *solo(tuple(a.visible for a in areas), index,
                                                   areas[index].name))

    def delete(self) -> None:
        if self.active_area() is not None:
            mask_edits.delete_area(self.doc, self.state.active)

    def move(self, step: int) -> None:
        i = self.state.active
        if self.active_area() is not None and can_move(i, step, len(self.rows)):
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
