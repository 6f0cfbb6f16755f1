"""Recovery files: the bookkeeping behind autosave, with no Qt in it.

A window's recovery file is three files side by side in the recovery folder::

    <session>.wrinkle   the document as it was at the last autosave
    <session>.json      what it is: project name, original path, time (shown in the offer)
    <session>.lock      locked (flock) for as long as the window lives; touched every few
                        seconds, so its time says when a window that died was last alive

Why the lock: a recovery file whose lock nobody holds was left by a window that did not close
normally (the kernel drops a dead process's locks), so it is offered at the next start; a file
still locked belongs to a running window (this process or another) and is left alone. Where
there are no advisory locks (Windows) the pid in the ``.json`` decides instead.

Why here and not with the widgets: which files are orphaned, what they say, how a project is
copied so that a worker thread can write it while edits go on — none of it needs a window, and
all of it is tested in milliseconds. The timers, the worker thread and the question box are
``studio.widgets.autosave``'s.
"""

from __future__ import annotations

import contextlib
import copy
import json
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from studio.core.project import writer
from studio.core.project.model import Project

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

# The most memory the last snapshot's copies may keep between autosaves (the ICT head: 141 MB):
# a project past it is copied whole at each autosave, as before, rather than held twice.
KEEP_BYTES = 512 << 20
SUFFIXES = (".wrinkle", ".json", ".lock")


@dataclass
class Recovery:
    """One recovery file left by a window that did not close normally."""

    project_file: Path
    name: str
    original: str | None
    saved_at: float
    stopped_at: float | None = None  # the window's last sign of life (its lock's time)
    crash_log: Path | None = None  # what faulthandler wrote when it died, if anything

    def describe(self) -> str:
        when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.saved_at))
        origin = self.original or "never saved"
        return f"“{self.name}”\nOriginal file: {origin}\nAutosaved: {when}"

    def story(self) -> str:
        """What happened, in a person's words: when the studio stopped and how recent the
        recovered work is, and where the crash log is when there is one."""
        stopped = max(self.stopped_at or 0.0, self.saved_at)
        day = time.strftime("%Y-%m-%d", time.localtime(stopped))
        today = time.strftime("%Y-%m-%d")
        at = time.strftime("%H:%M" if day == today else "%Y-%m-%d %H:%M", time.localtime(stopped))
        upto = time.strftime("%H:%M:%S", time.localtime(self.saved_at))
        text = (f"The studio stopped unexpectedly at {at}; your work up to {upto} is "
                "recovered.")
        if self.crash_log is not None:
            text += f"\nCrash log: {self.crash_log}"
        return text

    def remove(self) -> None:
        for suffix in SUFFIXES:  # (the crash log stays, for a report)
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(suffix).unlink()


class RecoveryFile:
    """One live window's recovery file: its lock, its heartbeat, its write and its removal."""

    def __init__(self, folder: Path, session: str) -> None:
        self.folder = folder
        self.session = session
        self._lock_fd: int | None = None

    @property
    def project_file(self) -> Path:
        return self.folder / f"{self.session}.wrinkle"

    @property
    def locked(self) -> bool:
        return self._lock_fd is not None

    def take_lock(self) -> None:
        """Create the folder and hold the lock (OSError when either fails)."""
        if self._lock_fd is not None:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.project_file.with_suffix(".lock"), os.O_RDWR | os.O_CREAT, 0o600)
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        self._lock_fd = fd

    def beat(self) -> None:
        """A sign of life on the lock file: its time is when a window that died was last alive."""
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                os.utime(self.project_file.with_suffix(".lock"))

    def remove(self) -> None:
        """Delete the project and its description; the lock stays held."""
        for suffix in (".wrinkle", ".json"):
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(suffix).unlink()

    def release(self, delete_lock: bool) -> None:
        """Let go of the lock (a crash keeps its file, a clean exit deletes it)."""
        if self._lock_fd is None:
            return
        if delete_lock:
            with contextlib.suppress(OSError):
                self.project_file.with_suffix(".lock").unlink()
        os.close(self._lock_fd)
        self._lock_fd = None

    def adopt(self, item: Recovery) -> None:
        """Become ``item``'s file: this one's lock is deleted, ``item``'s taken (OSError when it
        cannot be: the file stays where it is, offered again next time)."""
        self.release(delete_lock=True)
        self.folder = item.project_file.parent
        self.session = item.project_file.stem
        self.take_lock()
        self.beat()


def write_recovery(project: Project, target: Path, meta: dict[str, Any]) -> None:
    """Write ``project`` atomically to ``target``, then its description (any thread: the path
    is the one the write was started for, whatever the window adopted meanwhile)."""
    writer.save_project(project, target, backup=False)
    write_json(target.with_suffix(".json"), meta)


def recovery_meta(name: str, original: Path | None, crash_log: Path | None) -> dict[str, Any]:
    """What the ``.json`` says of a recovery file (the pid decides where there are no locks)."""
    return {"name": name, "original": str(original) if original else None,
            "saved_at": time.time(), "pid": os.getpid(),
            "crash_log": str(crash_log) if crash_log is not None else None}


def owner_alive(lock: Path, meta: dict[str, Any]) -> bool:
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


def find_recoveries(folder: Path) -> list[Recovery]:
    """Orphaned recovery files, newest first; stray lock files of dead windows are removed."""
    if not folder.is_dir():
        return []
    found: list[Recovery] = []
    for project_file in folder.glob("*.wrinkle"):
        meta = _read_meta(project_file.with_suffix(".json"))
        if owner_alive(project_file.with_suffix(".lock"), meta):
            continue
        mtime = _mtime(project_file)
        if mtime is None:
            continue
        name = meta.get("name") if isinstance(meta.get("name"), str) else project_file.stem
        original = meta.get("original") if isinstance(meta.get("original"), str) else None
        saved_at = meta.get("saved_at")
        saved_at = float(saved_at) if isinstance(saved_at, int | float) else mtime
        found.append(Recovery(project_file, name, original, saved_at,
                              _mtime(project_file.with_suffix(".lock")),
                              _crash_log(meta.get("crash_log"))))
    for lock in folder.glob("*.lock"):  # a window that died before its first autosave
        if not lock.with_suffix(".wrinkle").exists() and not owner_alive(lock, {}):
            with contextlib.suppress(OSError):
                lock.unlink()
    found.sort(key=lambda r: r.saved_at, reverse=True)
    return found


def _read_meta(path: Path) -> dict[str, Any]:
    """A recovery file's description; a missing or damaged one is an empty description (the
    file is still offered, named after itself)."""
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def _mtime(path: Path) -> float | None:
    try:
        return path.stat().st_mtime
    except OSError:
        return None


def _crash_log(value: object) -> Path | None:
    """The crash log a dead window's process wrote, if it wrote anything."""
    if not isinstance(value, str):
        return None
    path = Path(value)
    try:
        return path if path.is_file() and path.stat().st_size > 0 else None
    except OSError:
        return None


def write_json(path: Path, data: dict[str, Any]) -> None:
    """``data`` as JSON, replacing ``path`` whole (a reader never sees half of it)."""
    temp = path.with_name(f".{path.name}.tmp")
    temp.write_text(json.dumps(data), encoding="utf-8")
    os.replace(temp, path)


def snapshot_project(project: Project,
                     kept: dict[int, tuple[np.ndarray, np.ndarray]] | None = None) -> Project:
    """A copy of ``project`` that no later edit can reach, cheap enough for the GUI thread.

    Every writable array is copied (about 50 ms for the ICT head's 141 MB, against a second or
    more of CPU to write it): which arrays an edit writes in place is up to each command, so
    copying them all is the one rule that stays true as commands are added. Arrays that cannot
    change are shared: a loaded project's images are read-only views of the file's bytes.
    ``kept`` maps ``id(array)`` to ``(array, copy)`` from an earlier snapshot, for arrays known
    not to have changed since (see ``studio.widgets.autosave.SnapshotCopies``); it is refreshed
    with this one's, unless they would hold more than ``KEEP_BYTES``.
    """
    arrays = list(_arrays(project, set()))
    memo: dict[int, object] = {}
    for a in arrays:
        if _immutable(a):
            memo[id(a)] = a
        elif kept is not None and id(a) in kept and kept[id(a)][0] is a:
            memo[id(a)] = kept[id(a)][1]
    snapshot = copy.deepcopy(project, memo)
    if kept is not None:
        kept.clear()
        copies = {id(a): (a, memo[id(a)]) for a in arrays
                  if not _immutable(a) and id(a) in memo}
        if sum(a.nbytes for a, _ in copies.values()) <= KEEP_BYTES:  # type: ignore[union-attr]
            kept.update(copies)  # type: ignore[arg-type]
    return snapshot


def _immutable(array: np.ndarray) -> bool:
    """Whether nothing can write into ``array``: read-only, and so is all memory under it (a
    read-only view of a writable array changes when the array does)."""
    base: object = array
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return False
        base = base.base
    return base is None or isinstance(base, bytes)


def _arrays(value: object, seen: set[int]) -> Iterator[np.ndarray]:
    """The numpy arrays reachable from ``value`` (attributes, lists, tuples, dict values)."""
    if id(value) in seen:
        return
    seen.add(id(value))
    if isinstance(value, np.ndarray):
        yield value
    elif isinstance(value, dict):
        for item in value.values():
            yield from _arrays(item, seen)
    elif isinstance(value, list | tuple):
        for item in value:
            yield from _arrays(item, seen)
    elif hasattr(value, "__dict__"):
        for item in vars(value).values():
            yield from _arrays(item, seen)
