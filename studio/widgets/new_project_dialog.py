"""File ▸ New from Files: pick a neutral mesh, key-pose meshes and texture maps.

When the neutral mesh is an OBJ with several objects, groups or materials, a table lists them:
keep them all or only the ticked ones (the key poses are cut the same way), and tick the parts
that are not skin (eyes, teeth) so they never wrinkle — suggested by name, as small closed
shells, and as parts the key poses move rigidly. A glTF's meshes and materials are listed
the same way, with what was found already ticked: the meshes its morph targets move kept, its
eyes and teeth not face. A VRM is a glTF; an FBX's or a USD stage's face is found the same
way, without a table (reading an FBX takes a child process: too slow to do while the user types
its path).

Create hands every choice to ``studio.core.setup.new_setup.new_project``, the set-up the
command line's ``new`` runs too, so a head comes out the same both ways; what it found and
assumed is kept in ``report`` for the main window to show.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QApplication,
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDialog,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QMessageBox,
    QPushButton,
    QRadioButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from studio.core.files.errors import StudioError
from studio.core.formats.assemble import suggest_not_face, suggest_obj_choice
from studio.core.formats.gltf.codec import gltf_parts
from studio.core.mesh.file_kinds import MESHES, file_filter
from studio.core.mesh.meshio import ObjGroup, obj_groups
from studio.core.project.model import Project
from studio.core.setup.new_setup import NewSetup, new_project
from studio.widgets.app_settings import remember_folder, settings, start_folder
from studio.widgets.dialog_buttons import action_buttons
from studio.widgets.progress import progress_dialog

MESH_FILTER = file_filter()  # every kind the studio reads (core/mesh/file_kinds.py)
# a key pose is a mesh of the neutral's topology; a VRM, FBX or USD brings its own poses
POSE_FILTER = file_filter(pick=MESHES)
# Kinds of OBJ part, in the order preferred when two have as many names.
KIND_LABELS = {"mesh": "Meshes", "group": "Groups (g)", "material": "Materials",
               "object": "Objects (o)"}
GLTF = (".glb", ".gltf", ".vrm")  # scenes whose meshes and materials the parts table lists
# the face's axes offered for Up and Front: (label, parse_axis spelling; None: found)
AXIS_CHOICES = (("automatic", None), ("+X", "x"), ("-X", "-x"), ("+Y", "y"), ("-Y", "-y"),
                ("+Z", "z"), ("-Z", "-z"))
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga);;All files (*)"


class FileField(QWidget):
    """A path with a Browse… button."""

    def __init__(self, caption: str, file_filter: str, placeholder: str = "",
                 near: Callable[[], str | None] = lambda: None) -> None:
        super().__init__()
        self.caption, self.file_filter = caption, file_filter
        self.near = near  # a file the user chose already: Browse… opens beside it
        self.edit = QLineEdit()
        self.edit.setPlaceholderText(placeholder)
        browse = QPushButton("Browse…")
        browse.clicked.connect(self.browse)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.edit, 1)
        layout.addWidget(browse)

    def browse(self) -> None:
        start = start_folder(self.edit.text().strip(), self.near())
        name, _ = QFileDialog.getOpenFileName(self, self.caption, start, self.file_filter)
        if name:
            remember_folder(name)
            self.edit.setText(name)

    def path(self) -> str | None:
        return self.edit.text().strip() or None


class PartsBox(QGroupBox):
    """The OBJ's objects, groups or materials (one kind at a time: each kind splits the faces):
    which to keep, which are not face."""

    NAME, FACES, KEEP, NOT_FACE = range(4)

    def __init__(self) -> None:
        super().__init__("Parts of the mesh")
        self.groups: list[ObjGroup] = []
        self.found: tuple[set[str], set[str]] | None = None  # a glTF's kept and not-face names
        # an OBJ's suggestion for a kind of part: ({left out: why}, {not face: why}); by name
        # when unset
        self.suggest: Callable[[str], tuple[dict[str, str], dict[str, str]]] | None = None
        self.not_face_edited = False  # the user changed a not-face tick: suggestions keep off
        self.chosen = False  # the user changed the table: their choice over a glTF's finding
        self.kind = QComboBox()
        self.kind.currentIndexChanged.connect(self._fill)
        self.kind.activated.connect(self._choose)
        self.keep_all = QRadioButton("Keep all parts")
        self.keep_some = QRadioButton("Keep only the ticked parts")
        self.keep_all.setChecked(True)
        choice = QButtonGroup(self)
        choice.addButton(self.keep_all)
        choice.addButton(self.keep_some)
        self.keep_some.toggled.connect(self._enable_keep)
        for button in (self.keep_all, self.keep_some):
            button.clicked.connect(self._choose)
        self.table = QTableWidget(0, 4)
        self.table.setHorizontalHeaderLabels(["Part", "Faces", "Keep", "Not face"])
        self.table.verticalHeader().hide()
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(self.NAME, QHeaderView.ResizeMode.Stretch)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.itemChanged.connect(self._edited)
        hint = QLabel("Not face: eyes, teeth, tongue… keep their shading but never wrinkle "
                      "(a vertex is not face when all its faces are). Ticked to start with: "
                      "parts named so, small closed shells and parts the key poses only move "
                      "rigidly; helpers, hair cards and joint markers start unticked in Keep, "
                      "as 'new --auto' leaves them out (hover for why). The key poses are cut "
                      "like the neutral mesh.")
        hint.setWordWrap(True)
        top = QHBoxLayout()
        top.addWidget(QLabel("Parts by"))
        top.addWidget(self.kind)
        top.addSpacing(16)
        top.addWidget(self.keep_all)
        top.addWidget(self.keep_some)
        top.addStretch(1)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.table, 1)
        layout.addWidget(hint)

    def set_groups(self, groups: list[ObjGroup],
                   found: tuple[set[str], set[str]] | None = None) -> None:
        """Offer the parts (hidden when no kind has two); the kind with the most names is
        shown first, and likely non-skin parts start ticked as not face. ``found``: the names
        a glTF's face finding keeps and marks not face, ticked to start with."""
        self.groups, self.found = groups, found
        self.not_face_edited = self.chosen = False
        counts = {k: sum(g.kind == k for g in groups) for k in KIND_LABELS}
        kinds = [k for k in KIND_LABELS if counts[k] > 1]
        self.kind.blockSignals(True)
        self.kind.clear()
        for kind in sorted(kinds, key=lambda k: -counts[k]):
            self.kind.addItem(KIND_LABELS[kind], kind)
        self.kind.blockSignals(False)
        kept_all = found is None or all(g.name in found[0] for g in groups)
        (self.keep_all if kept_all else self.keep_some).setChecked(True)
        self._fill()
        self.setVisible(bool(kinds))

    def _fill(self) -> None:
        shown = [g for g in self.groups if g.kind == self.kind.currentData()]
        left_out, suggested = self._suggestions(shown)
        kept = self.found[0] if self.found else {g.name for g in shown} - set(left_out)
        if self.found is None and not self.chosen:  # an OBJ: helpers start unticked
            (self.keep_some if left_out else self.keep_all).setChecked(True)
        self.table.blockSignals(True)
        self.table.setRowCount(0)
        for row, group in enumerate(shown):
            self.table.insertRow(row)
            self.table.setItem(row, self.NAME, QTableWidgetItem(group.name))
            faces = QTableWidgetItem(str(group.faces))
            faces.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            self.table.setItem(row, self.FACES, faces)
            for column, ticked in ((self.KEEP, group.name in kept),
                                   (self.NOT_FACE, group.name in suggested)):
                item = QTableWidgetItem()
                item.setFlags(Qt.ItemFlag.ItemIsUserCheckable | Qt.ItemFlag.ItemIsEnabled)
                item.setCheckState(Qt.CheckState.Checked if ticked else Qt.CheckState.Unchecked)
                self.table.setItem(row, column, item)
            if group.name in suggested:
                why = f"Suggested as not face: {suggested[group.name]}"
                self.table.item(row, self.NAME).setToolTip(why)
                self.table.item(row, self.NOT_FACE).setToolTip(why)
            elif group.name in left_out:
                why = f"Suggested to leave out: {left_out[group.name]}"
                self.table.item(row, self.NAME).setToolTip(why)
                self.table.item(row, self.KEEP).setToolTip(why)
        self.table.blockSignals(False)
        self._enable_keep()

    def _suggestions(self, shown: list[ObjGroup]) -> tuple[dict[str, str], dict[str, str]]:
        """({name: why} to leave out, {name: why} to tick as not face) of the shown parts: a
        glTF's finding, else the OBJ's suggestion for this kind (what ``new --auto`` chooses:
        helpers left out; eyes, teeth, lashes not face by name, shell and rigid motion), else
        names."""
        if self.found:
            return {}, dict.fromkeys(self.found[1], "found with the face")
        if self.suggest is not None:
            QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)  # a real head: a second
            try:
                return self.suggest(self.kind.currentData())
            except StudioError:
                pass  # the file is reported at Create; names still help
            finally:
                QApplication.restoreOverrideCursor()
        return {}, dict.fromkeys(suggest_not_face(g.name for g in shown), "name")

    def resuggest(self) -> None:
        """The suggestion again (key poses were added or removed: rigid motion, or parts no
        pose moves, may show): the whole table while the user has changed nothing in it,
        else the not-face ticks unless the user has ticked or unticked some themselves."""
        if self.not_face_edited or self.isHidden():
            return
        if not self.chosen:
            self._fill()
            return
        _, suggested = self._suggestions([])
        self.table.blockSignals(True)
        self.set_ticked(self.NOT_FACE, set(suggested))
        for row in range(self.table.rowCount()):
            why = suggested.get(self.table.item(row, self.NAME).text())
            tip = f"Suggested as not face: {why}" if why else ""
            self.table.item(row, self.NAME).setToolTip(tip)
            self.table.item(row, self.NOT_FACE).setToolTip(tip)
        self.table.blockSignals(False)

    def _edited(self, item: QTableWidgetItem) -> None:
        self.chosen = True
        if item.column() == self.NOT_FACE:
            self.not_face_edited = True

    def _choose(self) -> None:
        self.chosen = True

    def follows_file(self) -> bool:
        """A glTF's table as found and left alone: its finding applies whole, as on the command
        line (the table shows one kind of part at a time, so its ticks alone could lose an
        eye that is a material of the face's mesh)."""
        return self.found is not None and not self.chosen

    def _enable_keep(self) -> None:
        """Keep ticks enabled only under "Keep only the ticked parts"; quietly (a flag's
        change emits ``itemChanged``, which is not the user choosing)."""
        flags = Qt.ItemFlag.ItemIsUserCheckable
        if self.keep_some.isChecked():
            flags |= Qt.ItemFlag.ItemIsEnabled
        quiet = self.table.blockSignals(True)
        for row in range(self.table.rowCount()):
            self.table.item(row, self.KEEP).setFlags(flags)
        self.table.blockSignals(quiet)

    def ticked(self, column: int) -> list[str]:
        return [self.table.item(r, self.NAME).text() for r in range(self.table.rowCount())
                if self.table.item(r, column).checkState() == Qt.CheckState.Checked]

    def set_ticked(self, column: int, names: set[str]) -> None:
        for row in range(self.table.rowCount()):
            name = self.table.item(row, self.NAME).text()
            self.table.item(row, column).setCheckState(
                Qt.CheckState.Checked if name in names else Qt.CheckState.Unchecked)

    def part_kind(self) -> str | None:
        return None if self.isHidden() or self.follows_file() else self.kind.currentData()

    def keep(self) -> list[str] | None:
        """The parts to keep, None for the whole file."""
        if self.isHidden() or self.follows_file() or self.keep_all.isChecked():
            return None
        return self.ticked(self.KEEP)

    def not_face(self) -> list[str] | None:
        """The ticked parts; None when no table is shown or a glTF's is left as found (the
        file's suggestion applies then)."""
        return None if self.isHidden() or self.follows_file() else self.ticked(self.NOT_FACE)


class NewProjectDialog(QDialog):
    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("New project from files")
        self.resize(680, 620)
        self.project: Project | None = None
        self.mesh = FileField("Neutral mesh", MESH_FILTER,
                              "required: the face in its rest pose (a glTF, VRM, FBX or USD "
                              "brings its key poses)")
        self.parts = PartsBox()
        self.parts.hide()
        self.mesh.edit.textChanged.connect(self.list_parts)
        beside_mesh = self.mesh.path  # maps and poses usually sit beside the neutral mesh
        self.diffuse = FileField("Diffuse map", IMAGE_FILTER, "optional: plain skin colour",
                                 beside_mesh)
        self.normal = FileField("Neutral normal map", IMAGE_FILTER, "optional: flat",
                                beside_mesh)
        self.wrinkled = FileField("Wrinkled normal map", IMAGE_FILTER, "optional: flat",
                                  beside_mesh)
        self.directx = QCheckBox("Normal maps use the DirectX convention (flip green)")
        self.auto = QCheckBox("Auto set-up from the key poses (wrinkle vectors, masks, and a "
                              "wrinkled map when none is given)")
        self.auto.setChecked(settings().value("new_project/auto", True, type=bool))
        self.auto.toggled.connect(lambda on: settings().setValue("new_project/auto", on))
        self.up = axis_choice("The head's up axis; automatic: found from the key poses' "
                              "motion or the mesh's extent (a VRM's own)")
        self.front = axis_choice("The way the face looks, at right angles to up; automatic: "
                                 "found from the way the moving skin faces (a VRM's own)")
        self.report: list[str] = []  # what was found, assumed and set up, a line each
        self.poses = QTableWidget(0, 2)
        self.poses.setHorizontalHeaderLabels(["Key pose", "Mesh file"])
        self.poses.horizontalHeader().setStretchLastSection(True)
        add = QPushButton("Add key poses…")
        add.clicked.connect(self.add_poses)
        remove = QPushButton("Remove")
        remove.clicked.connect(self.remove_pose)
        form = QFormLayout()
        form.addRow("Neutral mesh", self.mesh)
        form.addRow("Diffuse", self.diffuse)
        form.addRow("Neutral normals", self.normal)
        form.addRow("Wrinkled normals", self.wrinkled)
        form.addRow("Up", self.up)
        form.addRow("Front", self.front)
        form.addRow(self.directx)
        form.addRow(self.auto)
        buttons = QHBoxLayout()
        buttons.addWidget(add)
        buttons.addWidget(remove)
        buttons.addStretch(1)
        box = action_buttons(self, "Create", self.create)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.parts, 1)
        layout.addWidget(self.poses, 1)
        layout.addLayout(buttons)
        layout.addWidget(box)

    def list_parts(self) -> None:
        """Offer the parts of a neutral OBJ or glTF; a file that cannot be read is reported at
        Create."""
        path = Path(self.mesh.path() or "")
        groups: list[ObjGroup] = []
        found = None
        suffix = path.suffix.lower()
        if suffix in (".obj", *GLTF) and path.is_file():
            try:
                if suffix == ".obj":
                    groups = obj_groups(path)
                else:
                    groups, *chosen = gltf_parts(path)
                    found = (chosen[0], chosen[1])
            except StudioError:
                groups, found = [], None
        self.parts.suggest = (None if suffix != ".obj" or not groups else
                              lambda kind: suggest_obj_choice(path, kind, self.pose_files()))
        self.parts.set_groups(groups, found)

    def add_poses(self) -> None:
        names, _ = QFileDialog.getOpenFileNames(self, "Key-pose meshes",
                                                start_folder(self.mesh.path()), POSE_FILTER)
        if names:
            remember_folder(names[0])
        for name in names:
            self.add_pose(Path(name).stem, name)
        if names:
            self.parts.resuggest()

    def remove_pose(self) -> None:
        self.poses.removeRow(self.poses.currentRow())
        self.parts.resuggest()

    def add_pose(self, name: str, path: str) -> None:
        row = self.poses.rowCount()
        self.poses.insertRow(row)
        self.poses.setItem(row, 0, QTableWidgetItem(name))
        self.poses.setItem(row, 1, QTableWidgetItem(path))

    def pose_files(self) -> dict[str, str]:
        return {self.poses.item(r, 0).text().strip(): self.poses.item(r, 1).text().strip()
                for r in range(self.poses.rowCount())}

    def create(self) -> None:
        if self.mesh.path() is None:
            QMessageBox.warning(self, "New project", "Choose the neutral mesh first.")
            return
        made = self._make()
        if made is None:  # a bad file, said; or the set-up cancelled: the dialog stays
            return
        self.project = made.project
        self.report = [*made.found, f"Assumed: {made.assumed}.", *(made.done or [])]
        self.accept()

    def _make(self) -> NewSetup | None:
        """The project, set up as ``wrinkle-studio new`` sets it up; None after telling the
        user what is wrong with which file, or when they cancelled the auto set-up."""
        auto = self.auto.isChecked()
        progress, step = (progress_dialog(self, "Auto set-up",
                                          "Setting up wrinkles from the key poses…")
                          if auto else (None, None))
        QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
        made, error = None, None
        try:
            made = new_project(self.mesh.path(), self.pose_files(), self.diffuse.path(),
                               self.normal.path(), self.wrinkled.path(),
                               flip=self.directx.isChecked(), keep=self.parts.keep(),
                               not_face=self.parts.not_face(),
                               part_kind=self.parts.part_kind(), up=self.up.currentData(),
                               front=self.front.currentData(), auto=auto, progress=step)
        except StudioError as exc:
            error = str(exc)
        finally:
            QApplication.restoreOverrideCursor()
            if progress is not None:
                progress.close()
        if error is not None:
            QMessageBox.critical(self, "Cannot create the project", error)
            return None
        return made if made is not None and made.done is not None else None


def axis_choice(tip: str) -> QComboBox:
    """Automatic, or one of the six axes (the data: ``parse_axis``'s spelling)."""
    box = QComboBox()
    for label, axis in AXIS_CHOICES:
        box.addItem(label, axis)
    box.setToolTip(tip)
    return box
