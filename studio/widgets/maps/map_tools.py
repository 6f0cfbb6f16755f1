"""Texture maps and engine export in the GUI: the Maps menu (replace a map, wrinkled normals from
a height map, flip green) and File ▸ Export. Every map change is one undo step."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoCommand
from PySide6.QtWidgets import QApplication, QFileDialog, QInputDialog, QMenu

from studio.core.files.errors import StudioError
from studio.core.files.images import load_grey, load_rgb
from studio.core.files.naming import unique_name
from studio.core.wrinkles.normalmap import flip_green, height_to_normal
from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS, FaceTextures
from studio.widgets.app_settings import remember_folder, start_folder
from studio.widgets.document import Document
from studio.widgets.maps.image_swap import ImageSwapCommand
from studio.widgets.maps.tone_tools import ToneTools

MAPS = {"diffuse": "Diffuse map", "normal_neutral": "Neutral normal map",
        "normal_wrinkled": "Wrinkled normal map"}
WRINKLED = "wrinkled:"  # map keys "wrinkled:NAME" name one of several wrinkled maps
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga);;All files (*)"


SAY_MS = 15000  # where an export wrote: long enough to read a path


def map_label(key: str) -> str:
    if key.startswith(WRINKLED):
        return f"wrinkled map “{key[len(WRINKLED):]}”"
    return MAPS[key].lower()


def get_map(textures: FaceTextures, key: str) -> np.ndarray:
    if key.startswith(WRINKLED):
        return textures.wrinkle_maps[key[len(WRINKLED):]]
    return getattr(textures, key)


def set_map(textures: FaceTextures, key: str, image: np.ndarray) -> None:
    if key.startswith(WRINKLED):
        textures.set_wrinkle_map(key[len(WRINKLED):], image)
    else:
        setattr(textures, key, image)


class SetMapCommand(ImageSwapCommand):
    """Replace one texture map; keeps both images (maps are replaced whole, rarely)."""

    def __init__(self, doc: Document, attribute: str, image: np.ndarray, text: str) -> None:
        super().__init__(doc, get_map(doc.project.textures, attribute), image, text,
                         lambda new: set_map(doc.project.textures, attribute, new))


class WrinkleMapsCommand(QUndoCommand):
    """Adds, renames or removes wrinkled maps: the set of maps and which map every area reveals
    change together (areas refer to maps by name). Keeps references, never copies images."""

    def __init__(self, doc: Document, maps: dict[str, np.ndarray],
                 area_maps: dict[int, str] | None, text: str) -> None:
        super().__init__(text)
        self.doc = doc
        project = doc.project
        self.areas = [*project.influence.areas, *project.wdv.areas]
        textures = project.textures
        self.old = (dict(textures.wrinkle_maps), [a.wrinkle_map for a in self.areas],
                    (dict(textures.cavity_maps), dict(textures.colour_maps)))
        names = [area_maps.get(id(a), a.wrinkle_map) if area_maps else a.wrinkle_map
                 for a in self.areas]
        self.new = (dict(maps), names, textures.tone_for(maps))

    def _apply(self, state: tuple) -> None:
        maps, names, (cavity, colour) = state
        textures = self.doc.project.textures
        textures.wrinkle_maps = dict(maps)
        textures.cavity_maps, textures.colour_maps = dict(cavity), dict(colour)
        for area, name in zip(self.areas, names, strict=True):
            area.wrinkle_map = name
        self.doc.texturesChanged.emit()
        self.doc.areasChanged.emit()
        self.doc.wdvChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)


class MapTools:
    def __init__(self, window) -> None:
        self.window = window
        self.tone = ToneTools(self)  # each wrinkled map's cavity and colour maps

    @property
    def doc(self) -> Document:
        return self.window.doc

    def _ask_image(self, caption: str) -> Path | None:
        start = start_folder(self.doc.path, self.doc.project.mesh.source)
        name, _ = QFileDialog.getOpenFileName(self.window, caption, start, IMAGE_FILTER)
        if name:
            remember_folder(name)
        return Path(name) if name else None

    def _load(self, load, path: Path):
        try:
            return load(path)
        except StudioError as exc:
            self.window.show_error("Cannot use that image", exc)
            return None

    def replace(self, key: str) -> None:
        label = map_label(key)
        path = self._ask_image(f"Replace the {label}")
        image = self._load(load_rgb, path) if path else None
        if image is not None:
            self.doc.undo_stack.push(SetMapCommand(self.doc, key, image, f"Replace {label}"))

    def _height_normals(self, caption: str) -> np.ndarray | None:
        path = self._ask_image(caption)
        if path is None:
            return None
        strength, ok = QInputDialog.getDouble(
            self.window, "Wrinkled normals from a height map",
            "Strength (slope of one height unit per texel):", 4.0, 0.01, 1000.0, 2)
        if not ok:
            return None
        height = self._load(load_grey, path)
        return None if height is None else height_to_normal(height, strength)

    def from_height(self, key: str = "normal_wrinkled") -> None:
        image = self._height_normals("Height map for the wrinkled normals (white = high)")
        if image is not None:
            self.doc.undo_stack.push(SetMapCommand(
                self.doc, key, image, f"{map_label(key).capitalize()} from height map"))

    def flip(self, key: str) -> None:
        label = map_label(key)
        image = flip_green(get_map(self.doc.project.textures, key))
        self.doc.undo_stack.push(SetMapCommand(self.doc, key, image, f"Flip green of {label}"))

    def _ask_name(self, title: str, default: str) -> str | None:
        name, ok = QInputDialog.getText(self.window, title, "Name of the wrinkled map:",
                                        text=default)
        name = name.strip()
        if not ok or not name:
            return None
        if name in self.doc.project.textures.wrinkle_maps:
            self.window.show_error("Cannot name the map", StudioError(
                f"there is already a wrinkled map called “{name}”"))
            return None
        return name

    def add_wrinkled(self, from_height: bool = False) -> None:
        textures = self.doc.project.textures
        if len(textures.wrinkle_maps) >= MAX_WRINKLE_MAPS:
            self.window.show_error("Cannot add a wrinkled map", StudioError(
                f"a face can have at most {MAX_WRINKLE_MAPS} wrinkled maps; replace or remove "
                "one"))
            return
        name = self._ask_name("Add a wrinkled normal map",
                              unique_name("wrinkles", textures.wrinkle_maps))
        if name is None:
            return
        if from_height:
            image = self._height_normals(f"Height map for “{name}” (white = high)")
        else:
            path = self._ask_image(f"Normal map for “{name}”")
            image = self._load(load_rgb, path) if path else None
        if image is not None:
            maps = {**textures.wrinkle_maps, name: image}
            self.doc.undo_stack.push(WrinkleMapsCommand(self.doc, maps, None,
                                                        f"Add wrinkled map {name}"))

    def rename_wrinkled(self, old: str) -> None:
        new = self._ask_name(f"Rename wrinkled map “{old}”", old)
        if new is None:
            return
        project = self.doc.project
        maps = {new if k == old else k: v for k, v in project.textures.wrinkle_maps.items()}
        renamed = {id(a): new for a in [*project.influence.areas, *project.wdv.areas]
                   if a.wrinkle_map == old}
        self.doc.undo_stack.push(WrinkleMapsCommand(self.doc, maps, renamed,
                                                    f"Rename wrinkled map {old}"))

    def remove_wrinkled(self, name: str) -> None:
        """Areas that revealed it fall back to the first remaining map (undo restores them)."""
        maps = dict(self.doc.project.textures.wrinkle_maps)
        if len(maps) == 1:
            self.window.show_error("Cannot remove the map", StudioError(
                "a face needs at least one wrinkled map; replace it instead"))
            return
        del maps[name]
        project = self.doc.project
        fallback = {id(a): "" for a in [*project.influence.areas, *project.wdv.areas]
                    if a.wrinkle_map == name}
        self.doc.undo_stack.push(WrinkleMapsCommand(self.doc, maps, fallback,
                                                    f"Remove wrinkled map {name}"))

    def fill_wrinkled_menu(self, menu: QMenu) -> None:
        """One submenu per wrinkled map, rebuilt each time the Maps menu opens."""
        menu.clear()
        for name in self.doc.project.textures.wrinkle_map_names:
            key = WRINKLED + name
            sub = menu.addMenu(name)
            sub.addAction("Replace…", lambda k=key: self.replace(k))
            sub.addAction("From Height Map…", lambda k=key: self.from_height(k))
            sub.addAction("Flip Green (DirectX ↔ OpenGL)", lambda k=key: self.flip(k))
            self.tone.add_actions(sub, name)
            sub.addSeparator()
            sub.addAction("Rename…", lambda n=name: self.rename_wrinkled(n))
            sub.addAction("Remove", lambda n=name: self.remove_wrinkled(n))
        menu.addSeparator()
        menu.addAction("Add Wrinkled Map…", self.add_wrinkled)
        menu.addAction("Add Wrinkled Map from Height Map…", lambda: self.add_wrinkled(True))

    def _beside_project(self, name: str) -> str:
        """Where an export's dialog starts: beside the project file (as Blender's exporters
        start beside the .blend), else beside the face's mesh or in the last folder chosen —
        never the folder the studio happened to be started from."""
        return str(Path(start_folder(self.doc.path, self.doc.project.mesh.source)) / name)

    def export_gltf(self) -> None:
        name, _ = QFileDialog.getSaveFileName(
            self.window, "Export glTF", self._beside_project(f"{self.doc.display_name}.glb"),
            "Binary glTF (*.glb)")
        if name:
            from studio.core.formats.gltf.codec import save_gltf

            path = Path(name) if name.lower().endswith(".glb") else Path(name + ".glb")
            self._export(lambda: save_gltf(self.doc.project, path,
                                           self.doc.view.tangent_frame), str(path))

    def export_web(self) -> None:
        """File ▸ Export ▸ Web Page…: the face as the viewport shows it now (camera, light,
        blend, tangent frame), with its timeline, in one self-contained index.html that any
        browser opens without a network (core/formats/web_export.py). The folder is named in a
        save dialog, which takes a new name typed in it (a folder dialog takes only folders
        that exist); an existing folder chosen there is written into."""
        folder, _ = QFileDialog.getSaveFileName(
            self.window, "Export a web page: the folder for its index.html",
            self._beside_project(f"{self.doc.display_name} web page"), "Folder (*)",
            options=QFileDialog.Option.DontConfirmOverwrite)
        if not folder:
            return
        from studio.core.files.safe_io import check_output_folder
        from studio.core.formats.web_export import export_web
        from studio.render.settings import web_look

        def write() -> None:
            check_output_folder(folder, what="web folder")
            export_web(self.doc.project, folder, copy.deepcopy(self.doc.camera),
                       web_look(self.doc.view))

        self._export(write, str(Path(folder) / "index.html"))

    def export_folder(self) -> None:
        """The folder and engine layout in a dialog (widgets/engine_export_dialog.py)."""
        from studio.widgets.engine_export_dialog import open_engine_export

        open_engine_export(self.window)

    def _export(self, write, target: str) -> None:
        QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)  # a real head: seconds
        try:
            beside = write()  # a glTF export: the files written beside it
        except StudioError as exc:
            QApplication.restoreOverrideCursor()
            self.window.show_error("Cannot export", exc)
            return
        QApplication.restoreOverrideCursor()
        also = f" (beside it: {', '.join(p.name for p in beside)})" if beside else ""
        self.window.statusBar().showMessage(f"Exported to {Path(target).resolve()}{also}", SAY_MS)


def install_map_tools(window) -> MapTools:
    tools = MapTools(window)
    menu = window.menus["Maps"]
    for key in ("diffuse", "normal_neutral"):
        menu.addAction(f"Replace {MAPS[key]}…", lambda k=key: tools.replace(k))
    menu.addAction("Flip Green of Neutral Normal Map (DirectX ↔ OpenGL)",
                   lambda: tools.flip("normal_neutral"))
    menu.addSeparator()
    wrinkled = menu.addMenu("&Wrinkled Normal Maps")
    menu.aboutToShow.connect(lambda: tools.fill_wrinkled_menu(wrinkled))
    tools.fill_wrinkled_menu(wrinkled)
    export = QMenu("E&xport", window)
    export.addAction("glTF (.glb)…", tools.export_gltf)
    export.addAction("Folder for a Game Engine…", tools.export_folder)
    export.addAction("Web Page…", tools.export_web)
    window.menus["File"].insertMenu(window.quit_action, export)
    window.map_tools = tools
    return tools
