"""The studio window: viewport in the middle, dockable panels, menus, and file handling."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSize, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QActionGroup, QCloseEvent, QKeySequence, QShowEvent
from PySide6.QtWidgets import (
    QDockWidget,
    QFileDialog,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QScrollArea,
    QTabWidget,
    QUndoView,
    QWidget,
)

from studio.core.files.errors import Cancelled, StudioError
from studio.core.project.model import Project
from studio.widgets.about import show_about
from studio.widgets.app_settings import last_folder, settings
from studio.widgets.autosave import install_autosave
from studio.widgets.background import run_with_progress
from studio.widgets.dock_tabs import keep_dock_tab_words
from studio.widgets.document import Document
from studio.widgets.getting_started import install_getting_started
from studio.widgets.maps.auto_tools import install_auto_tools
from studio.widgets.maps.bake_tools import install_bake_tools
from studio.widgets.maps.furrow_controls import install_furrow_controls
from studio.widgets.maps.map_tools import install_map_tools
from studio.widgets.paint.tools import install_mask_tools
from studio.widgets.timeline.capture_tools import install_capture_tools
from studio.widgets.timeline.pose_panel import PosePanel
from studio.widgets.timeline.tools import add_timeline_menu_entries, install_timeline_tools
from studio.widgets.viewport.look_menu import LookMenu
from studio.widgets.viewport.shading_panel import ShadingPanel
from studio.widgets.viewport.viewport import ANTI_ALIASING, DEFAULT_SAMPLES, Viewport
from studio.widgets.wdv.panel import install_wdv_tools
from studio.widgets.wheel_guard import install_wheel_guard

PROJECT_FILTER = "Wrinkle Studio projects (*.wrinkle)"
MAX_RECENT = 10
# The default layout: these panels as tabs in one right-hand column, in this order.
RIGHT_TABS = ("Poses", "Shading", "Areas", "Wrinkle vectors", "Furrows", "UV Paint")
FRAME_TEXT = "frame {:.1f} ms ({:.0f} FPS)"
SIDE_WIDTH = 360  # pixels: the right-hand column (a pose slider gets 100 of them)
TIMELINE_HEIGHT = 200  # pixels: the timeline strip under the viewport


def sample_project() -> Project:
    """The bundled sample: the ICT-FaceKit head, set up (kept set up in the user's cache)."""
    from studio.widgets.sample_cache import cached_sample

    return cached_sample()


def _installed(path: Path) -> bool:
    """Whether ``path`` is one of the studio's own files (the sample head's resource)."""
    from studio.paths import resource_dir

    return path.resolve().is_relative_to(resource_dir().resolve())


class _ColumnPanel(QScrollArea):
    """A panel of the right-hand column: asks for the column's width (so the window lays out
    that way from its first frame) and scrolls what does not fit."""

    def sizeHint(self) -> QSize:
        return QSize(SIDE_WIDTH, super().sizeHint().height())


class MainWindow(QMainWindow):
    firstFrame = Signal()

    def __init__(self, project: Project | None = None, path: Path | None = None) -> None:
        super().__init__()
        self.doc = Document(project or sample_project(), path, self)
        self.viewport = Viewport(self.doc)
        self.setCentralWidget(self.viewport)
        self.setDockNestingEnabled(True)
        self.pose_panel = PosePanel(self.doc)
        self.shading_panel = ShadingPanel(self.doc)
        self.undo_view = QUndoView(self.doc.undo_stack)
        self.undo_view.setEmptyLabel("<opened>")
        self.docks: dict[str, QDockWidget] = {}
        self._add_dock("Poses", self.pose_panel, Qt.DockWidgetArea.RightDockWidgetArea)
        self._add_dock("Shading", self.shading_panel, Qt.DockWidgetArea.RightDockWidgetArea)
        self._add_dock("History", self.undo_view, Qt.DockWidgetArea.LeftDockWidgetArea)
        self.docks["History"].hide()
        self.tools = self.addToolBar("Tools")
        self.tools.setObjectName("toolbar:tools")
        # panel toggles apart from the tools, under their own word: they open panels, they are
        # not modes of the viewport
        self.panels_bar = self.addToolBar("Panels")
        self.panels_bar.setObjectName("toolbar:panels")
        self.panels_bar.addWidget(QLabel(" Panels: "))
        # --- authoring panels and tools: one install call each (technique 2, technique 1,
        # timeline), kept in their own modules ---
        install_mask_tools(self)  # technique 1: influence areas, UV paint, face paint
        install_timeline_tools(self)  # timeline, playback, animation export
        self.timeline_panel.player.playingChanged.connect(self.viewport.set_playing)
        install_wdv_tools(self)  # technique 2: wrinkle direction vectors
        install_autosave(self)  # autosave, crash recovery, undo memory budget
        install_wheel_guard()  # the wheel scrolls panels; it edits a field only once focused
        self._frame_label = QLabel("")
        # room for the longest reading, so a slow frame's time is not cut at the edge
        self._frame_label.setMinimumWidth(
            self._frame_label.fontMetrics().horizontalAdvance(FRAME_TEXT.format(9999.9, 999)))
        self.statusBar().addPermanentWidget(self._frame_label)
        self._build_menus()
        install_map_tools(self)  # Maps menu and File ▸ Export, needs the menus
        add_timeline_menu_entries(self)  # File ▸ Export Animation… (after Export), View
        install_bake_tools(self)  # Maps ▸ Bake from a high-poly mesh, needs Maps
        install_auto_tools(self)  # Tools menu: auto setup, strain → areas, wrinkle synthesis
        install_furrow_controls(self)  # the Furrows dock and Maps ▸ Furrow Controls
        install_capture_tools(self)  # File ▸ Import Capture…, needs the menus and timeline
        keep_dock_tab_words(self)  # (before the docks are tabbed: their bars are made then)
        self._arrange_docks()
        install_getting_started(self)  # Help ▸ Getting Started; shown at the first start
        self.doc.modifiedChanged.connect(self.setWindowModified)
        self.doc.pathChanged.connect(self._update_title)
        self.doc.projectReplaced.connect(self._update_title)
        self.viewport.frameRendered.connect(self._show_frame_time)
        self.viewport.glFailed.connect(self._gl_failed)
        self._update_title()
        self._initial_size()
        self._restore_layout()

    def _initial_size(self) -> None:
        """Most of the screen, as 3D tools open; 1440×900 where the screen is unknown."""
        screen = self.screen()
        if screen is None:
            self.resize(1440, 900)
            return
        area = screen.availableGeometry()
        self.resize(round(area.width() * 0.9), round(area.height() * 0.9))

    def _arrange_docks(self) -> None:
        """The default layout, as Blender and Substance Painter lay out theirs: every panel a
        tab in one narrow column on the right and the timeline a short strip below the
        viewport, so the face gets most of the window (History stays hidden on the left)."""
        right = [self.docks[t] for t in RIGHT_TABS if t in self.docks]
        # the tabs down the column's edge, as Blender's sidebar: every title reads in full
        self.setTabPosition(Qt.DockWidgetArea.RightDockWidgetArea, QTabWidget.TabPosition.East)
        for dock in right:
            self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
            dock.setMinimumWidth(0)  # a panel may ask for room; the column's width is ours
        for dock in right[1:]:
            self.tabifyDockWidget(right[0], dock)
        for dock in right:
            self._raise_on_toggle(dock)
        if right:
            right[0].raise_()
        self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, self.docks["History"])
        if "Timeline" in self.docks:
            self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, self.docks["Timeline"])

    def _raise_on_toggle(self, dock: QDockWidget) -> None:
        """A panel's toggle (View menu, toolbar) brings a panel that sits behind another tab
        to the front instead of closing it, and raises a panel it opens."""
        on_screen = {"now": False}  # in front of its tab group (a closed one keeps its last)
        dock.visibilityChanged.connect(
            lambda visible: None if dock.isHidden() else on_screen.update(now=visible))

        def toggled(checked: bool) -> None:
            if not checked and not on_screen["now"] and not dock.isFloating():
                dock.show()  # it was open, behind another tab: the user asked to see it
            if dock.isVisible():
                dock.raise_()

        dock.toggleViewAction().triggered.connect(toggled)

    def _default_dock_sizes(self) -> None:
        """The side column narrow and the timeline short (sizes apply only to a shown window)."""
        shown = [d for t, d in self.docks.items() if t in RIGHT_TABS and not d.isHidden()]
        if shown:
            self.resizeDocks(shown[:1], [SIDE_WIDTH], Qt.Orientation.Horizontal)
        if "Timeline" in self.docks:
            self.resizeDocks([self.docks["Timeline"]], [TIMELINE_HEIGHT], Qt.Orientation.Vertical)

    def _add_dock(self, title: str, widget: QWidget, area: Qt.DockWidgetArea) -> None:
        dock = QDockWidget(title, self)
        dock.setObjectName(f"dock:{title}")
        if title in RIGHT_TABS and title != "UV Paint":  # (the canvas pans and zooms itself)
            # narrower than it asks, a panel scrolls: the column stays put
            scroll = _ColumnPanel()
            scroll.setWidget(widget)
            scroll.setWidgetResizable(True)
            scroll.setFrameShape(QScrollArea.Shape.NoFrame)
            dock.setWidget(scroll)
        else:
            dock.setWidget(widget)
        self.addDockWidget(area, dock)
        self.docks[title] = dock

    # --- menus ---------------------------------------------------------------------------------
    def _action(self, menu, text: str, slot, shortcut=None, tip: str = "") -> QAction:
        action = QAction(text, self)
        if shortcut is not None:
            keys = shortcut if isinstance(shortcut, list) else [shortcut]
            action.setShortcuts([QKeySequence(k) for k in keys])
        action.setStatusTip(tip)
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_menus(self) -> None:
        """The menu bar, every top-level menu created here in its order and kept in
        ``self.menus`` by its plain title, so the feature modules that add entries find them
        without searching the bar; ``self.quit_action`` is where File's additions go above."""
        bar = self.menuBar()
        self.menus: dict[str, QMenu] = {
            title.replace("&", ""): bar.addMenu(title)
            for title in ("&File", "&Edit", "&View", "&Maps", "&Tools", "&Help")}
        file = self.menus["File"]
        self._action(file, "&New from Files…", self.new_from_files, QKeySequence.StandardKey.New,
                     "Start a project from a neutral mesh, key-pose meshes and texture maps")
        self._action(file, "&Open…", self.open_dialog, QKeySequence.StandardKey.Open)
        self.recent_menu = file.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        self._action(file, "Open &Sample Face", self.open_sample)
        file.addSeparator()
        self._action(file, "&Save", self.save, QKeySequence.StandardKey.Save)
        self._action(file, "Save &As…", self.save_as, "Ctrl+Shift+S")
        file.addSeparator()
        self.quit_action = self._action(file, "&Quit", self.close, QKeySequence.StandardKey.Quit)

        edit = self.menus["Edit"]
        undo = self.doc.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        redo = self.doc.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        edit.addAction(undo)
        edit.addAction(redo)
        edit.addSeparator()
        edit.addAction(self.docks["History"].toggleViewAction())
        self.docks["History"].toggleViewAction().setText("Undo &History")

        view = self.menus["View"]
        numpad_period = QKeySequence(Qt.Key.Key_Period | Qt.KeyboardModifier.KeypadModifier)
        frame = self._action(view, "&Frame Face", self.frame_face_front,
                             ["Home", numpad_period, "F"],
                             "The face from its front, filling the view (Home, numpad ., F)")
        everything = self._action(view, "Frame &All", self.doc.frame_all, "Shift+Home",
                                  "The whole mesh: neck, shoulders, eyes and teeth too")
        for action in (frame, everything):
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            self.viewport.addAction(action)
        view.addSeparator()
        for title, dock in self.docks.items():
            if title != "History":
                view.addAction(dock.toggleViewAction())
        view.addSeparator()
        self.look_menu = LookMenu(view.addMenu("L&ook"), self.doc)
        self._anti_aliasing_menu(view.addMenu("&Anti-Aliasing"))
        view.addAction(self.viewport.reduce_action(self))
        view.addSeparator()
        self._action(view, "Reset &Layout", self.reset_layout)
        self._action(view, "&Paint Layout", self.paint_layout, None,
                     "The UV canvas and the face side by side; the Areas panel in front")

        help_menu = self.menus["Help"]
        self._action(help_menu, "&Navigation…", self.show_navigation_help, "F1")
        self._action(help_menu, "&About Wrinkle Studio", self.show_about)

    def frame_face_front(self) -> None:
        """View ▸ Frame Face (F, Home): the face straight from its front, filling the view,
        whatever way the camera was turned; the document's own framing (on opening a
        project) keeps its three-quarter view."""
        camera = self.doc.camera
        camera.yaw, camera.pitch = 0.0, 0.0
        self.doc.frame_face()

    def _anti_aliasing_menu(self, menu: QMenu) -> None:
        """Samples per pixel in the viewport, remembered; choices this driver cannot draw are
        greyed once OpenGL is up. Off is much faster on a software renderer."""
        group = QActionGroup(self)
        chosen = int(settings().value("viewport/samples", DEFAULT_SAMPLES))
        self.anti_aliasing: dict[int, QAction] = {}
        for samples in ANTI_ALIASING:
            action = menu.addAction("Off" if samples == 0 else f"{samples}× Multisampling")
            action.setCheckable(True)
            action.setChecked(samples == chosen)
            action.triggered.connect(lambda _=False, n=samples: self.set_anti_aliasing(n))
            group.addAction(action)
            self.anti_aliasing[samples] = action
        self.viewport.set_samples(chosen)

        def grey_unsupported() -> None:
            most = self.viewport.max_samples
            for samples, action in self.anti_aliasing.items():
                action.setEnabled(samples <= most)
                action.setToolTip("" if samples <= most else f"this driver draws at most {most}")

        self.firstFrame.connect(grey_unsupported)

    def set_anti_aliasing(self, samples: int) -> None:
        self.viewport.set_samples(samples)
        self.anti_aliasing[samples].setChecked(True)
        settings().setValue("viewport/samples", samples)

    # --- status --------------------------------------------------------------------------------
    def _update_title(self) -> None:
        self.setWindowTitle(f"{self.doc.display_name}[*] — Wrinkle Studio")
        self.setWindowModified(self.doc.modified)

    def _show_frame_time(self, ms: float) -> None:
        self._frame_label.setText(FRAME_TEXT.format(ms, 1000.0 / max(ms, 1e-3)))
        if self.viewport.frames_rendered == 1:
            self.firstFrame.emit()

    def _gl_failed(self, message: str) -> None:
        self.statusBar().showMessage(message)
        QTimer.singleShot(0, lambda: QMessageBox.critical(self, "Wrinkle Studio", message))

    def show_error(self, title: str, error: Exception) -> None:
        QMessageBox.critical(self, title, str(error))

    def show_about(self) -> None:
        show_about(self, self.viewport.gl_description)

    def show_navigation_help(self) -> None:
        QMessageBox.information(
            self, "Viewport navigation",
            "Orbit: middle-drag, or Alt+left-drag\nPan: Shift+middle-drag, or Alt+Shift+left-drag"
            "\nZoom: wheel, or Ctrl+middle-drag\nFrame the face: F\n"
            "Front / side / top: numpad 1 / 3 / 7 (Ctrl+3: other side)")

    # --- files ---------------------------------------------------------------------------------
    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False means the user cancelled."""
        if not self.doc.modified:
            return True
        answer = QMessageBox.warning(
            self, "Unsaved changes",
            f"Save the changes to “{self.doc.display_name}” before closing it?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
            | QMessageBox.StandardButton.Cancel)
        if answer == QMessageBox.StandardButton.Save:
            return self.save()
        return answer == QMessageBox.StandardButton.Discard

    def open_path(self, path: Path) -> bool:
        """Open a project, read on a worker thread behind a progress dialog with Cancel (a large
        project takes seconds); on failure say why, on cancel say so, and in both cases keep
        the open project untouched."""
        from studio.core.project.reader import load_project

        try:
            project = run_with_progress(self, "Opening project", f"Opening {path.name}…",
                                        lambda progress: load_project(path, progress))
        except Cancelled:
            self.statusBar().showMessage(f"Opening {path.name} cancelled", 5000)
            return False
        except StudioError as exc:
            self.show_error("Cannot open project", exc)
            self._forget_recent(path)
            return False
        self.doc.replace_project(project, path)
        self._remember_recent(path)
        self.statusBar().showMessage(f"Opened {path} · face: {self.doc.face_frame().how}", 8000)
        return True

    def open_dialog(self) -> None:
        if not self.maybe_save():
            return
        name, _ = QFileDialog.getOpenFileName(self, "Open project", self._last_folder(),
                                              PROJECT_FILTER)
        if name:
            self.open_path(Path(name))

    def open_sample(self) -> None:
        if self.maybe_save():
            self.doc.replace_project(sample_project(), None)

    def new_from_files(self) -> None:
        from studio.widgets.new_project_dialog import NewProjectDialog

        if not self.maybe_save():
            return
        dialog = NewProjectDialog(self)
        if dialog.exec() and dialog.project is not None:
            self.doc.replace_project(dialog.project, None)
            if dialog.report:
                QMessageBox.information(self, "New project: what was found and set up",
                                        "\n".join(dialog.report))

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def save_as(self) -> bool:
        start = str(Path(self._save_folder()) / f"{self.doc.display_name}.wrinkle")
        name, _ = QFileDialog.getSaveFileName(self, "Save project as", start, PROJECT_FILTER)
        if not name:
            return False
        path = Path(name)
        if path.suffix != ".wrinkle":
            path = path.with_name(path.name + ".wrinkle")
        return self.save_to(path)

    def save_to(self, path: Path) -> bool:
        from studio.core.project.writer import save_project

        self.doc.store_view_state()
        try:
            save_project(self.doc.project, path)
        except StudioError as exc:
            self.show_error("Cannot save project", exc)
            return False
        self.doc.mark_saved(path)
        self._remember_recent(path)
        self.statusBar().showMessage(f"Saved {path}", 5000)
        return True

    # --- remembered settings -------------------------------------------------------------------
    def _last_folder(self) -> str:
        return last_folder()

    def _save_folder(self) -> str:
        """Where Save As starts: the project's own folder; for a project not saved yet, the
        folder its mesh was read from (where the user keeps this character's files); else
        the last folder used."""
        if self.doc.path is not None:
            return str(Path(self.doc.path).parent)
        source = self.doc.project.mesh.source
        if source and Path(source).parent.is_dir() and not _installed(Path(source)):
            return str(Path(source).parent)
        return self._last_folder()  # (the bundled sample's is the studio's own folder)

    def recent_files(self) -> list[str]:
        value = settings().value("recent_files", [])
        return [value] if isinstance(value, str) else list(value or [])

    def _remember_recent(self, path: Path) -> None:
        path = path.resolve()
        files = [str(path), *(f for f in self.recent_files() if f != str(path))][:MAX_RECENT]
        s = settings()
        s.setValue("recent_files", files)
        s.setValue("last_folder", str(path.parent))

    def _forget_recent(self, path: Path) -> None:
        settings().setValue("recent_files",
                            [f for f in self.recent_files() if f != str(path.resolve())])

    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        files = self.recent_files()
        for name in files:
            action = self.recent_menu.addAction(Path(name).name)
            action.setStatusTip(name)
            action.triggered.connect(lambda _=False, n=name: self.maybe_save()
                                     and self.open_path(Path(n)))
        if not files:
            self.recent_menu.addAction("(none)").setEnabled(False)

    def _restore_layout(self) -> None:
        s = settings()
        self._default_state = self.saveState()
        geometry, state = s.value("window/geometry"), s.value("window/state")
        if geometry is not None:
            self.restoreGeometry(geometry)
        if state is not None:
            self.restoreState(state)
        self._sized = state is not None  # the default sizes wait for the first show

    def showEvent(self, event: QShowEvent) -> None:
        """The default dock sizes, once, when the window first shows: a dock takes a size only
        once the window has laid it out."""
        super().showEvent(event)
        if not self._sized:
            self._sized = True
            self.layout().activate()
            self._default_dock_sizes()

    def reset_layout(self) -> None:
        self.restoreState(self._default_state)
        self._default_dock_sizes()

    def paint_layout(self) -> None:
        """Substance Painter's 2D/3D split: the UV canvas on the left and the face beside it,
        sharing the room left of the panels equally (the face shows the painted area live while
        a stroke lasts), and the Areas panel, with the brush and the area's links, in front on
        the right."""
        self.reset_layout()
        canvas = self.docks["UV Paint"]
        self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, canvas)  # out of the tabs
        canvas.show()
        self.docks["Areas"].show()
        self.docks["Areas"].raise_()
        self.layout().activate()
        side = self.docks["Areas"].width()
        self.resizeDocks([canvas], [(self.width() - side) // 2], Qt.Orientation.Horizontal)

    def closeEvent(self, event: QCloseEvent) -> None:
        if not self.maybe_save():
            event.ignore()
            return
        s = settings()
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        event.accept()

    def grab_when_rendered(self, out: Path, on_done) -> None:
        """Save a screenshot of the whole window once the viewport has drawn (docs, CI)."""
        def grab() -> None:
            from studio.core.files.atomic_write import atomic_output
            from studio.core.files.errors import StudioError

            image = self.grab()
            try:  # a temporary file renamed into place: never a half-written screenshot
                with atomic_output(out, what="screenshot") as handle:
                    if not image.save(handle.name, "PNG"):
                        raise OSError("the image could not be encoded")
                ok = True
            except (StudioError, OSError):
                ok = False
            on_done(ok)

        def later() -> None:
            QTimer.singleShot(300, grab)

        if self.viewport.frames_rendered:
            later()
        else:
            self.firstFrame.connect(later)
