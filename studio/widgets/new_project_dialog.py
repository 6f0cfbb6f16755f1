"""File ▸ New from Files: pick a neutral mesh, key-pose meshes and texture maps."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLineEdit,
    QMessageBox,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from studio.core.assemble import project_from_files
from studio.core.errors import StudioError
from studio.core.normalmap import flip_green
from studio.core.project import Project

MESH_FILTER = "Meshes (*.obj *.ply *.glb *.gltf *.stl *.off);;All files (*)"
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga);;All files (*)"


class FileField(QWidget):
    """A path with a Browse… button."""

    def __init__(self, caption: str, file_filter: str, placeholder: str = "") -> None:
        super().__init__()
        self.caption, self.file_filter = caption, file_filter
        self.edit = QLineEdit()
        self.edit.setPlaceholderText(placeholder)
        browse = QPushButton("Browse…")
        browse.clicked.connect(self.browse)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.edit, 1)
        layout.addWidget(browse)

    def browse(self) -> None:
        name, _ = QFileDialog.getOpenFileName(self, self.caption, self.edit.text(),
                                              self.file_filter)
        if name:
            self.edit.setText(name)

    def path(self) -> str | None:
        return self.edit.text().strip() or None


class NewProjectDialog(QDialog):
    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("New project from files")
        self.resize(640, 460)
        self.project: Project | None = None
        self.mesh = FileField("Neutral mesh", MESH_FILTER, "required: the face in its rest pose")
        self.diffuse = FileField("Diffuse map", IMAGE_FILTER, "optional: plain skin colour")
        self.normal = FileField("Neutral normal map", IMAGE_FILTER, "optional: flat")
        self.wrinkled = FileField("Wrinkled normal map", IMAGE_FILTER, "optional: flat")
        self.directx = QCheckBox("Normal maps use the DirectX convention (flip green)")
        self.poses = QTableWidget(0, 2)
        self.poses.setHorizontalHeaderLabels(["Key pose", "Mesh file"])
        self.poses.horizontalHeader().setStretchLastSection(True)
        add = QPushButton("Add key poses…")
        add.clicked.connect(self.add_poses)
        remove = QPushButton("Remove")
        remove.clicked.connect(lambda: self.poses.removeRow(self.poses.currentRow()))
        form = QFormLayout()
        form.addRow("Neutral mesh", self.mesh)
        form.addRow("Diffuse", self.diffuse)
        form.addRow("Neutral normals", self.normal)
        form.addRow("Wrinkled normals", self.wrinkled)
        form.addRow(self.directx)
        buttons = QHBoxLayout()
        buttons.addWidget(add)
        buttons.addWidget(remove)
        buttons.addStretch(1)
        box = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                               | QDialogButtonBox.StandardButton.Cancel)
        box.button(QDialogButtonBox.StandardButton.Ok).setText("Create")
        box.accepted.connect(self.create)
        box.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.poses, 1)
        layout.addLayout(buttons)
        layout.addWidget(box)

    def add_poses(self) -> None:
        names, _ = QFileDialog.getOpenFileNames(self, "Key-pose meshes", "", MESH_FILTER)
        for name in names:
            self.add_pose(Path(name).stem, name)

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
        try:
            project = project_from_files(self.mesh.path(), self.pose_files(),
                                         self.diffuse.path(), self.normal.path(),
                                         self.wrinkled.path())
        except StudioError as exc:
            QMessageBox.critical(self, "Cannot create the project", str(exc))
            return
        if self.directx.isChecked():
            textures = project.textures
            textures.normal_neutral = flip_green(textures.normal_neutral)
            textures.normal_wrinkled = flip_green(textures.normal_wrinkled)
        self.project = project
        self.accept()
