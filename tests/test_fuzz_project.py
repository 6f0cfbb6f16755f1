"""Property-based fuzzing of the project loader: hostile or damaged files never crash it.

Each property takes a valid saved project, mutates it (raw bytes, or the archive's members and
headers) and loads the result: either a valid Project comes back or ProjectError is raised —
any other exception fails the test. ``WRINKLE_FUZZ_EXAMPLES`` scales the number of examples
per property (default 250; the figures in docs/reliability.md used more).
"""

from __future__ import annotations

import io
import json
import os
import struct
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studio.core.files.errors import ProjectError
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.project.schema import check_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face

pytestmark = pytest.mark.core

EXAMPLES = int(os.environ.get("WRINKLE_FUZZ_EXAMPLES", "250"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=False,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
TRIED: dict[str, int] = {}  # property -> examples run (printed at the end with -s)


@pytest.fixture(scope="module")
def valid(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    project = make_test_face(561, texture_size=64, mask_size=32)
    path = tmp_path_factory.mktemp("fuzz") / "valid.wrinkle"
    save_project(project, path)
    return path.read_bytes()


@pytest.fixture(scope="module")
def scratch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz-cases") / "case.wrinkle"


@pytest.fixture(scope="module", autouse=True)
def report():
    yield
    print(f"\nfuzz cases tried: {sum(TRIED.values())} {TRIED}")


def _members(data: bytes) -> list[tuple[zipfile.ZipInfo, bytes]]:
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        return [(info, archive.read(info)) for info in archive.infolist()]


def _zip(members: list[tuple[zipfile.ZipInfo | str, bytes]]) -> bytes:
    buffer = io.BytesIO()
    with warnings.catch_warnings(), zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        warnings.simplefilter("ignore")  # duplicate names are one of the mutations
        for info, payload in members:
            archive.writestr(info, payload)
    return buffer.getvalue()


def _load_checked(path: Path, data: bytes, kind: str) -> None:
    """The property: a valid Project, or ProjectError naming the file — nothing else."""
    TRIED[kind] = TRIED.get(kind, 0) + 1
    path.write_bytes(data)
    try:
        project = load_project(path)
    except ProjectError as exc:
        assert exc.path == path and exc.problem
        return
    assert isinstance(project, Project)
    check_project(project, path)  # what loaded is consistent enough to be saved again
    assert project.mesh.triangles.max() < project.mesh.n_vertices
    assert all(np.isfinite(p.positions).all() for p in project.poses)


@FUZZ
@given(data=st.data())
def test_truncation(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    cut = data.draw(st.integers(0, len(valid) - 1))
    _load_checked(scratch, valid[:cut], "truncation")


@FUZZ
@given(data=st.data())
def test_bit_flips(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    damaged = bytearray(valid)
    for _ in range(data.draw(st.integers(1, 8))):
        at = data.draw(st.integers(0, len(damaged) - 1))
        damaged[at] ^= 1 << data.draw(st.integers(0, 7))
    _load_checked(scratch, bytes(damaged), "bit flips")


@FUZZ
@given(data=st.data())
def test_byte_runs_overwritten(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    """Whole runs of junk or of 0xFF (huge sizes and offsets in the zip's own headers)."""
    damaged = bytearray(valid)
    at = data.draw(st.integers(0, len(damaged) - 1))
    run = data.draw(st.binary(min_size=1, max_size=16) | st.just(b"\xff" * 8))
    damaged[at:at + len(run)] = run
    _load_checked(scratch, bytes(damaged), "byte runs")


@FUZZ
@given(data=st.data())
def test_huge_declared_sizes(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    """The central directory claims a member is enormous (a zip bomb's signature)."""
    damaged = bytearray(valid)
    offsets = [i for i in range(len(damaged) - 46) if damaged[i:i + 4] == b"PK\x01\x02"]
    at = data.draw(st.sampled_from(offsets))
    size = data.draw(st.sampled_from([0xFFFFFFFF, 0x7FFFFFFF, 1 << 31, 1 << 30, 0]))
    field = data.draw(st.sampled_from([20, 24]))  # compressed / uncompressed size
    struct.pack_into("<I", damaged, at + field, size)
    _load_checked(scratch, bytes(damaged), "huge sizes")


_HOSTILE_NAMES = ["../evil.npy", "/etc/passwd", "..\\evil", "mesh/../../x.npy", "C:/x.npy",
                  "mesh//rest.npy", "mesh/rest.npy/", "", "mesh/rest.npy\x00.png"]


@FUZZ
@given(data=st.data())
def test_member_names(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    """Traversal, absolute and odd names, duplicates and symlink members."""
    members = _members(valid)
    i = data.draw(st.integers(0, len(members) - 1))
    info, payload = members[i]
    action = data.draw(st.sampled_from(["rename", "duplicate", "symlink", "extra"]))
    if action == "rename":
        name = data.draw(st.sampled_from(_HOSTILE_NAMES) | st.text(min_size=1, max_size=30))
        members[i] = (zipfile.ZipInfo(name or "x", date_time=info.date_time), payload)
    elif action == "duplicate":
        members.append((zipfile.ZipInfo(info.filename, date_time=info.date_time), payload))
    elif action == "symlink":
        link = zipfile.ZipInfo(info.filename, date_time=info.date_time)
        link.external_attr = (0o120777 << 16)
        members[i] = (link, b"/etc/passwd")
    else:
        name = data.draw(st.sampled_from(_HOSTILE_NAMES))
        members.append((zipfile.ZipInfo(name or "y", date_time=info.date_time), b"junk"))
    _load_checked(scratch, _zip(members), f"names: {action}")


@FUZZ
@given(data=st.data())
def test_swapped_members(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    members = _members(valid)
    i, j = data.draw(st.lists(st.integers(0, len(members) - 1), min_size=2, max_size=2,
                              unique=True))
    (a, pa), (b, pb) = members[i], members[j]
    members[i], members[j] = (a, pb), (b, pa)
    _load_checked(scratch, _zip(members), "swapped members")


def _npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    return buffer.getvalue()


_DTYPES = [np.float32, np.float64, np.int32, np.int64, np.uint8, np.float16, np.bool_, "<U3",
           ">f4", ">i4", np.complex64]


@FUZZ
@given(data=st.data())
def test_wrong_arrays(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    """An array member replaced by one of the wrong shape, dtype or values (NaN, huge indices)."""
    members = _members(valid)
    arrays = [k for k, (info, _) in enumerate(members) if info.filename.endswith(".npy")]
    k = data.draw(st.sampled_from(arrays))
    info, payload = members[k]
    original = np.load(io.BytesIO(payload), allow_pickle=False)
    kind = data.draw(st.sampled_from(["shape", "dtype", "values", "pickle", "header"]))
    if kind == "shape":
        dims = st.integers(0, 8) | st.sampled_from([1, 2, 3, 4, 560, 561, 562, 700])
        shape = tuple(data.draw(st.lists(dims, min_size=0, max_size=3)))
        if np.prod(shape) > 1_000_000:  # the big cases are the declared-size ones below
            shape = (*shape[:-1], 3)
        replacement = _npy(np.zeros(shape, original.dtype))
    elif kind == "dtype":
        replacement = _npy(original.astype(data.draw(st.sampled_from(_DTYPES))))
    elif kind == "values":
        changed = original.copy()
        flat = changed.reshape(-1)
        at = data.draw(st.integers(0, flat.size - 1))
        if changed.dtype.kind == "f":
            flat[at] = data.draw(st.sampled_from([np.nan, np.inf, -np.inf, 1e38, -1e38]))
        else:
            flat[at] = data.draw(st.sampled_from([-1, 2**31 - 1, 10**6, -(2**31)]))
        replacement = _npy(changed)
    elif kind == "pickle":
        buffer = io.BytesIO()
        np.save(buffer, np.array([{"a": 1}], dtype=object), allow_pickle=True)
        replacement = buffer.getvalue()
    else:  # a header that declares a huge shape over the real bytes
        header = b"{'descr': '<f4', 'fortran_order': False, 'shape': (100000000000, 3), }"
        header += b" " * (118 - len(header)) + b"\n"
        replacement = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + b"\0" * 64
    members[k] = (info, replacement)
    _load_checked(scratch, _zip(members), f"arrays: {kind}")


_JUNK = st.recursive(
    st.none() | st.booleans() | st.integers(-2**40, 2**40) | st.floats(allow_nan=False)
    | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner,
                                                                max_size=3),
    max_leaves=6)


def _paths(value: object, prefix: tuple = ()) -> list[tuple]:
    found = [prefix] if prefix else []
    if isinstance(value, dict):
        for key, inner in value.items():
            found += _paths(inner, (*prefix, key))
    elif isinstance(value, list):
        for i, inner in enumerate(value):
            found += _paths(inner, (*prefix, i))
    return found


@FUZZ
@given(data=st.data())
def test_project_json_fields(valid: bytes, scratch: Path, data: st.DataObject) -> None:
    """A field of project.json replaced by junk, a huge count or a traversal member name."""
    members = _members(valid)
    k = next(i for i, (info, _) in enumerate(members) if info.filename == "project.json")
    doc = json.loads(members[k][1])
    where = data.draw(st.sampled_from(_paths(doc)))
    value = data.draw(_JUNK | st.sampled_from(
        [10**9, 2**31, -1, 0, "../../etc/passwd", "/abs/mask.png", "masks/../project.json",
         "poses/00.npy", 1e308]))
    target = doc
    for key in where[:-1]:
        target = target[key]
    if isinstance(target, dict | list):
        target[where[-1]] = value
    members[k] = (members[k][0], json.dumps(doc).encode())
    _load_checked(scratch, _zip(members), "project.json fields")


def test_the_valid_file_loads(valid: bytes, scratch: Path) -> None:
    _load_checked(scratch, valid, "valid")
