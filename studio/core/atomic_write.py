"""Writing user files all or nothing: a temporary file beside the target, renamed over it.

Why: an export, bake or render interrupted half-way (an error, Ctrl+C, a kill, a full disk)
used to leave a truncated file in place of the user's previous one. Every writer of the studio
goes through :func:`atomic_output`, which reuses the project file's temporary-file helpers
(locking, removal of the leftovers of a killed run, permissions, folder fsync) so that all
files are written the same way as projects always were.
"""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from studio.core import project_file as pf
from studio.core.errors import StudioError
from studio.core.safe_io import check_path_text, make_folder


def _reason(exc: OSError, where: str) -> str:
    return pf._os_reason(exc, where)


@contextlib.contextmanager
def atomic_output(path: str | Path, error: type[StudioError] = StudioError,
                  make_folders: bool = False, what: str = "file") -> Iterator[IO[bytes]]:
    """Write ``path`` all or nothing: yields an open, locked temporary file beside it.

    The caller writes into the handle (or, for a library that wants a name, to
    ``handle.name``); on a clean exit it is flushed, fsynced, given the old file's permissions
    and renamed over ``path``. On any exception (Ctrl+C included) it is removed and ``path`` is
    untouched; a run killed outright leaves only the hidden, locked temporary file, which the
    next write of the same target sweeps away.
    """
    path = check_path_text(path, error)
    if make_folders:
        make_folder(path.absolute().parent, error)
    target = Path(os.path.realpath(path))
    folder = target.parent
    pf._remove_stale_temps(folder, target.name)
    try:
        handle = pf._locked_temp(folder, target.name)
    except OSError as exc:
        raise error(f"cannot write the {what}: {_reason(exc, f'the folder {folder}')}",
                    path) from None
    try:
        with handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
            pf._copy_mode(handle.name, target)
        os.replace(handle.name, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(handle.name)
        if isinstance(exc, OSError):
            reason = "the disk is full" if exc.errno == errno.ENOSPC else _reason(exc, str(path))
            raise error(f"cannot write the {what}: {reason}", path) from None
        raise
    pf._fsync_folder(folder)


def write_atomic(path: str | Path, data: bytes, error: type[StudioError] = StudioError,
                 make_folders: bool = False, what: str = "file") -> None:
    """``path.write_bytes(data)``, all or nothing (see :func:`atomic_output`)."""
    with atomic_output(path, error, make_folders, what) as handle:
        handle.write(data)
