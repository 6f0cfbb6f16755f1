"""Reading and writing user files safely: the one place every reader and writer goes through.

Why a module of its own: a careless or hostile path (``/dev/zero``, a FIFO, a folder, a name
with a null byte, the command's own input given again as its output) used to hang, traceback or
overwrite a file, each in a different place. Here:

- :func:`require_regular` and :func:`read_regular` refuse anything but a regular file *before*
  opening it for reading (a FIFO blocks ``open`` for ever, ``/dev/zero`` never ends), and read
  at most a stated number of bytes;
- :func:`check_output` checks a destination before any work starts: not a folder, not one of the
  command's inputs, in a folder that exists (or can be made) and can be written;
- :func:`atomic_output` writes through a locked temporary file beside the target that is renamed
  over it only once complete, so an interrupted write leaves the old file (or none), never a
  broken one. It shares the project file's temporary-file helpers (locking, removal of the
  leftovers of a killed run, permissions, folder fsync), so every writer behaves the same.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from studio.core.errors import StudioError


def check_path_text(path: str | Path, error: type[StudioError] = StudioError) -> Path:
    """``path`` as a Path, refusing names no file can have (empty, or with a null byte)."""
    text = os.fspath(path)
    if text == "":
        raise error("an empty file name")
    if "\0" in text:
        raise error(f"the file name {text!r} contains a null byte, which no file name can")
    return Path(text)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO pipe"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def require_regular(path: str | Path, error: type[StudioError] = StudioError,
                    what: str = "file") -> Path:
    """Raise ``error`` unless ``path`` is an existing regular file (links followed).

    For readers that hand the path to a library (zipfile, trimesh): ``stat`` never blocks, so a
    FIFO or device is refused at once instead of hanging the library's ``open`` or ``read``.
    """
    path = check_path_text(path, error)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise error(f"the {what} does not exist", path) from None
    except OSError as exc:
        raise error(f"cannot read the {what}: {exc.strerror or exc}", path) from None
    if not stat.S_ISREG(mode):
        raise error(f"not a file: this is {_kind(mode)}, not a {what}", path)
    return path


def read_regular(path: str | Path, limit: int, error: type[StudioError] = StudioError,
                 what: str = "file", setting: str | None = None) -> bytes:
    """The bytes of the regular file ``path``, refusing it when it is larger than ``limit``.

    Opened non-blocking (a FIFO swapped in after the check still cannot block) and checked
    again on the open descriptor; ``setting`` names the environment variable that raises the
    limit, for the message.
    """
    path = require_regular(path, error, what)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise error(f"cannot read the {what}: {exc.strerror or exc}", path) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise error(f"not a file: this is {_kind(info.st_mode)}, not a {what}", path)
        if info.st_size > limit:
            how = f" (set {setting} to raise it)" if setting else ""
            raise error(f"the {what} is {info.st_size} bytes, more than the limit of {limit} "
                        f"bytes{how}", path)
        with os.fdopen(fd, "rb", closefd=False) as handle:
            data = handle.read(limit + 1)
    except OSError as exc:
        raise error(f"cannot read the {what}: {exc.strerror or exc}", path) from None
    finally:
        os.close(fd)
    if len(data) > limit:  # grew while being read
        raise error(f"the {what} is larger than the limit of {limit} bytes", path)
    return data


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def check_output(path: str | Path, inputs: Iterable[str | Path | None] = (),
                 error: type[StudioError] = StudioError, make_folders: bool = False,
                 what: str = "output") -> Path:
    """Check the destination ``path`` before any work is done; returns it as a Path.

    Refused: names no file can have, a folder, one of the command's ``inputs`` (writing over
    the file being read loses it), a destination that is not a regular file (a device or FIFO
    would be replaced by the rename), and a folder that is missing (unless ``make_folders``:
    then the nearest existing one must be a folder) or that cannot be written.
    """
    path = check_path_text(path, error)
    for source in inputs:
        if source is not None and _same_file(path, check_path_text(source, error)):
            raise error(f"the {what} would overwrite the input file {source}; choose another "
                        "name", path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise error(f"cannot write the {what}: {_reason(exc, str(path))}", path) from None
    if mode is not None and not stat.S_ISREG(mode):
        raise error(f"cannot write the {what}: this is {_kind(mode)}", path)
    folder = path.absolute().parent
    existing = folder
    while not existing.exists():
        if not make_folders:
            raise error(f"cannot write the {what}: the folder {folder} does not exist", path)
        existing = existing.parent
    if not existing.is_dir():
        raise error(f"cannot write the {what}: {existing} is not a folder", path)
    if not os.access(existing, os.W_OK | os.X_OK):
        raise error(f"cannot write the {what}: permission denied for the folder {existing}",
                    path)
    return path


def make_folder(folder: str | Path, error: type[StudioError] = StudioError) -> None:
    """Create ``folder`` and its parents, as a StudioError naming it when that fails."""
    try:
        Path(folder).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise error(f"cannot create the folder: {_reason(exc, str(folder))}", folder) from None


def _reason(exc: OSError, where: str) -> str:
    from studio.core.project_file import _os_reason

    return _os_reason(exc, where)


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
    from studio.core import project_file as pf  # its temp-file helpers; imported late (cycle)

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
