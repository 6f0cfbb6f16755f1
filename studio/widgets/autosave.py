"""Autosave and crash recovery: hours of painting survive a crash, a kill or a power cut.

Every few minutes (QSettings ``autosave/interval_minutes``, default 3; 0 turns it off) a window
whose document has unsaved changes writes it with :func:`save_project` (atomic) to a recovery file
in the user's data folder (``QStandardPaths.AppDataLocation/recovery``)::

    <session>.wrinkle   the document as it was at the last autosave
    <session>.json      what it is: project name, original path, time (shown in the offer)
    <session>.lock      locked (flock) for as long as the window lives

Why the lock: a recovery file whose lock nobody holds was left by a window that did not close
normally (the kernel drops a dead process's locks), so it is offered at the next start; a file
still locked belongs to a running window (this process or another) and is left alone. Where
there are no advisory locks (Windows) the pid in the ``.json`` decides instead.

A clean close of the window, or saving the document, deletes the recovery file. At start-up the
window offers each orphaned one (a question box naming project, original path and time): Yes
opens it as an unsaved document (so the user chooses where to save it) and deletes the
recovery file; Discard deletes it; Ignore keeps it for the next start.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, QStandardPaths, QTimer
from PySide6.QtWidgets import QMessageBox

from studio.core.errors import StudioError

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

if TYPE_CHECKING:
    from studio.widgets.main_window import MainWindow


INTERVAL_KEY = "autosave/interval_minutes"
DEFAULT_MINUTES = 3.0
_sessions = itertools.count(1)
_offering = False  # one offer at a time (a recovered second window must not ask again)


def recovery_dir() -> Path:
    """The folder for recovery files (created on demand)."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    if not base:
        base = str(Path.home() / ".local" / "share" / "WrinkleStudio")
    return Path(base) / "recovery"


@dataclass
class Recovery:
    """One recovery file left by a window that did not close normally."""

    project_file: Path
    name: str
    original: str | None
    saved_at: float

    def describe(self) -> str:
        when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.saved_at))
        origin = self.original or "never saved"
        return f"“{self.name}”\nOriginal file: {origin}\nAutosaved: {when}"

    def remove(self) -> None:
        for suffix in (".wrinkle", ".json", ".lock"):
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(suffix).unlink()


def _owner_alive(lock: Path, meta: dict[str, Any]) -> bool:
    """Whether a running window still owns this recovery file."""
    if fcntl is not None:
        try:
            fd = os.open(lock, os.O_RDWR)
        except FileNotFoundError:
            return False
        except OSError:
            return True  # cannot tell: leave it alone
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return True
        finally:
            os.close(fd)  # closing drops the probe's own lock
        return False
    pid = meta.get("pid")
    if not isinstance(pid, int) or pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    return True


def find_recoveries(folder: Path | None = None) -> list[Recovery]:
    """Orphaned recovery files, newest first; stray lock files of dead windows are removed."""
    folder = folder or recovery_dir()
    if not folder.is_dir():
        return []
    found: list[Recovery] = []
    for project_file in folder.glob("*.wrinkle"):
        meta_file = project_file.with_suffix(".json")
        try:
            meta = json.loads(meta_file.read_text(encoding="utf-8"))
            if not isinstance(meta, dict):
                meta = {}
        except (OSError, ValueError):
            meta = {}
        if _owner_alive(project_file.with_suffix(".lock"), meta):
            continue
        try:
            mtime = project_file.stat().st_mtime
        except OSError:
            continue
        name = meta.get("name") if isinstance(meta.get("name"), str) else project_file.stem
        original = meta.get("original") if isinstance(meta.get("original"), str) else None
        saved_at = meta.get("saved_at")
        saved_at = float(saved_at) if isinstance(saved_at, int | float) else mtime
        found.append(Recovery(project_file, name, original, saved_at))
    for lock in folder.glob("*.lock"):  # a window that died before its first autosave
        if not lock.with_suffix(".wrinkle").exists() and not _owner_alive(lock, {}):
            with contextlib.suppress(OSError):
                lock.unlink()
    found.sort(key=lambda r: r.saved_at, reverse=True)
    return found


class Autosaver(QObject):
    """Autosaves one window's document and offers recovery when the window starts."""

    def __init__(self, window: MainWindow) -> None:
        super().__init__(window)
        self.window = window
        self.session = f"{os.getpid()}-{int(time.time())}-{next(_sessions)}"
        self.folder = recovery_dir()
        self._lock_fd: int | None = None
        self._saved_index: int | None = None  # undo index at the last autosave
        self.autosaves = 0
        self._closing = False
        self.timer = QTimer(self)
        self.timer.timeout.connect(self.autosave)
        self.set_interval(_interval_minutes())
        window.installEventFilter(self)
        window.doc.modifiedChanged.connect(self._modified_changed)

    @property
    def project_file(self) -> Path:
        return self.folder / f"{self.session}.wrinkle"

    def set_interval(self, minutes: float) -> None:
        """Autosave every ``minutes`` (0 or less: never)."""
        self.timer.stop()
        if minutes > 0:
            self.timer.start(max(1, round(minutes * 60_000)))

    # --- autosaving ----------------------------------------------------------------------------
    def autosave(self) -> bool:
        """Write the document to the recovery file if it changed since the last autosave."""
        from studio.core.project_file import save_project

        doc = self.window.doc
        if not doc.modified or self._saved_index == doc.undo_stack.index():
            return False
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._take_lock()
            doc.store_view_state()
            save_project(doc.project, self.project_file, backup=False)
            meta = {"name": doc.display_name, "original": str(doc.path) if doc.path else None,
                    "saved_at": time.time(), "pid": os.getpid()}
            _write_json(self.project_file.with_suffix(".json"), meta)
        except (StudioError, OSError) as exc:  # never interrupt the user: say it and go on
            self.window.statusBar().showMessage(f"Autosave failed: {exc}", 10_000)
            return False
        self._saved_index = doc.undo_stack.index()
        self.autosaves += 1
        self.window.statusBar().showMessage("Autosaved", 2000)
        return True

    def _take_lock(self) -> None:
        if self._lock_fd is not None:
            return
        fd = os.open(self.project_file.with_suffix(".lock"), os.O_RDWR | os.O_CREAT, 0o600)
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        self._lock_fd = fd

    def discard(self) -> None:
        """Delete this window's recovery file (the document is saved, or closed on purpose)."""
        for suffix in (".wrinkle", ".json"):
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(suffix).unlink()
        self._saved_index = None

    def shut_down(self) -> None:
        """A clean exit: stop, delete the recovery file and the lock."""
        self.timer.stop()
        self.discard()
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(".lock").unlink()
            os.close(self._lock_fd)
            self._lock_fd = None

    def abandon(self) -> None:
        """What a crash does (for tests): stop and let go of the files without deleting them."""
        self.timer.stop()
        self.window.removeEventFilter(self)
        with contextlib.suppress(RuntimeError, TypeError):
            self.window.doc.modifiedChanged.disconnect(self._modified_changed)
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def _modified_changed(self, modified: bool) -> None:
        if not modified:  # saved (or undone back to the saved state): nothing to recover
            self.discard()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """A clean exit is a Close the window accepted, which Qt follows at once with a Hide.

        Why not act on Close itself: the window's closeEvent runs after this filter and may
        still refuse (the user cancelled "save changes?").
        """
        if watched is self.window:
            if event.type() == QEvent.Type.Close:
                self._closing = True
                QTimer.singleShot(0, self._close_refused)
            elif event.type() == QEvent.Type.Hide and self._closing:
                self._closing = False
                self.shut_down()
        return False

    def _close_refused(self) -> None:
        self._closing = False

    # --- recovery ------------------------------------------------------------------------------
    def offer_recovery(self) -> int:
        """Ask about each orphaned recovery file; returns how many documents were recovered."""
        global _offering
        if _offering:
            return 0
        _offering = True
        try:
            return self._offer()
        finally:
            _offering = False

    def _offer(self) -> int:
        from studio.core.project_file import load_project

        recovered = 0
        for item in find_recoveries(self.folder):
            buttons = (QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Discard
                       | QMessageBox.StandardButton.Ignore)
            answer = QMessageBox.question(
                self.window, "Recover unsaved work",
                "Wrinkle Studio did not close normally last time. Unsaved work was found:\n\n"
                f"{item.describe()}\n\nRecover it? (Yes: open it as an unsaved document; "
                "Discard: delete it; Ignore: ask again next time)", buttons)
            if answer == QMessageBox.StandardButton.Discard:
                item.remove()
                continue
            if answer != QMessageBox.StandardButton.Yes:
                continue
            try:
                project = load_project(item.project_file)
            except StudioError as exc:
                self.window.show_error("Cannot recover project", exc)
                continue
            target = self.window if recovered == 0 and not self.window.doc.modified \
                else _new_window(self.window)
            target.doc.replace_project(project, None)
            target.doc.undo_stack.resetClean()  # unsaved until the user saves it somewhere
            target.statusBar().showMessage(
                f"Recovered “{item.name}” — save it to keep it", 10_000)
            item.remove()
            recovered += 1
        return recovered


def _new_window(parent: MainWindow) -> MainWindow:
    """A further window for a second recovered document (kept alive by the first)."""
    window = type(parent)(parent.doc.project)
    parent._recovered_windows = [*getattr(parent, "_recovered_windows", []), window]
    window.show()
    return window


def _write_json(path: Path, data: dict[str, Any]) -> None:
    temp = path.with_name(f".{path.name}.tmp")
    temp.write_text(json.dumps(data), encoding="utf-8")
    os.replace(temp, path)


def _interval_minutes() -> float:
    from studio.widgets.main_window import settings

    try:
        return float(settings().value(INTERVAL_KEY, DEFAULT_MINUTES))
    except (TypeError, ValueError):
        return DEFAULT_MINUTES


def install_autosave(window: MainWindow) -> Autosaver:
    """Autosave ``window``'s document, keep its undo history in budget, offer recovery once
    the window is running (a queued call, so the window shows before any question)."""
    from studio.widgets.undo_budget import install_undo_budget

    window.autosaver = Autosaver(window)
    window.undo_budget = install_undo_budget(window.doc.undo_stack, window)
    QTimer.singleShot(0, window.autosaver.offer_recovery)
    return window.autosaver
