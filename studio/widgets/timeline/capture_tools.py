"""File ▸ Import Capture…: a facial capture take (studio/core/formats/capture.py) keyed onto the
timeline as one undo step, with a report of what matched and what did not.

Why a report every time: a take names its shapes in ARKit's spelling and a rig in its own, so
which columns found a pose is the first thing a user checks; a column left out silently would
look like a dead expression on playback.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QFileDialog, QMessageBox

from studio.core.files.errors import Cancelled, StudioError
from studio.core.formats.capture import import_capture
from studio.widgets.app_settings import settings
from studio.widgets.background import run_with_progress
from studio.widgets.timeline.edits import TimelineState

CAPTURE_FILTER = ("Capture takes (*.csv *.glb *.gltf);;Live Link Face takes (*.csv);;"
                  "glTF morph-weight animations (*.glb *.gltf);;All files (*)")
FOLDER_KEY = "capture/last_folder"


def capture_folder() -> str:
    """Where the last take came from (else the last project's folder, else home)."""
    s = settings()
    return str(s.value(FOLDER_KEY, s.value("last_folder", str(Path.home()))))


def import_capture_dialog(window) -> bool:
    """Ask for a take and key it onto the timeline; False when cancelled or refused."""
    name, _ = QFileDialog.getOpenFileName(window, "Import capture", capture_folder(),
                                          CAPTURE_FILTER)
    if not name:
        return False
    path = Path(name)
    settings().setValue(FOLDER_KEY, str(path.parent))
    doc = window.doc
    poses = [p.name for p in doc.project.poses]
    try:  # read on a worker thread: a long take keeps the window drawing, with Cancel
        timeline, report = run_with_progress(
            window, "Importing capture", f"Reading {path.name}…",
            lambda progress: import_capture(path, doc.project.timeline, poses))
    except Cancelled:
        return False
    except StudioError as exc:
        window.show_error("Cannot import the capture", exc)
        return False
    window.timeline_panel.edits.push(f"Import capture {path.name}", TimelineState.of(timeline))
    QMessageBox.information(window, "Capture imported", "\n\n".join(report.lines()))
    return True


def install_capture_tools(window) -> QAction:
    """File ▸ Import Capture… (Ctrl+I) after the ways to open a project; called once the menus
    and the timeline exist."""
    file_menu = window.menus["File"]
    action = QAction("Import &Capture…", window)
    action.setShortcut(QKeySequence("Ctrl+I"))
    action.setStatusTip("Key a facial capture take (Live Link Face CSV, ARKit blend shapes) "
                        "onto the timeline")
    action.triggered.connect(lambda: import_capture_dialog(window))
    first_separator = next((a for a in file_menu.actions() if a.isSeparator()), None)
    file_menu.insertAction(first_separator, action)
    window.import_capture_action = action
    return action
