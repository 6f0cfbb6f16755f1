"""Dock tabs that show their whole title: scroll arrows rather than "P…", "Sha…", "Ar…".

Why: the right-hand column's tabs run down its edge; on a 720-pixel screen six titles do not fit
its height, and Qt's default elides every one of them to a letter or three, so a person cannot
tell the panels apart. As Blender's sidebar does, each tab keeps its words and the bar scrolls
when they outgrow it. Qt makes a dock area's tab bar when docks are first tabbed together (and
again when a person tabs them by hand), so each new bar is set up as it appears.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt, QTimer
from PySide6.QtWidgets import QMainWindow, QTabBar
from shiboken6 import isValid


def keep_words(bar: QTabBar) -> None:
    bar.setElideMode(Qt.TextElideMode.ElideNone)
    bar.setUsesScrollButtons(True)


class _TabWatcher(QObject):
    """Sets up the window's tab bars when its dock layout changes (Qt makes, reuses and
    re-parents them then, setting their eliding as it goes)."""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() in (QEvent.Type.ChildAdded, QEvent.Type.LayoutRequest):
            QTimer.singleShot(0, lambda: _all(watched))  # once Qt has finished with them
        return False


def _all(window: QObject) -> None:
    if isValid(window):
        for bar in window.findChildren(QTabBar):
            if bar.elideMode() != Qt.TextElideMode.ElideNone:
                keep_words(bar)


def keep_dock_tab_words(window: QMainWindow) -> None:
    """Every dock tab bar of ``window``, now and later, shows whole titles."""
    _all(window)
    watcher = _TabWatcher(window)
    window.installEventFilter(watcher)
