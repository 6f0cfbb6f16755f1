"""What the studio window remembers and says, with no Qt in it: the recent files list, where
Save As starts, the title and the frame time.

Why apart from the window: these are rules a person notices (the file just opened comes first,
a file that failed to open leaves the list, Save As starts beside the character's own files);
here they are plain values, tested in milliseconds, and ``main_window.py`` only stores them in
the settings and shows them (napari's model and view).
"""

from __future__ import annotations

from pathlib import Path

MAX_RECENT = 10
FRAME_TEXT = "frame {:.1f} ms ({:.0f} FPS)"


def recent_list(value: object) -> list[str]:
    """The recent files as stored (QSettings gives one string for a list of one)."""
    if isinstance(value, str):
        return [value]
    return [str(v) for v in value or []]  # type: ignore[union-attr]


def with_recent(files: list[str], path: str) -> list[str]:
    """``path`` first, once, and at most ``MAX_RECENT`` files."""
    return [path, *(f for f in files if f != path)][:MAX_RECENT]


def without_recent(files: list[str], path: str) -> list[str]:
    return [f for f in files if f != path]


def save_folder(project_path: Path | None, mesh_source: str | None, installed: bool,
                last: str) -> str:
    """Where Save As starts: the project's own folder; for a project not saved yet, the folder
    its mesh was read from (where the user keeps this character's files) unless that is the
    studio's own (the bundled sample's); else the last folder used."""
    if project_path is not None:
        return str(Path(project_path).parent)
    if mesh_source and Path(mesh_source).parent.is_dir() and not installed:
        return str(Path(mesh_source).parent)
    return last


def window_title(name: str) -> str:
    """The title bar ([*] is where Qt marks unsaved changes)."""
    return f"{name}[*] — Wrinkle Studio"


def frame_text(ms: float) -> str:
    return FRAME_TEXT.format(ms, 1000.0 / max(ms, 1e-3))
