"""Writing user files all or nothing: a temporary file beside the target, renamed over it.

Why: an export, bake or render interrupted half-way (an error, Ctrl+C, a kill, a full disk)
used to leave a truncated file in place of the user's previous one. Every writer of the studio,
the project file's included, goes through :func:`atomic_output`: a locked temporary file (so
the leftovers of a killed run are swept away by the next write, never a file being written),
the old file's permissions, an fsync of the file and of its folder.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

from studio.core.files.errors import StudioError
from studio.core.files.processes import process_tag, tag_alive
from studio.core.files.safe_io import check_path_text, make_folder, os_reason


@contextlib.contextmanager
def atomic_output(path: str | Path, error: type[StudioError] = StudioError,
                  make_folders: bool = False, what: str = "file", verb: str = "write",
                  before_replace: Callable[[Path], None] | None = None) -> Iterator[IO[bytes]]:
    """Write ``path`` all or nothing: yields an open, locked temporary file beside it.

    The caller writes into the handle (or, for a library that wants a name, to
    ``handle.name``); on a clean exit it is flushed, fsynced, given the old file's permissions
    and renamed over ``path``. On any exception (Ctrl+C included) it is removed and ``path`` is
    untouched; a run killed outright leaves only the hidden, locked temporary file, which the
    next write of the same target sweeps away. ``before_replace(target)`` runs just before the
    rename (the project writer keeps the old file as a backup there); errors read "cannot
    {verb} the {what}: …".
    """
    path = check_path_text(path, error)
    if make_folders:
        make_folder(path.absolute().parent, error)
    target = Path(os.path.realpath(path))
    folder = target.parent
    remove_stale_temps(folder, target.name)
    try:
        handle = locked_temp(folder, target.name)
    except OSError as exc:
        raise error(f"cannot {verb} the {what}: {os_reason(exc, f'the folder {folder}')}",
                    path) from None
    try:
        with handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
            copy_mode(handle.name, target)
        if before_replace is not None:
            before_replace(target)
        os.replace(handle.name, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(handle.name)
        if isinstance(exc, OSError):
            raise error(f"cannot {verb} the {what}: {os_reason(exc, str(path))}", path) from None
        raise
    fsync_folder(folder)


def write_atomic(path: str | Path, data: bytes, error: type[StudioError] = StudioError,
                 make_folders: bool = False, what: str = "file") -> None:
    """``path.write_bytes(data)``, all or nothing (see :func:`atomic_output`)."""
    with atomic_output(path, error, make_folders, what) as handle:
        handle.write(data)


def temp_prefix(name: str) -> str:
    """The hidden name every temporary file of ``name`` starts with."""
    return f".{name}."


def locked_temp(folder: Path, name: str) -> Any:
    """A new temporary file beside the target, locked while it is written.

    Why the lock: a save killed half-way leaves its temporary file behind; the next save removes
    the ones nobody holds a lock on (the kernel drops a dead process's locks), never a file that
    another save is writing right now.
    """
    for _ in range(5):
        handle = tempfile.NamedTemporaryFile(  # noqa: SIM115 - the caller closes it
            dir=folder, prefix=temp_prefix(name), suffix=".tmp", delete=False)
        if fcntl is None:
            return handle
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX)
        if os.fstat(handle.fileno()).st_nlink > 0:  # not swept away before it was locked
            return handle
        handle.close()
    return handle


def remove_stale_temps(folder: Path, name: str) -> None:
    """Delete temporary files of earlier saves of ``name`` that died before renaming them."""
    if fcntl is None:  # no advisory locks (Windows): leave them, they are only hidden litter
        return
    prefix = temp_prefix(name)
    try:
        entries = [e for e in os.scandir(folder)
                   if e.name.startswith(prefix) and e.name.endswith(".tmp")]
    except OSError:
        return
    for entry in stale_backup_staging(folder, name):
        with contextlib.suppress(OSError):
            os.unlink(entry)
    for entry in entries:
        try:
            fd = os.open(entry.path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            continue
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                continue
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # held: a save is writing it
            os.unlink(entry.path)
        except OSError:
            pass
        finally:
            os.close(fd)


def stale_backup_staging(folder: Path, name: str) -> list[str]:
    """Half-made backups (the project writer's ``keep_backup`` staging links) of processes
    that have died."""
    prefix = f".{name}.bak."
    stale = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if not (entry.name.startswith(prefix) and entry.name.endswith(".staging")):
                continue
            tag = entry.name[len(prefix):-len(".staging")]
            if tag != process_tag() and tag_alive(tag, entry.stat().st_ctime) is False:
                stale.append(entry.path)
    return stale



def copy_mode(temp: str, target: Path) -> None:
    """Give the new file the old one's permissions (or the umask's), not mkstemp's 0600."""
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    with contextlib.suppress(OSError):  # a file system without modes still gets the file
        os.chmod(temp, mode)


def fsync_folder(folder: Path) -> None:
    """Make the rename itself durable where the platform allows opening a folder."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
