"""The timeline's place in the main window: the bottom dock and File ▸ Export Animation…."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence

from studio.widgets.hover_keys import install_hover_keys
from studio.widgets.timeline.panel import TimelinePanel


def add_timeline_menu_entries(window) -> None:
    """Export Animation… above Quit in the File menu, and the dock's toggle in View (called by
    the main window once its menus exist)."""
    action = QAction("Export &Animation…", window)
    action.setShortcut(QKeySequence("Ctrl+E"))
    action.setStatusTip("Render the timeline to PNG frames, an animated GIF or a video")
    action.triggered.connect(lambda: _export(window))
    file = window.menus["File"]
    actions = file.actions()
    index = actions.index(window.quit_action)
    before = actions[index - 1] if index > 0 and actions[index - 1].isSeparator() else None
    file.insertAction(before or window.quit_action, action)
    window.export_animation_action = action
    view = window.menus["View"]
    toggle = window.docks["Timeline"].toggleViewAction()
    toggle.setShortcut(QKeySequence("Ctrl+T"))
    view.insertAction(next((a for a in view.actions() if a.isSeparator()), None), toggle)


def _export(window) -> None:
    from studio.widgets.export_dialog import open_export_dialog

    open_export_dialog(window)


def install_timeline_tools(window) -> TimelinePanel:
    """Add the timeline to a main window (called once from its constructor)."""
    panel = TimelinePanel(window.doc)
    window.timeline_panel = panel
    window._add_dock("Timeline", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    panel.setMinimumHeight(150)
    window.pose_panel.poseEdited.connect(panel.set_current_pose)  # K keys the slider just moved
    # Blender's hover keys: the timeline's own keys while the mouse is over it, F and Space
    # over the viewport, with no click first
    hover = install_hover_keys(window)
    hover.add(panel, panel.hover_keys())
    hover.add(window.viewport, {Qt.Key.Key_F: lambda: window.frame_face_front(),
                                Qt.Key.Key_Space: panel.player.toggle})  # Blender plays there too
    return panel
