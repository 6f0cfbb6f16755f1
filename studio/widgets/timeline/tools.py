"""The timeline's place in the main window: the bottom dock and File ▸ Export Animation…."""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction, QKeySequence

from studio.widgets.timeline.panel import TimelinePanel


def _menu(window, title: str):
    for action in window.menuBar().actions():
        if action.menu() is not None and action.text().replace("&", "") == title:
            return action.menu()
    return None


def _add_menu_entries(window) -> bool:
    """Export Animation… above Quit in the File menu, and the dock's toggle in View."""
    file = _menu(window, "File")
    if file is None:
        return False
    action = QAction("Export &Animation…", window)
    action.setShortcut(QKeySequence("Ctrl+E"))
    action.setStatusTip("Render the timeline to PNG frames, an animated GIF or a video")
    action.triggered.connect(lambda: _export(window))
    quit_action = next((a for a in file.actions() if a.text().replace("&", "") == "Quit"), None)
    if quit_action is None:
        file.addSeparator()
        file.addAction(action)
    else:
        actions = file.actions()
        index = actions.index(quit_action)
        before = actions[index - 1] if index > 0 and actions[index - 1].isSeparator() else None
        file.insertAction(before or quit_action, action)
    window.export_animation_action = action
    view = _menu(window, "View")
    if view is not None:
        toggle = window.docks["Timeline"].toggleViewAction()
        toggle.setShortcut(QKeySequence("Ctrl+T"))
        view.insertAction(next((a for a in view.actions() if a.isSeparator()), None), toggle)
    return True


def _export(window) -> None:
    from studio.widgets.export_dialog import open_export_dialog

    open_export_dialog(window)


def install_timeline_tools(window) -> TimelinePanel:
    """Add the timeline to a main window (called once from its constructor)."""
    panel = TimelinePanel(window.doc)
    window.timeline_panel = panel
    window._add_dock("Timeline", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    panel.setMinimumHeight(265)
    if not _add_menu_entries(window):  # the menus are built after the panels
        QTimer.singleShot(0, window, lambda: _add_menu_entries(window))
    return panel
