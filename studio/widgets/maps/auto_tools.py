"""Starting points the studio derives by itself, in a Tools menu (issues 8 and 10):

- **Auto Setup from Poses**: for every key pose, a wrinkle-vector area and a soft mask linked to
  it (studio.core.setup.auto_setup), as one undo step;
- **Convert Automatic Wrinkles to Mask / to WDV Area**: what the strain mode shows at the current
  pose weights, made editable, one undo step each;
- **Synthesise Wrinkled Normal Map…**: furrows from the poses' compression
  (studio.core.setup.wrinkle_synth), added as a named wrinkled map (or replacing one), one undo
  step; recorded with its options, as the set-up's maps are, so the Furrows panel's controls
  make it again (drawn by ``furrow_maps.FurrowMaps.draw``, the one way every map is drawn).

``install_auto_tools(window)`` is the one call the main window makes. The undo steps reuse the
editors' commands: the area lists of techniques 1 and 2 (mask_edits.AreasCommand,
wdv_edits.AreaListCommand; both under one macro undo as one step) and the Maps menu's
(map_tools.WrinkleMapsCommand: the maps and which map each area reveals, together).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMessageBox,
    QVBoxLayout,
)

from studio.core.files.errors import StudioError
from studio.core.files.naming import unique_name
from studio.core.setup import auto_setup
from studio.core.setup.face_frame import face_locator
from studio.core.setup.furrow_maps import FurrowMaps
from studio.core.setup.wrinkle_synth import (
    SynthOptions,
    default_size,
    face_options,
    is_flat,
)
from studio.core.wrinkles.furrow_controls import SynthesisedMap, map_digest
from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS
from studio.widgets.dialog_buttons import action_buttons
from studio.widgets.document import Document
from studio.widgets.maps.furrow_controls import push_furrows
from studio.widgets.maps.map_tools import WrinkleMapsCommand
from studio.widgets.paint.edits import AreasCommand
from studio.widgets.progress import progress_dialog
from studio.widgets.wdv.edits import AreaListCommand

MAP_SIZES = (512, 1024, 2048, 4096)
SYNTH_NAME = "synthesised"


class SynthDialog(QDialog):
    """Spacing, depth, size, which poses, and which map the result becomes."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self.setWindowTitle("Synthesise Wrinkled Normal Map")
        project = window.doc.project
        textures = project.textures
        names = textures.wrinkle_map_names
        full = len(names) >= MAX_WRINKLE_MAPS
        layout = QVBoxLayout(self)
        intro = QLabel("Furrows are laid across the direction in which each pose compresses the "
                       "skin, deeper where it compresses more.")
        intro.setWordWrap(True)
        layout.addWidget(intro)
        form = QFormLayout()
        self.map_name = QComboBox()
        self.map_name.setEditable(not full)
        self.map_name.addItems(names)
        flat = next((n for n in names if is_flat(textures.wrinkle_maps[n])), None)
        default = flat or (names[-1] if full else unique_name(SYNTH_NAME, names))
        if default not in names:
            self.map_name.insertItem(0, default)
        self.map_name.setCurrentText(default)
        self.map_name.setToolTip("A new name adds a wrinkled map; an existing one is replaced")
        self.map_name.currentTextChanged.connect(self._show_target)
        form.addRow("Wrinkled map:", self.map_name)
        self.target = QLabel()
        self.target.setWordWrap(True)
        form.addRow("", self.target)
        current = default_size(textures)
        suggested = face_options(project, current)  # furrows scaled to this face's size
        self.spacing = QDoubleSpinBox()
        self.spacing.setRange(3.0, 128.0)
        self.spacing.setValue(suggested.spacing)
        self.spacing.setSuffix(" texels")
        self.spacing.setToolTip("Distance between neighbouring furrows, at the map's size")
        form.addRow("Furrow spacing:", self.spacing)
        self.depth = QDoubleSpinBox()
        self.depth.setRange(0.1, 20.0)
        self.depth.setSingleStep(0.25)
        self.depth.setValue(suggested.depth)
        self.depth.setSuffix(" texels")
        self.depth.setToolTip("Depth of a furrow where the skin is fully compressed")
        form.addRow("Furrow depth:", self.depth)
        self.size = QComboBox()
        for s in MAP_SIZES:
            self.size.addItem(f"{s} × {s}", s)
        self.size.setCurrentIndex(int(np.argmin([abs(s - current) for s in MAP_SIZES])))
        form.addRow("Map size:", self.size)
        self.size.currentIndexChanged.connect(lambda _: self._scale_furrows(project))
        self.poses = QListWidget()
        for pose in project.poses:
            item = QListWidgetItem(pose.name)
            item.setFlags(item.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            item.setCheckState(Qt.CheckState.Checked)
            self.poses.addItem(item)
        self.poses.setMaximumHeight(140)
        self.poses.itemChanged.connect(lambda _item: self._show_target(
            self.map_name.currentText()))
        form.addRow("From poses:", self.poses)
        self.over_neutral = QCheckBox("Keep the neutral normal map's detail (pores) under the "
                                      "furrows")
        self.over_neutral.setChecked(True)
        form.addRow("", self.over_neutral)
        self.reveal = QCheckBox("Areas that follow these poses reveal this map")
        self.reveal.setToolTip("Technique-1 areas linked to a chosen pose and technique-2 areas "
                               "made from one show this map's wrinkles (undo puts them back)")
        self.reveal.setChecked(True)
        form.addRow("", self.reveal)
        layout.addLayout(form)
        self.buttons = action_buttons(self, "Synthesise", self.accept)
        layout.addWidget(self.buttons)
        self._names = names
        self._full = full
        self._show_target(self.map_name.currentText())

    def _show_target(self, name: str) -> None:
        name = name.strip()
        if name in self._names:
            text = f"Replaces the wrinkled map “{name}” (undo brings it back)."
            if self._full:
                text = (f"This face has {MAX_WRINKLE_MAPS} wrinkled maps, the most it can have: "
                        + text)
        else:
            text = "Adds a new wrinkled map."
        self.target.setText(text)
        ok = self.buttons.button(QDialogButtonBox.StandardButton.Ok)
        ok.setEnabled(bool(name) and bool(self.chosen_poses()))

    def _scale_furrows(self, project) -> None:
        """Keep the furrows the same on the face when the map's size changes."""
        options = face_options(project, int(self.size.currentData()))
        self.spacing.setValue(options.spacing)
        self.depth.setValue(options.depth)

    def chosen_poses(self) -> list[str]:
        items = (self.poses.item(i) for i in range(self.poses.count()))
        return [it.text() for it in items if it.checkState() == Qt.CheckState.Checked]

    def options(self) -> SynthOptions:
        return SynthOptions(size=int(self.size.currentData()), spacing=self.spacing.value(),
                            depth=self.depth.value())


class AutoTools:
    def __init__(self, window) -> None:
        self.window = window

    @property
    def doc(self) -> Document:
        return self.window.doc

    def _say(self, text: str) -> None:
        self.window.statusBar().showMessage(text, 8000)

    def _push_areas(self, text: str, influence=(), links=None, wdv=()) -> None:
        """New technique-1 and technique-2 areas (and links) after the existing ones, as one
        undo step."""
        doc, stack = self.doc, self.doc.undo_stack
        stack.beginMacro(text)
        if influence or links:
            merged = auto_setup.merged_links(doc.project.influence.links, links or {})
            stack.push(AreasCommand(doc, text, [*doc.project.influence.areas, *influence],
                                    merged))
        if wdv:
            stack.push(AreaListCommand(doc, [*doc.project.wdv.areas, *wdv], text))
        stack.endMacro()

    # --- Auto Setup ------------------------------------------------------------------
    def run_auto_setup(self) -> auto_setup.AutoSetupReport | None:
        project = self.doc.project
        if not project.poses:
            QMessageBox.information(self.window, "Auto Setup",
                                    "This face has no key poses to start from.")
            return None
        progress, step = progress_dialog(self.window, "Auto Setup",
                                         "Measuring how each key pose moves the skin…")
        try:
            frame = self.doc.face_frame()
            report = auto_setup.suggest_setup(project, progress=step, locate=face_locator(frame),
                                              frame=frame)
        except StudioError as exc:
            self.window.show_error("Cannot set up from the poses", exc)
            return None
        finally:
            progress.close()
        if report is None:  # cancelled
            return None
        if not report.empty:
            self._push_areas("Auto Setup from Poses", report.influence_areas, report.links,
                             report.wdv_areas)
        if report.empty or report.still_poses or report.flat_poses:
            QMessageBox.information(self.window, "Auto Setup",
                                    "\n".join([report.summary(), *report.pose_lines()]))
        else:
            self._say(report.summary())
        return report

    # --- strain → editable -----------------------------------------------------------
    def strain_to_mask(self) -> None:
        try:
            area, links = auto_setup.strain_mask(self.doc.project, self.doc.pose_weights)
        except StudioError as exc:
            self.window.show_error("Cannot convert the automatic wrinkles", exc)
            return
        self._push_areas(f"Automatic wrinkles to mask {area.name}", [area], links)
        self._say(f"Added the mask “{area.name}”, linked to {', '.join(links)}")

    def strain_to_wdv(self) -> None:
        try:
            area = auto_setup.strain_wdv_area(self.doc.project, self.doc.pose_weights)
        except StudioError as exc:
            self.window.show_error("Cannot convert the automatic wrinkles", exc)
            return
        self._push_areas(f"Automatic wrinkles to WDV area {area.name}", wdv=[area])
        self._say(f"Added the wrinkle-vector area “{area.name}” ({int(area.authored.sum())} "
                  f"vectors, pose “{area.pose}”)")

    # --- a synthesised wrinkled map --------------------------------------------------
    def synthesise_dialog(self) -> None:
        if not self.doc.project.poses:
            QMessageBox.information(self.window, "Synthesise Wrinkled Normal Map",
                                    "This face has no key poses to synthesise wrinkles from.")
            return
        dialog = SynthDialog(self.window)
        if dialog.exec() != QDialog.DialogCode.Accepted:
            return
        self.synthesise(dialog.map_name.currentText().strip(), dialog.chosen_poses(),
                        dialog.options(), dialog.over_neutral.isChecked(),
                        dialog.reveal.isChecked())

    def _set_wrinkle_map(self, name: str, image: np.ndarray, record: SynthesisedMap,
                         reveal: bool) -> None:
        """Add the named wrinkled map or replace it, with its record (so the Furrows panel's
        controls make it again, as they do the set-up's maps), and with ``reveal`` let the
        areas of its poses reveal it: one undo step."""
        doc = self.doc
        maps = doc.project.textures.wrinkle_maps
        if name not in maps and len(maps) >= MAX_WRINKLE_MAPS:
            raise StudioError(f"a face can have at most {MAX_WRINKLE_MAPS} wrinkled maps; "
                              "choose one to replace")
        areas = auto_setup.areas_of_poses(doc.project, list(record.poses)) if reveal else []
        text = f"Synthesise wrinkled map {name}"
        doc.undo_stack.beginMacro(text)
        doc.undo_stack.push(WrinkleMapsCommand(
            doc, {**maps, name: image}, {id(a): name for a in areas}, text))
        push_furrows(doc, doc.project.furrows.with_map(name, record), text, None)
        doc.undo_stack.endMacro()
        self._furrow_maps().took(doc.project, name)

    def _furrow_maps(self) -> FurrowMaps:
        """The Furrows panel's maps (their poses' fields kept for its controls' remakes)."""
        panel = getattr(self.window, "furrow_panel", None)
        return panel.maps if panel is not None else FurrowMaps()

    def synthesise(self, name: str, poses: list[str], options: SynthOptions,
                   over_neutral: bool = True, reveal: bool = True) -> bool:
        """Run the synthesis with a progress dialog (shown if it takes more than a moment);
        True when a map was added or replaced, False if cancelled or refused."""
        progress, step = progress_dialog(self.window, "Synthesise Wrinkled Normal Map",
                                         "Synthesising the wrinkled normal map…")
        project = self.doc.project
        record = SynthesisedMap(tuple(poses), options.spacing, options.depth, anatomy=False,
                                over_neutral=over_neutral)
        try:
            if not poses:
                raise StudioError("a wrinkled map is synthesised from key poses, and none "
                                  "was chosen")
            image = self._furrow_maps().draw(project, record, project.furrows, options.size,
                                             step)
            if image is not None:
                self._set_wrinkle_map(name, image,
                                      replace(record, digest=map_digest(image)), reveal)
        except StudioError as exc:
            self.window.show_error("Cannot synthesise the wrinkled map", exc)
            return False
        finally:
            progress.close()
        if image is None:
            return False
        self._say(f"Synthesised the wrinkled map “{name}” from {', '.join(poses)}")
        return True


def install_auto_tools(window) -> AutoTools:
    tools = AutoTools(window)
    menu = window.menus["Tools"]
    if menu.actions():
        menu.addSeparator()
    menu.addAction("Auto Setup from Poses", tools.run_auto_setup).setStatusTip(
        "For every key pose: wrinkle vectors where it moves the skin and a soft mask where it "
        "compresses it, linked to it")
    menu.addSeparator()
    menu.addAction("Convert Automatic Wrinkles to Mask", tools.strain_to_mask).setStatusTip(
        "What the automatic mode shows at the current pose, as an editable technique-1 mask")
    menu.addAction("Convert Automatic Wrinkles to WDV Area", tools.strain_to_wdv).setStatusTip(
        "What the automatic mode shows at the current pose, as editable wrinkle vectors")
    menu.addSeparator()
    menu.addAction("Synthesise Wrinkled Normal Map…", tools.synthesise_dialog).setStatusTip(
        "Furrows across the direction each pose compresses the skin, as a new wrinkled map")
    window.auto_tools = tools
    window.auto_menu = menu
    return tools
