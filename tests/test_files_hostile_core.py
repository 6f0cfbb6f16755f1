"""Hostile paths and files met by the studio's readers and writers: folders, FIFOs, devices and
sockets given where a file or an output folder is wanted, folders that cannot be made, refusals
of the operating system worded for the user, process ids left in the names of stale files, and
images in the less common layouts (16-bit little-endian, palette with alpha, a header claiming a
decompression bomb). Each refusal must be the right error class, name the file and say exactly
what is wrong; each accepted input must come back with the right values.

Why: these are the paths a careless or hostile input takes; a message that loses the file name
or words the problem wrongly leaves the user guessing, and a wrong liveness answer deletes the
file of a save still running (or keeps a stale one for ever)."""

from __future__ import annotations

import ctypes
import ctypes.util
import errno
import io
import os
import socket
import stat
import struct
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.files import processes
from studio.core.files.errors import ImageError, MeshError, StudioError
from studio.core.files.images import decode_image, read_image, write_tiff
from studio.core.files.png_unfilter import unfilter_with_pillow
from studio.core.files.safe_io import (
    _kind,
    _not_regular,
    check_output_folder,
    make_folder,
    os_reason,
    require_regular,
)
from tests.test_png_filters import filter_rows

pytestmark = pytest.mark.core

# A process id no system hands out: Linux caps pid_max at 2**22.
NO_SUCH_PID = 2**30


# --- what a path is ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("mode", "kind"),
    [
        (stat.S_IFDIR, "a folder"),
        (stat.S_IFIFO, "a FIFO pipe"),
        (stat.S_IFCHR, "a device"),
        (stat.S_IFBLK, "a device"),
        (stat.S_IFSOCK, "a socket"),
        (stat.S_IFLNK, "not a regular file"),
    ],
)
def test_each_kind_of_path_is_named_in_plain_words(mode: int, kind: str) -> None:
    """A character device and a block device are both "a device"; a kind without a word of
    its own is "not a regular file"."""
    assert _kind(mode | 0o644) == kind


@pytest.mark.parametrize(
    ("what", "message"),
    [
        ("image", "not a file: this is a folder, not an image"),
        ("mesh file", "not a file: this is a folder, not a mesh file"),
        ("Output", "not a file: this is a folder, not an Output"),
        ("project", "not a file: this is a folder, not a project"),
    ],
)
def test_the_article_before_what_was_wanted_follows_its_first_letter(
    what: str, message: str
) -> None:
    assert _not_regular(stat.S_IFDIR, what) == message


def test_a_fifo_socket_and_device_are_refused_as_input_by_their_kind(tmp_path: Path) -> None:
    """``stat`` sees what the path is without opening it, so nothing blocks."""
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    with pytest.raises(MeshError) as caught:
        require_regular(fifo, MeshError, "mesh file")
    assert caught.value.path == fifo
    assert caught.value.problem == "not a file: this is a FIFO pipe, not a mesh file"

    sock = tmp_path / "s.png"
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as server:
        server.bind(str(sock))
        with pytest.raises(ImageError) as caught:
            require_regular(sock, ImageError, "image")
    assert caught.value.problem == "not a file: this is a socket, not an image"

    with pytest.raises(ImageError) as caught:
        require_regular("/dev/null", ImageError, "image")
    assert caught.value.problem == "not a file: this is a device, not an image"


# --- output folders -----------------------------------------------------------------------------


def test_an_existing_folder_is_a_fine_output_folder(tmp_path: Path) -> None:
    assert check_output_folder(tmp_path) == tmp_path
    assert check_output_folder(str(tmp_path)) == tmp_path


def test_a_missing_output_folder_is_accepted_and_not_made_yet(tmp_path: Path) -> None:
    """Three levels that do not exist yet: made later, by the exporter, not by the check."""
    target = tmp_path / "a" / "b" / "c"
    assert check_output_folder(target, MeshError) == target
    assert not (tmp_path / "a").exists()


def test_a_device_as_output_folder_is_refused_naming_it() -> None:
    with pytest.raises(StudioError) as caught:
        check_output_folder("/dev/null")
    assert type(caught.value) is StudioError
    assert caught.value.path == Path("/dev/null")
    assert caught.value.problem == "cannot write the folder: this is a device, not a folder"


def test_a_file_as_output_folder_is_refused_as_a_file(tmp_path: Path) -> None:
    target = tmp_path / "export"
    target.write_text("notes")
    with pytest.raises(StudioError) as caught:
        check_output_folder(target)
    assert caught.value.problem == "cannot write the folder: this is a file, not a folder"


def test_a_fifo_as_output_folder_is_refused_in_the_callers_words(tmp_path: Path) -> None:
    fifo = tmp_path / "export"
    os.mkfifo(fifo)
    with pytest.raises(MeshError) as caught:
        check_output_folder(fifo, MeshError, "export folder")
    assert caught.value.path == fifo
    assert caught.value.problem == (
        "cannot write the export folder: this is a FIFO pipe, not a folder"
    )


def test_an_output_folder_under_a_file_says_a_part_is_not_a_folder(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("x")
    target = tmp_path / "notes.txt" / "export"
    with pytest.raises(MeshError) as caught:
        check_output_folder(target, MeshError)
    assert caught.value.path == target
    assert caught.value.problem == f"cannot write the folder: a part of {target} is not a folder"


@pytest.mark.parametrize(
    ("name", "problem"),
    [
        ("", "an empty file name"),
        ("out\0put", "the file name 'out\\x00put' contains a null byte, which no file name can"),
    ],
)
def test_an_output_folder_name_no_file_can_have_is_the_callers_error(
    name: str, problem: str
) -> None:
    with pytest.raises(MeshError) as caught:
        check_output_folder(name, MeshError)
    assert caught.value.problem == problem


@pytest.fixture
def read_only_folders(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every folder readable and searchable but not writable (tests run as root, where a chmod
    would not refuse anything)."""
    real = os.access

    def access(path: object, mode: int, *args: object, **kwargs: object) -> bool:
        if mode & os.W_OK:
            return False
        return real(path, mode, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "access", access)


@pytest.mark.usefixtures("read_only_folders")
def test_a_folder_that_cannot_be_written_is_refused(tmp_path: Path) -> None:
    with pytest.raises(MeshError) as caught:
        check_output_folder(tmp_path, MeshError)
    assert caught.value.path == tmp_path
    assert (
        caught.value.problem == f"cannot write the folder: permission denied for the folder "
        f"{tmp_path}"
    )


@pytest.mark.usefixtures("read_only_folders")
def test_a_missing_folder_under_a_read_only_one_is_refused_naming_the_parent(
    tmp_path: Path,
) -> None:
    target = tmp_path / "new" / "deeper"
    with pytest.raises(MeshError) as caught:
        check_output_folder(target, MeshError, "texture folder")
    assert caught.value.path == target
    assert caught.value.problem == (
        f"cannot write the texture folder: permission denied for the folder {tmp_path}"
    )


# --- making folders --------------------------------------------------------------------------


def test_make_folder_makes_every_missing_level_and_allows_an_existing_one(tmp_path: Path) -> None:
    target = tmp_path / "a" / "b" / "c"
    make_folder(target)
    assert target.is_dir()
    make_folder(str(target))  # already there: fine
    assert target.is_dir()


def test_make_folder_under_a_file_names_the_folder(tmp_path: Path) -> None:
    (tmp_path / "f").write_text("x")
    target = tmp_path / "f" / "sub"
    with pytest.raises(MeshError) as caught:
        make_folder(target, MeshError)
    assert caught.value.path == target
    assert caught.value.problem == f"cannot create the folder: a part of {target} is not a folder"


def test_make_folder_over_a_file_gives_the_systems_words_and_the_name(tmp_path: Path) -> None:
    target = tmp_path / "f"
    target.write_text("x")
    with pytest.raises(ImageError) as caught:
        make_folder(target, ImageError)
    assert caught.value.path == target
    assert caught.value.problem == f"cannot create the folder: File exists ({target})"


# --- the operating system's refusals ------------------------------------------------------------


@pytest.mark.parametrize(
    ("code", "reason"),
    [
        (errno.ENOSPC, "the disk is full"),
        (errno.EDQUOT, "the disk quota is exceeded"),
        (errno.EIO, "the disk reported an input/output error"),
        (errno.EACCES, "permission denied for /x/y"),
        (errno.EROFS, "/x/y is on a read-only disk"),
        (errno.ELOOP, "/x/y is a loop of symbolic links"),
    ],
)
def test_known_refusals_are_worded_for_the_user(code: int, reason: str) -> None:
    assert os_reason(OSError(code, os.strerror(code)), "/x/y") == reason


def test_other_refusals_give_the_systems_words_then_the_place() -> None:
    assert (
        os_reason(OSError(errno.EBUSY, "Device or resource busy"), "/x")
        == "Device or resource busy (/x)"
    )
    assert os_reason(OSError("no errno at all"), "/x") == "no errno at all (/x)"


# --- whether a process still runs -------------------------------------------------------------


def _start_time(pid: int) -> float:
    """When process ``pid`` started, in seconds since the epoch, from /proc."""
    boot = next(
        float(line.split()[1])
        for line in Path("/proc/stat").read_text().splitlines()
        if line.startswith("btime")
    )
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return boot + float(fields[19]) / os.sysconf("SC_CLK_TCK")


needs_proc = pytest.mark.skipif(not os.path.exists("/proc/stat"), reason="needs Linux /proc")


def test_this_process_is_alive_and_a_pid_no_system_gives_is_not() -> None:
    assert processes.process_alive(os.getpid()) is True
    assert processes.process_alive(NO_SUCH_PID) is False
    assert processes.process_alive(NO_SUCH_PID, time.time()) is False


def test_someone_elses_process_counts_as_alive(monkeypatch: pytest.MonkeyPatch) -> None:
    """``kill`` refused (another user's process): it exists, whatever /proc would say."""

    def kill(pid: int, sig: int) -> None:
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "kill", kill)
    assert processes.process_alive(NO_SUCH_PID, time.time()) is True


def test_a_process_that_vanishes_before_proc_is_read_counts_as_alive(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """When the start time cannot be read the answer errs on keeping the file's owner alive."""
    monkeypatch.setattr(os, "kill", lambda pid, sig: None)
    assert processes.process_alive(NO_SUCH_PID, time.time()) is True


@needs_proc
def test_a_file_made_before_the_process_started_is_from_another_process() -> None:
    """A second's grace: made up to 1 s before this process started still counts as ours."""
    start = _start_time(os.getpid())
    assert processes.process_alive(os.getpid(), start - 1.0) is True
    assert processes.process_alive(os.getpid(), start - 1.5) is False
    assert processes.process_alive(os.getpid(), start - 1e6) is False
    assert processes.process_alive(os.getpid(), time.time()) is True


@needs_proc
def test_a_threads_id_is_not_a_live_process() -> None:
    seen: list[bool] = []
    worker = threading.Thread(
        target=lambda: seen.append(processes.process_alive(threading.get_native_id(), time.time()))
    )
    worker.start()
    worker.join()
    assert seen == [False]


@pytest.fixture
def odd_process_name() -> Iterator[str]:
    """This process renamed to one holding ')' and numbers, as a hostile program could be."""
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    pr_set_name, pr_get_name = 15, 16
    old = ctypes.create_string_buffer(32)
    if (
        libc.prctl(pr_get_name, old, 0, 0, 0) != 0
        or threading.current_thread() is not threading.main_thread()
    ):
        pytest.skip("cannot rename the process")
    name = b"w) 1 2 3 4 5 6"
    libc.prctl(pr_set_name, name, 0, 0, 0)
    try:
        yield name.decode()
    finally:
        libc.prctl(pr_set_name, old.value, 0, 0, 0)


@needs_proc
def test_a_process_name_with_a_parenthesis_does_not_shift_the_start_time(
    odd_process_name: str,
) -> None:
    """/proc/PID/stat puts the name in parentheses; only the last ')' ends it."""
    assert Path(f"/proc/{os.getpid()}/comm").read_text().strip() == odd_process_name
    start = _start_time(os.getpid())
    assert processes.process_alive(os.getpid(), start - 1.5) is False
    assert processes.process_alive(os.getpid(), start) is True


# --- images in less common layouts ------------------------------------------------------------


def _pillow_bytes(image: Image.Image, fmt: str) -> bytes:
    buffer = io.BytesIO()
    image.save(buffer, fmt)
    return buffer.getvalue()


@pytest.mark.filterwarnings("ignore:IM image format is deprecated:DeprecationWarning")
def test_a_little_endian_16_bit_image_keeps_its_16_bits() -> None:
    """An IM file stores I;16L: 513 and 65535 must not be cut to 8 bits or turned to colour."""
    image = Image.new("I;16L", (3, 1))
    image.putpixel((0, 0), 513)
    image.putpixel((2, 0), 65535)
    pixels = decode_image(_pillow_bytes(image, "IM"), "grey.im")
    assert pixels.dtype == np.uint16
    np.testing.assert_array_equal(pixels, [[513, 0, 65535]])


def test_a_palette_image_with_alpha_comes_back_as_rgba() -> None:
    """A PA TIFF: colours from the palette, the alpha kept as a fourth channel."""
    image = Image.new("PA", (2, 1))
    image.putpalette([0, 0, 0, 10, 20, 30, 200, 100, 50] + [0] * (256 * 3 - 9))
    image.putpixel((0, 0), (1, 255))
    image.putpixel((1, 0), (2, 64))
    pixels = decode_image(_pillow_bytes(image, "TIFF"), "pa.tif")
    assert pixels.dtype == np.uint8
    np.testing.assert_array_equal(pixels, [[[10, 20, 30, 255], [200, 100, 50, 64]]])


def _bmp_header(width: int, height: int) -> bytes:
    """A 24-bit BMP's headers declaring ``width`` × ``height`` pixels, with no pixels after."""
    info = struct.pack("<IiiHHIIiiII", 40, width, height, 1, 24, 0, 0, 2835, 2835, 0, 0)
    return b"BM" + struct.pack("<IHHI", 14 + len(info), 0, 0, 14 + len(info)) + info


def test_a_non_png_header_claiming_a_decompression_bomb_is_refused_on_opening() -> None:
    """30000² pixels is over twice the studio's 16384² ceiling: Pillow refuses it before any
    memory is taken, and the message names the file."""
    with pytest.raises(ImageError) as caught:
        decode_image(_bmp_header(30000, 30000), "bomb.bmp")
    assert caught.value.path == Path("bomb.bmp")
    assert caught.value.problem.startswith(
        "not an image this studio can read (Image size "
        "(900000000 pixels) exceeds limit of 536870912 pixels"
    )


def test_write_tiff_stores_whole_numbers_of_any_integer_type_as_8_bit(tmp_path: Path) -> None:
    values = np.array([[0, 128, 255], [1, 2, 3]])  # int64, as numpy makes them
    write_tiff(tmp_path / "mask.tif", values)
    back = read_image(tmp_path / "mask.tif")
    assert back.dtype == np.uint8
    np.testing.assert_array_equal(back, values)
    assert [p.name for p in tmp_path.iterdir()] == ["mask.tif"]  # no temporary file left


# --- the Pillow row decoder for wide pixels ---------------------------------------------------


@pytest.mark.parametrize("bpp", [5, 9, 12])
def test_pixels_wider_than_eight_bytes_are_unfiltered_group_by_group(bpp: int) -> None:
    """Three groups of bytes (4 + 4 + 1 for 9 bytes, 4 + 4 + 4 for 12) each land in their own
    columns; every filter type appears."""
    rng = np.random.default_rng(bpp)
    raw = rng.integers(0, 256, (5, 2 * bpp), dtype=np.uint8)
    kinds = [0, 1, 2, 3, 4]
    filtered = filter_rows(raw, kinds, bpp)
    assert not np.array_equal(filtered, raw)
    out = unfilter_with_pillow(np.array(kinds, np.uint8), filtered, bpp)
    assert out.dtype == np.uint8
    np.testing.assert_array_equal(out, raw)
