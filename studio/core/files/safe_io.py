"""Reading and writing user files safely: the one place every reader and writer goes through.

Why a module of its own: a careless or hostile path (``/dev/zero``, a FIFO, a folder, a name
with a null byte, the command's own input given again as its output) used to hang, traceback or
overwrite a file, each in a different place. Here:

- :func:`require_regular` and :func:`read_regular` refuse anything but a regular file *before*
  opening it for reading (a FIFO blocks ``open`` for ever, ``/dev/zero`` never ends), and read
  at most a stated number of bytes;
- :func:`check_output` checks a destination before any work starts: not a folder, not one of the
  command's inputs, in a folder that exists (or can be made) and can be written;
- :func:`os_reason` words what the operating system refused, the same for every file;
- writing all or nothing is :mod:`studio.core.files.atomic_write`'s.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Iterable
from pathlib import Path
from typing import BinaryIO

from studio.core.files.errors import StudioError


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
    if stat.S_ISREG(mode):
        return "a file"
    return "not a regular file"


def _not_regular(mode: int, what: str) -> str:
    """"not a file: this is a folder, not an image" — the message for a path of ``mode``."""
    article = "an" if what[:1].lower() in "aeiou" else "a"
    return f"not a file: this is {_kind(mode)}, not {article} {what}"


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
        raise error(_not_regular(mode, what), path)
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
            raise error(_not_regular(info.st_mode, what), path)
        if info.st_size > limit:
            how = f" (set {setting} to raise it)" if setting else ""
            raise error(f"the {what} is {info.st_size} bytes, more than the limit of {limit} "
                        f"bytes{how}", path)
        with os.fdopen(fd, "rb", closefd=False) as handle:
            data = _read_at_most(handle, min(limit, info.st_size), limit)
    except OSError as exc:
        raise error(f"cannot read the {what}: {exc.strerror or exc}", path) from None
    finally:
        os.close(fd)
    if len(data) > limit:  # grew while being read
        raise error(f"the {what} is larger than the limit of {limit} bytes", path)
    return data


def _read_at_most(handle: BinaryIO, size: int, limit: int) -> bytes:
    """The handle's bytes, ``size`` expected, at most ``limit + 1``. Why not ``read(limit +
    1)``: Python allocates the whole request first, 2 GB of address space for a 1 kB file,
    which fails outright under a memory limit (``ulimit -v``). A file that grows while it is
    read is read on a megabyte at a time."""
    data = handle.read(size + 1)
    if len(data) <= size:
        return data
    grown = bytearray(data)
    while len(grown) <= limit:
        piece = handle.read(min(1 << 20, limit + 1 - len(grown)))
        if not piece:
            break
        grown += piece
    return bytes(grown)


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
        raise error(f"cannot write the {what}: {os_reason(exc, str(path))}", path) from None
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


def check_output_folder(path: str | Path, error: type[StudioError] = StudioError,
                        what: str = "folder") -> Path:
    """Check a destination folder before any work: an existing folder is fine (exporting
    again replaces its files, each one atomically, as an exporter's user expects), a file or
    device is refused, a missing one is made later if its nearest existing parent is a
    writable folder."""
    path = check_path_text(path, error)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return check_output(path, (), error, make_folders=True, what=what)
    except OSError as exc:
        raise error(f"cannot write the {what}: {os_reason(exc, str(path))}", path) from None
    if not stat.S_ISDIR(mode):
        raise error(f"cannot write the {what}: this is {_kind(mode)}, not a folder", path)
    if not os.access(path, os.W_OK | os.X_OK):
        raise error(f"cannot write the {what}: permission denied for the folder {path}", path)
    return path


def make_folder(folder: str | Path, error: type[StudioError] = StudioError) -> None:
    """Create ``folder`` and its parents, as a StudioError naming it when that fails."""
    try:
        Path(folder).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise error(f"cannot create the folder: {os_reason(exc, str(folder))}", folder) from None


def os_reason(exc: OSError, where: str) -> str:
    """One plain phrase for what the operating system refused, naming ``where`` when it is the
    place's fault (every reader and writer of the studio words its refusals with this)."""
    reasons = {
        errno.ENOSPC: "the disk is full",
        errno.EDQUOT: "the disk quota is exceeded",
        errno.EACCES: f"permission denied for {where}",
        errno.EPERM: f"permission denied for {where}",
        errno.EROFS: f"{where} is on a read-only disk",
        errno.ENOENT: f"{where} does not exist",
        errno.EISDIR: f"{where} is a folder",
        errno.ENOTDIR: f"a part of {where} is not a folder",
        errno.ENAMETOOLONG: f"the name {where} is too long",
        errno.ELOOP: f"{where} is a loop of symbolic links",
        errno.EIO: "the disk reported an input/output error",
    }
    return reasons.get(exc.errno, f"{exc.strerror or exc} ({where})")
