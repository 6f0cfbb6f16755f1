"""Texture maps and engine export in the GUI: the Maps menu (replace a map, wrinkled normals from
a height map, flip green) and File ▸ Export. Every map change is one undo step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtGui import QUndoCommand
from PySide6.QtWidgets import QFileDialog, QInputDialog, QMenu

from studio.core.errors import StudioError
from studio.core.images import load_grey, load_rgb
from studio.core.normalmap import flip_green, height_to_normal
from studio.widgets.document import Document

MAPS = {"diffuse": "Diffuse map", "normal_neutral": "Neutral normal map",
        "normal_wrinkled": "Wrinkled normal map"}
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga);;All files (*)"


class SetMapCommand(QUndoCommand):
    """Replace one texture map; keeps both images (maps are replaced whole, rarely)."""

    def __init__(self, doc: Document, attribute: str, image: np.ndarray, text: str) -> None:
        super().__init__(text)
        self.doc, self.attribute = doc, attribute
        self.old = getattr(doc.project.textures, attribute)
        self.new = image

    def _apply(self, image: np.ndarray) -> None:
        setattr(self.doc.project.textures, self.attribute, image)
        self.doc.texturesChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)

    def nbytes(self) -> int:
        return self.old.nbytes + self.new.nbytes


class MapTools:
    def __init__(self, window) -> None:
        self.window = window

    @property
    def doc(self) -> Document:
        return self.window.doc

    def _ask_image(self, caption: str) -> Path | None:
        name, _ = QFileDialog.getOpenFileName(self.window, caption, "", IMAGE_FILTER)
        return Path(name) if name else None

    def replace(self, attribute: str) -> None:
        path = self._ask_image(f"Replace the {MAPS[attribute].lower()}")
        if path is None:
            return
        try:
            image = load_rgb(path)
        except StudioError as exc:
            self.window.show_error("Cannot use that image", exc)
            return
        self.doc.undo_stack.push(SetMapCommand(self.doc, attribute, image,
                                               f"Replace {MAPS[attribute].lower()}"))

    def from_height(self) -> None:
        path = self._ask_image("Height map for the wrinkled normals (white = high)")
        if path is None:
            return
        strength, ok = QInputDialog.getDouble(
            self.window, "Wrinkled normals from a height map",
            "Strength (slope of one height unit per texel):", 4.0, 0.01, 1000.0, 2)
        if not ok:
            return
        try:
            image = height_to_normal(load_grey(path), strength)
        except StudioError as exc:
            self.window.show_error("Cannot use that image", exc)
            return
        self.doc.undo_stack.push(SetMapCommand(self.doc, "normal_wrinkled", image,
                                               "Wrinkled normals from height map"))

    def flip(self, attribute: str) -> None:
        image = flip_green(getattr(self.doc.project.textures, attribute))
        self.doc.undo_stack.push(SetMapCommand(self.doc, attribute, image,
                                               f"Flip green of {MAPS[attribute].lower()}"))

    def export_gltf(self) -> None:
        name, _ = QFileDialog.getSaveFileName(self.window, "Export glTF",
                                              f"{self.doc.display_name}.glb",
                                              "Binary glTF (*.glb)")
        if name:
            from studio.core.gltf import save_gltf

            self._export(lambda: save_gltf(self.doc.project, Path(name)), name)

    def export_folder(self) -> None:
        name = QFileDialog.getExistingDirectory(self.window, "Export for a game engine")
        if name:
            from studio.core.export import export_folder

            self._export(lambda: export_folder(self.doc.project, name), name)

    def _export(self, write, target: str) -> None:
        try:
            write()
        except StudioError as exc:
            self.window.show_error("Cannot export", exc)
            return
        self.window.statusBar().showMessage(f"Exported to {target}", 5000)


def install_map_tools(window) -> MapTools:
    tools = MapTools(window)
    bar = window.menuBar()
    menu = QMenu("&Maps", window)
    for attribute, label in MAPS.items():
        menu.addAction(f"Replace {label}…", lambda a=attribute: tools.replace(a))
    menu.addSeparator()
    menu.addAction("Wrinkled Normal Map from Height Map…", tools.from_height)
    menu.addSeparator()
    for attribute in ("normal_neutral", "normal_wrinkled"):
        menu.addAction(f"Flip Green of {MAPS[attribute]} (DirectX ↔ OpenGL)",
                       lambda a=attribute: tools.flip(a))
    help_action = next(a for a in bar.actions() if a.text().replace("&", "") == "Help")
    bar.insertMenu(help_action, menu)
    file_menu = next(a.menu() for a in bar.actions() if a.text().replace("&", "") == "File")
    quit_action = file_menu.actions()[-1]
    export = QMenu("E&xport", window)
    export.addAction("glTF (.glb)…", tools.export_gltf)
    export.addAction("Folder for a Game Engine…", tools.export_folder)
    file_menu.insertMenu(quit_action, export)
    window.map_tools = tools
    return tools
