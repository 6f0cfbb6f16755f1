"""Maps ▸ Bake Wrinkled Normal Map from High-Poly Mesh…: the sculpt's wrinkles become a wrinkled
normal map (studio.core.wrinkles.bake), on a worker thread behind a progress dialog whose Cancel
stops it. The result replaces the chosen wrinkled map as one undo step (map_tools.SetMapCommand)."""

from __future__ import annotations

import math
import threading
from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, Qt, QThread, Signal, Slot
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QMessageBox,
    QProgressDialog,
    QVBoxLayout,
)

from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import load_mesh
from studio.core.mesh.uv_tiles import UvTiles
from studio.core.wrinkles.bake import (
    DISTANCE_SHARE,
    BakeCancelled,
    BakeResult,
    bake_normal_map,
    default_max_distance,
    sculpt_for,
)
from studio.widgets.dialog_buttons import action_buttons
from studio.widgets.document import Document
from studio.widgets.maps.map_tools import WRINKLED, SetMapCommand, get_map, map_label
from studio.widgets.new_project_dialog import MESH_FILTER, FileField

RESOLUTIONS = (512, 1024, 2048, 4096)
LOW_HITS = 0.5  # below this share of texels hitting the high mesh, the user is warned


class BakeDialog(QDialog):
    """Asks for the high-polygon mesh, the map to replace, its resolution and how far rays may
    go; the resolution follows the chosen map's."""

    def __init__(self, parent, mesh: FaceMesh, maps: dict[str, np.ndarray]) -> None:
        super().__init__(parent)
        self.setWindowTitle("Bake Wrinkled Normal Map")
        self.mesh = FileField("High-polygon mesh", MESH_FILTER,
                              "the sculpt with the wrinkles, on the face's UV layout")
        self.target = QComboBox()
        for name in maps:
            self.target.addItem(name, WRINKLED + name)
        self.target.setEnabled(len(maps) > 1)
        self.resolution = QComboBox()
        for size in RESOLUTIONS:
            self.resolution.addItem(f"{size} × {size}", size)

        def follow(index: int) -> None:
            width = maps[self.target.itemText(index)].shape[1]
            self.resolution.setCurrentIndex(
                RESOLUTIONS.index(width) if width in RESOLUTIONS else 1)

        self.target.currentIndexChanged.connect(follow)
        follow(0)
        default = default_max_distance(mesh)
        diagonal = default / DISTANCE_SHARE
        decimals = max(3, 4 - math.floor(math.log10(diagonal)))
        self.distance = QDoubleSpinBox()
        self.distance.setDecimals(decimals)
        self.distance.setRange(10.0 ** -decimals, diagonal)
        self.distance.setValue(default)
        self.distance.setSingleStep(default / 4)
        note = QLabel(f"Rays go both ways along the face's normals, up to this far, and take the "
                      f"nearest surface of the high-polygon mesh (the face is {diagonal:.4g} "
                      "units across its bounding box). The result replaces the wrinkled map; "
                      "Undo brings the old one back.")
        note.setWordWrap(True)
        form = QFormLayout()
        form.addRow("High-poly mesh", self.mesh)
        form.addRow("Into wrinkled map", self.target)
        form.addRow("Resolution", self.resolution)
        form.addRow("Max ray distance", self.distance)
        box = action_buttons(self, "Bake", self._accept)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(note)
        layout.addWidget(box)
        self.resize(560, 0)

    def _accept(self) -> None:
        if self.mesh.path() is None:
            QMessageBox.warning(self, "Bake", "Choose the high-polygon mesh first.")
            return
        self.accept()

    def map_size(self) -> int:
        return int(self.resolution.currentData())

    def map_key(self) -> str:
        return str(self.target.currentData())


class BakeWorker(QThread):
    """Loads the high mesh and bakes, off the GUI thread; ``cancel`` stops it between chunks."""

    progressed = Signal(int)  # per mille
    baked = Signal(object)  # BakeResult
    failed = Signal(object)  # StudioError
    stopped = Signal()  # cancelled

    def __init__(self, low: FaceMesh, path: Path, size: int, distance: float, bits: int,
                 tangent_frame: str, skin: np.ndarray | None = None,
                 tiles: UvTiles | None = None) -> None:
        super().__init__()
        self.low, self.path, self.size, self.distance, self.bits = low, path, size, distance, bits
        self.tangent_frame = tangent_frame  # the frame the viewport reads the map in
        self.skin = skin  # per triangle: the skin's own the texels eyes overlap in UV
        self.tiles = tiles  # the face's UDIM atlas: the sculpt's UVs are placed in it too
        self._cancel = threading.Event()

    def cancel(self) -> None:
        self._cancel.set()

    def run(self) -> None:
        try:
            high = sculpt_for(load_mesh(self.path), self.tiles)
            result = bake_normal_map(
                self.low, high, self.size, self.distance, bits=self.bits,
                progress=lambda done: self.progressed.emit(round(done * 1000)),
                cancelled=self._cancel.is_set, tangent_frame=self.tangent_frame,
                skin=self.skin)
        except BakeCancelled:
            self.stopped.emit()
        except StudioError as exc:
            self.failed.emit(exc)
        except MemoryError:
            self.failed.emit(StudioError(f"not enough memory to bake a {self.size} × "
                                         f"{self.size} map from this mesh; try a smaller one"))
        else:
            if self._cancel.is_set():
                self.stopped.emit()
            else:
                self.baked.emit(result)


class BakeTools(QObject):
    """The menu action's logic. A QObject living on the GUI thread, so the worker's signals
    reach its slots queued, on the GUI thread."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self.window = window
        self.worker: BakeWorker | None = None
        self.progress: QProgressDialog | None = None
        self._target: tuple[object, str, int] | None = None  # (project, map, size) baked for

    @property
    def doc(self) -> Document:
        return self.window.doc

    @property
    def busy(self) -> bool:
        return self.worker is not None

    def open_dialog(self) -> None:
        if self.busy:
            return
        project = self.doc.project
        dialog = BakeDialog(self.window, project.mesh, project.textures.wrinkle_maps)
        if dialog.exec() != QDialog.DialogCode.Accepted:
            return
        self.start(Path(dialog.mesh.path() or ""), dialog.map_size(), dialog.distance.value(),
                   dialog.map_key())

    def start(self, path: Path, size: int, distance: float, key: str | None = None) -> None:
        """Bake in the background; the map (``key`` as in map_tools, default the first wrinkled
        map) is replaced, as one undo step, when it is done. It keeps its bit depth."""
        project = self.doc.project
        key = key or WRINKLED + project.textures.wrinkle_map_names[0]
        bits = 16 if get_map(project.textures, key).dtype == np.uint16 else 8
        worker = BakeWorker(project.mesh, Path(path), size, distance, bits,
                            self.doc.view.tangent_frame, project.skin_triangles(),
                            project.uv_tiles)
        progress = QProgressDialog(f"Baking {Path(path).name} into a {size} × {size} wrinkled "
                                   "normal map…", "Cancel", 0, 1000, self.window)
        progress.setWindowTitle("Bake Wrinkled Normal Map")
        progress.setWindowModality(Qt.WindowModality.WindowModal)
        progress.setMinimumDuration(0)
        progress.setAutoClose(False)
        progress.setAutoReset(False)
        progress.canceled.connect(worker.cancel)
        worker.progressed.connect(progress.setValue)
        worker.baked.connect(self._apply)
        worker.failed.connect(self._failed)
        worker.stopped.connect(self._stopped)
        worker.finished.connect(self._done)
        self.worker, self.progress, self._target = worker, progress, (project, key, size)
        progress.show()
        worker.start()

    @Slot(object)
    def _apply(self, result: BakeResult) -> None:
        assert self._target is not None
        project, key, size = self._target
        self._close_progress()
        textures = self.doc.project.textures
        if self.doc.project is not project or key[len(WRINKLED):] not in textures.wrinkle_maps:
            return  # the project or the map went away meanwhile (the dialog is modal)
        label = map_label(key)
        self.doc.undo_stack.push(SetMapCommand(self.doc, key, result.image,
                                               f"Bake {label} from high-poly mesh"))
        share = result.hit_fraction
        self.window.statusBar().showMessage(
            f"Baked the {label} at {size} × {size}: {share:.0%} of the face's texels found the "
            "high-poly mesh", 8000)
        if share < LOW_HITS:
            QMessageBox.warning(
                self.window, "Bake Wrinkled Normal Map",
                f"Only {share:.0%} of the face's texels found the high-polygon mesh within the "
                "maximum ray distance; the rest took its normal at the same UV. If the mesh is "
                "not where the face is (another scale or position), fix it in your modelling "
                "tool; otherwise try a larger distance. Undo brings the old map back.")

    @Slot(object)
    def _failed(self, exc: StudioError) -> None:
        self._close_progress()
        self.window.show_error("Cannot bake", exc)

    @Slot()
    def _stopped(self) -> None:
        self.window.statusBar().showMessage("Bake cancelled; the map is unchanged", 5000)

    def _close_progress(self) -> None:
        progress, self.progress = self.progress, None
        if progress is not None:
            progress.canceled.disconnect()  # closing a progress dialog emits canceled
            progress.close()
            progress.deleteLater()

    @Slot()
    def _done(self) -> None:
        self._close_progress()
        if self.worker is not None:
            self.worker.deleteLater()
        self.worker = None


def install_bake_tools(window) -> BakeTools:
    """Add the bake at the end of the Maps menu, below the wrinkled maps."""
    tools = BakeTools(window)
    menu = window.menus["Maps"]
    action = QAction("Bake Wrinkled Normal Map from High-Poly Mesh…", window)
    action.triggered.connect(tools.open_dialog)
    menu.addAction(action)
    window.bake_tools = tools
    return tools
