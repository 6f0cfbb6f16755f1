"""The studio's remembered settings (window layout, recent files, brush, autosave, …): one
QSettings store, named here so every widget module reads the same one without importing the
main window."""

from __future__ import annotations

from PySide6.QtCore import QSettings


def settings() -> QSettings:
    return QSettings("WrinkleStudio", "Wrinkle Studio")
