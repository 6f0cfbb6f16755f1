"""The studio's remembered settings (window layout, recent files, brush, autosave, …): one
QSettings store, named here so every widget module reads the same one without importing the
main window."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSettings, QStandardPaths


def settings() -> QSettings:
    return QSettings("WrinkleStudio", "Wrinkle Studio")


def data_folder() -> Path:
    """The user's data folder for the studio (recovery files, crash logs): not created here."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base) if base else Path.home() / ".local" / "share" / "WrinkleStudio"


def last_folder() -> str:
    """The folder the user last chose a file in (their home folder at first)."""
    return str(settings().value("last_folder", str(Path.home())))


def remember_folder(chosen: str | Path) -> None:
    """Remember the folder of a file the user chose, for the next file dialog."""
    settings().setValue("last_folder", str(Path(chosen).parent))


def start_folder(*near: str | Path | None) -> str:
    """Where a file dialog opens: beside the first of ``near`` (files the user already chose
    for this: a map beside its mesh, a pose beside the neutral) whose folder exists, else the
    last folder the user chose a file in."""
    for path in near:
        if path:
            folder = Path(path).expanduser()
            folder = folder if folder.is_dir() else folder.parent
            if folder.is_dir():
                return str(folder)
    return last_folder()
