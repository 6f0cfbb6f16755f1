"""The crash log: what Python's faulthandler says when the studio dies in native code.

A segmentation fault in Qt or a driver ends the process before any Python handler runs; only
faulthandler, armed beforehand with a file of its own, still writes the Python stack of every
thread. That file lives in the user's data folder (``crash-logs/``), named by start time and
process, and the recovery offer at the next start names it. A process that ends without a
fault leaves an empty file, which is deleted at exit; logs that say something are kept (the
newest ``KEEP``) for a bug report.
"""

from __future__ import annotations

import atexit
import contextlib
import faulthandler
import os
import time
from pathlib import Path
from typing import TextIO

from studio.widgets.app_settings import data_folder

KEEP = 20
_log: tuple[Path, TextIO] | None = None


def crash_log_dir() -> Path:
    return data_folder() / "crash-logs"


def enable_crash_log(folder: Path | None = None) -> Path | None:
    """Arm faulthandler with a file for this process (once); returns its path, or None when no
    file can be made (the studio runs on without one)."""
    global _log
    if _log is not None:
        return _log[0]
    folder = folder or crash_log_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"crash-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"
        stream = path.open("w", encoding="utf-8")
    except OSError:
        return None
    faulthandler.enable(stream, all_threads=True)
    _log = (path, stream)
    atexit.register(_tidy)
    _prune(folder)
    return path


def current_crash_log() -> Path | None:
    """This process's crash log, if one is armed."""
    return _log[0] if _log is not None else None


def _tidy() -> None:
    """At a normal exit: nothing crashed, so the empty log goes."""
    global _log
    if _log is None:
        return
    path, stream = _log
    faulthandler.disable()
    stream.close()
    _log = None
    with contextlib.suppress(OSError):
        if path.stat().st_size == 0:
            path.unlink()


def _prune(folder: Path) -> None:
    logs = sorted(folder.glob("crash-*.log"), reverse=True)  # names start with the time
    for old in logs[KEEP:]:
        with contextlib.suppress(OSError):
            old.unlink()
