"""A small hostile project cannot make the loader allocate what its members inflate to (issue #30).

A zip member of zeros deflates about a thousand to one, so a 600 kB file can hold a 600 MB
``.npy`` member. The loader reads each member's header first (a ``.npy`` header's dtype and
shape, a PNG's IHDR), checks it against what project.json expects and against the member's
declared size, and only then inflates it: a member that claims the wrong shape, or more bytes
than its header needs, is refused having cost a few hundred bytes.

The first test is the reported file, measured as the peak resident memory of a process that
loads it; the others run every kind of member in-process and measure with tracemalloc (numpy
and Python allocations both), with bombs of 64 MiB so that they stay quick.
"""

from __future__ import annotations

import io
import json
import os
import struct
import subprocess
import sys
import tracemalloc
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest

from studio.core.files.errors import ProjectError
from studio.core.files.png import HEADER_BYTES
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face

ROOT = Path(__file__).resolve().parents[1]
PIECE = 1 << 20
BOMB = 64 << 20  # bytes of zeros behind each in-process case's header
MAX_EXTRA_RSS_MB = 100  # the bound: hostile load's peak over a valid load's

# A child that loads argv[1] and prints the message (or "loaded") and its own peak RSS in KiB
# (VmHWM: ru_maxrss would carry the forking pytest's peak across exec).
CHILD = ("import sys\n"
         "from studio.core.files.errors import ProjectError\n"
         "from studio.core.project.reader import load_project\n"
         "try:\n"
         "    load_project(sys.argv[1])\n"
         "    print('loaded')\n"
         "except ProjectError as exc:\n"
         "    print(exc)\n"
         "with open('/proc/self/status') as status:\n"
         "    print(int(status.read().split('VmHWM:')[1].split()[0]))\n")


def npy_header(shape: tuple[int, ...], descr: str = "<f4", version: int = 1) -> bytes:
    stream = io.BytesIO()
    header = {"descr": descr, "fortran_order": False, "shape": shape}
    write = (np.lib.format.write_array_header_1_0 if version == 1
             else np.lib.format.write_array_header_2_0)
    write(stream, header)
    return stream.getvalue()


def zero_pieces(count: int):
    """``count`` zero bytes in pieces (the test never holds a bomb)."""
    zeros = bytes(PIECE)
    for start in range(0, count, PIECE):
        yield zeros[:min(PIECE, count - start)]


def bomb_project(source: Path, target: Path, member: str, head: bytes, zeros: int,
                 tail: bytes = b"") -> None:
    """A copy of ``source`` whose ``member`` is ``head``, ``zeros`` zero bytes and ``tail``,
    deflated as it is written."""
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for info in zin.infolist():
            if info.filename == member:
                continue
            zout.writestr(info.filename, zin.read(info), zipfile.ZIP_DEFLATED)
        info = zipfile.ZipInfo(member)
        info.compress_type = zipfile.ZIP_DEFLATED
        with zout.open(info, "w", force_zip64=True) as out:
            out.write(head)
            for piece in zero_pieces(zeros):
                out.write(piece)
            out.write(tail)


def png_bomb(png: bytes, zeros: int) -> tuple[bytes, bytes]:
    """(head, tail) of the PNG ``png`` with an ancillary chunk of ``zeros`` zero bytes after
    its IHDR: a valid image that a container could pad to any size."""
    kind = b"fiLl"  # ancillary, private, safe to copy: every decoder skips it
    crc = zlib.crc32(kind)
    for piece in zero_pieces(zeros):
        crc = zlib.crc32(piece, crc)
    return (png[:HEADER_BYTES] + struct.pack(">I", zeros) + kind,
            struct.pack(">I", crc) + png[HEADER_BYTES:])


def child_load(path: Path) -> tuple[str, int]:
    """(the load's outcome, the loading process's peak RSS in KiB)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-W", "error", "-c", CHILD, str(path)], env=env,
                          capture_output=True, text=True, timeout=120, check=True)
    outcome, peak = done.stdout.strip().splitlines()[-2:]
    return outcome, int(peak)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="peak RSS read from /proc")
def test_a_600_mb_npy_member_in_a_600_kb_file_is_refused_in_bounded_memory(tmp_path: Path
                                                                           ) -> None:
    """The reported file: rest.npy inflates to 600 MB of zeros behind a header claiming shape
    (50000000, 3). It is refused with the reported message, and the process that refused it
    peaked under 100 MB above one that loaded the valid project (before: 1.2 GB)."""
    valid, hostile = tmp_path / "valid.wrinkle", tmp_path / "hostile.wrinkle"
    save_project(make_test_face(1600, texture_size=64, mask_size=32), valid, backup=False)
    shape = (50_000_000, 3)
    bomb_project(valid, hostile, "mesh/rest.npy", npy_header(shape), 600_000_000)
    assert hostile.stat().st_size < 1 << 20

    outcome, valid_peak = child_load(valid)
    assert outcome == "loaded"
    outcome, hostile_peak = child_load(hostile)
    assert outcome == (f"{hostile}: 'mesh/rest.npy' (the mesh's rest) has shape (50000000, 3), "
                       "expected (1600, 3)")
    assert hostile_peak < valid_peak + MAX_EXTRA_RSS_MB * 1024, \
        f"peak {hostile_peak // 1024} MB, a valid load {valid_peak // 1024} MB"


# Every kind of .npy member: (member, dtype, columns). Each bomb's header claims BOMB bytes of
# the member's own dtype and columns, so only the row count is wrong.
NPY_MEMBERS = [
    ("mesh/rest.npy", "<f4", 3),
    ("mesh/triangles.npy", "<i4", 3),
    ("mesh/uvs.npy", "<f4", 2),
    ("mesh/weld.npy", "<i4", 1),
    ("poses/00.npy", "<f4", 3),
    ("wdv/00_directions.npy", "<f4", 3),
    ("wdv/00_lengths.npy", "<f4", 1),
    ("wdv/00_cones.npy", "<f4", 1),
    ("mesh/not_face.npy", "|b1", 1),
    ("mesh/vertex_tile.npy", "<i2", 1),
]
PNG_MEMBERS = ["textures/diffuse.png", "textures/wrinkled_01.png", "masks/00_forehead_right.png"]


def optional_members(project) -> dict[str, np.ndarray]:
    """Not-face flags, UV tiles and painted cones for the sample (it has none of its own)."""
    n, v = project.mesh.n_welded, project.mesh.n_vertices
    return {"mesh/not_face.npy": np.arange(n) % 7 == 0,
            "mesh/vertex_tile.npy": np.zeros(v, np.int16),
            "wdv/00_cones.npy": np.full(n, 12.5, np.float32)}


@pytest.fixture(scope="module")
def full(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A valid project with every kind of member: the sample's, and the optional ones added
    (project.json naming them as the writer would)."""
    folder = tmp_path_factory.mktemp("bomb")
    project = make_test_face(561, texture_size=64, mask_size=32)
    save_project(project, folder / "sample.wrinkle", backup=False)
    path = folder / "full.wrinkle"
    with zipfile.ZipFile(folder / "sample.wrinkle") as zin, zipfile.ZipFile(path, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info)
            if info.filename == "project.json":
                doc = json.loads(data)
                doc["not_face"] = "mesh/not_face.npy"
                doc["uv_tiles"] = {"tiles": [1001], "cells": [[0, 0, 1]],
                                   "vertex_tile": "mesh/vertex_tile.npy"}
                doc["wdv"]["areas"][0]["cones"] = "wdv/00_cones.npy"
                data = json.dumps(doc).encode()
            zout.writestr(info.filename, data, zipfile.ZIP_DEFLATED)
        for name, array in optional_members(project).items():
            stream = io.BytesIO()
            np.save(stream, array)
            zout.writestr(name, stream.getvalue(), zipfile.ZIP_DEFLATED)
    return path


def peak_of_load(path: Path) -> tuple[str, int]:
    """(the ProjectError's text, the peak bytes Python and numpy allocated meanwhile)."""
    tracemalloc.start()
    try:
        with pytest.raises(ProjectError) as refused:
            load_project(path)
        return str(refused.value), tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.core
@pytest.mark.parametrize(("member", "descr", "columns"), NPY_MEMBERS,
                         ids=[m for m, *_ in NPY_MEMBERS])
def test_every_npy_member_claiming_a_huge_shape_is_refused_before_inflating(
        full: Path, tmp_path: Path, member: str, descr: str, columns: int) -> None:
    """Each .npy member (mesh, poses, WDV arrays, not-face flags, UV tiles) goes through the
    header-first read: its 64 MiB bomb is refused for its shape having allocated far less."""
    itemsize = np.dtype(descr).itemsize
    rows = BOMB // (itemsize * columns)
    shape = (rows, columns) if columns > 1 else (rows,)
    hostile = tmp_path / "hostile.wrinkle"
    bomb_project(full, hostile, member, npy_header(shape, descr), BOMB)
    message, peak = peak_of_load(hostile)
    assert f"'{member}'" in message and f"has shape {shape}, expected (" in message, message
    assert peak < BOMB // 8, f"{peak >> 20} MiB allocated"


@pytest.mark.core
@pytest.mark.parametrize(("head", "tail", "problem"), [
    (npy_header((561, 3)), b"", "is truncated or has extra bytes"),  # trailing zeros
    (b"\x93NUMPY\x02\x00" + struct.pack("<I", 1 << 31), b"", "its header claims 2147483648"),
], ids=["trailing bytes", "4 GiB header"])
def test_a_right_header_with_a_huge_tail_or_a_huge_header_is_refused_before_inflating(
        full: Path, tmp_path: Path, head: bytes, tail: bytes, problem: str) -> None:
    """The shape is right but 64 MiB of zeros follow the data, or a version-2 header claims
    2 GiB of header text (numpy's own reader would read it all before checking its length)."""
    hostile = tmp_path / "hostile.wrinkle"
    bomb_project(full, hostile, "mesh/rest.npy", head, BOMB, tail)
    message, peak = peak_of_load(hostile)
    assert "'mesh/rest.npy'" in message and problem in message, message
    assert peak < BOMB // 8, f"{peak >> 20} MiB allocated"


@pytest.mark.core
@pytest.mark.parametrize("member", PNG_MEMBERS)
def test_a_png_member_padded_beyond_what_its_pixels_need_is_refused_before_inflating(
        full: Path, tmp_path: Path, member: str) -> None:
    """A texture or mask with a 64 MiB ancillary chunk of zeros (a valid PNG: decoders skip
    the chunk) is larger than any PNG of its pixels can be, and refused from its IHDR."""
    with zipfile.ZipFile(full) as archive:
        png = archive.read(member)
    head, tail = png_bomb(png, BOMB)
    hostile = tmp_path / "hostile.wrinkle"
    bomb_project(full, hostile, member, head, BOMB, tail)
    message, peak = peak_of_load(hostile)
    assert f"'{member}'" in message and "more than a PNG of its" in message, message
    assert peak < BOMB // 8, f"{peak >> 20} MiB allocated"


@pytest.mark.core
def test_the_project_with_every_kind_of_member_loads(full: Path) -> None:
    """The project the bombs are made from loads, optional members included: each refusal
    below is its bomb's."""
    loaded = load_project(full)
    expected = optional_members(make_test_face(561, texture_size=64, mask_size=32))
    np.testing.assert_array_equal(loaded.not_face, expected["mesh/not_face.npy"])
    np.testing.assert_array_equal(loaded.uv_tiles.vertex_tile, expected["mesh/vertex_tile.npy"])
    np.testing.assert_array_equal(loaded.wdv.areas[0].cone_angles_deg, 12.5)


@pytest.mark.core
@pytest.mark.parametrize(("setting", "limit", "problem"), [
    ("WRINKLE_STUDIO_MAX_MESH_VERTICES", 560,
     "project.json: mesh.welded_vertices is 561 vertices, more than the limit of 560 vertices"),
    ("WRINKLE_STUDIO_MAX_MESH_TRIANGLES", 1000,
     "project.json: mesh.triangles is 1,118 triangles, more than the limit of 1,000 triangles"),
    ("WRINKLE_STUDIO_MAX_POSES", 4,
     "project.json: the pose count is 5 key poses, more than the limit of 4 key poses"),
], ids=["vertices", "triangles", "poses"])
def test_project_json_counts_are_held_to_the_mesh_budgets_before_any_array_is_read(
        full: Path, monkeypatch: pytest.MonkeyPatch, setting: str, limit: int,
        problem: str) -> None:
    """A file whose arrays agree with project.json can still be huge: its declared counts
    meet the same budgets as an imported mesh's, naming the setting that raises them."""
    monkeypatch.setenv(setting, str(limit))
    with pytest.raises(ProjectError) as refused:
        load_project(full)
    assert problem in str(refused.value) and setting in str(refused.value), refused.value
