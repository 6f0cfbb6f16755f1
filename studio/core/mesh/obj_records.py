"""An OBJ file's lines sorted by what they hold, before any number is read.

Reading a head with its key poses means reading dozens of OBJ files of a few MB each; a Python
loop over their lines took most of a set-up (16 s for the ICT head's 54 files). ``sort_records``
does the sorting with numpy over the file's bytes: tokens are found by their edges, the lines
by their first token, and the ``v``, ``vt`` and ``f`` tokens are cut out in bulk. Only the few
lines that name parts (``o``, ``g``, ``usemtl``, ``mtllib``) or hold bytes beyond ASCII are
looked at one by one.

``records_by_line`` is the plain reading, line by line: it is what a file is read by whenever
the bulk reading meets something it does not handle the same way (a short line, a line break
other than LF or CR LF, a Unicode space that may start a ``v`` line), so that every message
names the line as it always did. The bulk reading gives exactly the records the plain one
would; tests/test_obj_records_core.py holds them side by side.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.errors import MeshError

Array = np.ndarray

# The three ways an OBJ names parts of a mesh, and the name of faces that come before any.
KINDS = ("object", "group", "material")
UNNAMED = {"object": "(no object)", "group": "default", "material": "(no material)"}
KEYWORD = {"o": "object", "g": "group", "usemtl": "material"}

# Bytes str.splitlines or str.split treat as a line break or a space that the bulk reading
# does not (it splits lines at LF only and words at space, tab and CR): such a file is read
# line by line: VT, FF, FS, GS, RS, US (_ODD), and NEL, LS and PS, Unicode line breaks in UTF-8.
_UNUSUAL = ("\x85".encode(), "\u2028".encode(), "\u2029".encode())
_SOLID, _SPACE, _ODD = 0, 1, 2  # the class of each byte: a token's, a space, one of those
_CLASS = np.zeros(256, np.uint8)
_CLASS[[ord(c) for c in " \t\r\n"]] = _SPACE
_CLASS[[0x0B, 0x0C, 0x1C, 0x1D, 0x1E, 0x1F]] = _ODD


@dataclass
class Records:
    """The numbers of an OBJ as text, sorted by kind, with where each came from.

    ``v``/``vt``/``corners`` hold their tokens with one space between: 3 per ``v`` line (the
    first three; a fourth ``w`` or vertex colours are ignored), 2 per ``vt``, and every face
    corner as written (``7``, ``7/3``, ``7/3/1``, ``7//1``).
    """

    v: str
    v_line: Array  # (N,) line of each ``v``, from 1
    vt: str
    vt_line: Array  # (M,)
    corners: str
    sizes: Array  # (P,) corners per face
    f_line: Array  # (P,)
    f_nv: Array  # (P,) ``v`` lines before the face: the base of its negative indices
    f_nvt: Array  # (P,) ``vt`` lines before the face
    # kind -> (faces before the line, name) at every ``o``/``g``/``usemtl`` line
    changes: dict[str, list[tuple[int, str]]]
    libraries: list[str]  # ``mtllib`` lines, as written


def sort_records(path: Path | str, raw: bytes) -> Records:
    """The file's records: in bulk when it can be, else line by line (which also raises the
    MeshError naming a line that is wrong)."""
    records = _records_in_bulk(raw)
    if records is None:
        records = records_by_line(path, raw.decode("utf-8", errors="replace"))
    return records


def records_by_line(path: Path | str, text: str) -> Records:
    """Sort the lines one by one; a line too short for its kind is a MeshError naming it."""
    v: list[str] = []
    v_line: list[int] = []
    vt: list[str] = []
    vt_line: list[int] = []
    corners: list[str] = []
    sizes: list[int] = []
    f_line: list[int] = []
    f_nv: list[int] = []
    f_nvt: list[int] = []
    changes: dict[str, list[tuple[int, str]]] = {kind: [] for kind in KINDS}
    libraries: list[str] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        key = parts[0]
        if key == "v":
            if len(parts) < 4:
                raise MeshError(f"line {lineno}: a vertex needs three coordinates", path)
            v.extend(parts[1:4])
            v_line.append(lineno)
        elif key == "vt":
            if len(parts) < 3:
                raise MeshError(
                    f"line {lineno}: a texture coordinate needs two numbers (u v)", path
                )
            vt.extend(parts[1:3])
            vt_line.append(lineno)
        elif key == "f":
            if len(parts) < 4:
                raise MeshError(
                    f"line {lineno}: face {len(sizes) + 1} has {len(parts) - 1} "
                    "vertices; a face needs at least 3",
                    path,
                )
            corners.extend(parts[1:])
            sizes.append(len(parts) - 1)
            f_line.append(lineno)
            f_nv.append(len(v_line))
            f_nvt.append(len(vt_line))
        else:
            _name_line(line, parts, len(sizes), changes, libraries)
    return Records(" ".join(v), _ints(v_line), " ".join(vt), _ints(vt_line), " ".join(corners),
                   _ints(sizes), _ints(f_line), _ints(f_nv), _ints(f_nvt), changes, libraries)


def _name_line(line: str, parts: list[str], faces_before: int,
               changes: dict[str, list[tuple[int, str]]], libraries: list[str]) -> None:
    """Record an ``mtllib``, ``o``, ``g`` or ``usemtl`` line; any other line is ignored."""
    key = parts[0]
    if key == "mtllib":
        libraries.append(line.strip()[len(key):].strip())
    elif key in KEYWORD:
        kind = KEYWORD[key]
        changes[kind].append((faces_before, " ".join(parts[1:]) or UNNAMED[kind]))


def _ints(values: list[int]) -> Array:
    return np.asarray(values, dtype=np.intp)


def _records_in_bulk(raw: bytes) -> Records | None:
    """The records found with numpy over the bytes, or None where the file holds something
    read differently line by line (or wrong, which the line-by-line reading names)."""
    buf = np.frombuffer(raw + b"\n", np.uint8)  # every line ends with LF
    byte_class = _CLASS[buf]
    if (byte_class == _ODD).any():
        return None
    cr = np.flatnonzero(buf == 13)
    if (buf[cr + 1] != 10).any():  # a CR alone breaks a line too
        return None
    high = np.flatnonzero(buf >= 128)
    if len(high) and any(seq in raw for seq in _UNUSUAL):
        return None
    solid = byte_class == _SOLID
    edge = np.diff(solid.view(np.int8), prepend=np.int8(0))
    starts = np.flatnonzero(edge == 1)  # of each token
    ends = np.flatnonzero(edge == -1)  # the space after each token (the last byte is LF)
    breaks = np.flatnonzero(buf == 10)
    token_line = np.searchsorted(breaks, starts)  # from 0
    first = np.flatnonzero(np.diff(token_line, prepend=-1))  # each line's first token
    line = token_line[first]  # the lines holding any token
    count = np.diff(first, append=len(starts))  # tokens on each line
    key_at = starts[first]
    key_len = ends[first] - key_at
    c0, c1 = buf[key_at], buf[key_at + 1]
    # a line holding a byte beyond ASCII is read as text: its spaces may be Unicode's
    wide = np.isin(line, np.searchsorted(breaks, high))
    one = (key_len == 1) & ~wide
    is_v = one & (c0 == ord("v"))
    is_f = one & (c0 == ord("f"))
    is_vt = (key_len == 2) & (c0 == ord("v")) & (c1 == ord("t")) & ~wide
    if ((count < 4) & (is_v | is_f)).any() or ((count < 3) & is_vt).any():
        return None
    by_text = wide | (one & np.isin(c0, list(b"og"))) | (
        (key_len == 6) & np.isin(c0, list(b"um")))
    faces_before = np.cumsum(is_f) - is_f
    changes: dict[str, list[tuple[int, str]]] = {kind: [] for kind in KINDS}
    libraries: list[str] = []
    for i in np.flatnonzero(by_text):
        start = breaks[line[i] - 1] + 1 if line[i] else 0
        text = raw[start:breaks[line[i]]].decode("utf-8", errors="replace")
        parts = text.split()
        if parts and parts[0] in ("v", "vt", "f"):
            return None
        if parts:
            _name_line(text, parts, int(faces_before[i]), changes, libraries)
    f_first = first[is_f]
    return Records(
        v=_joined(buf, starts, ends, first[is_v], 1, 3),
        v_line=line[is_v] + 1,
        vt=_joined(buf, starts, ends, first[is_vt], 1, 2),
        vt_line=line[is_vt] + 1,
        corners=_joined(buf, starts, ends, f_first, 1, count[is_f] - 1),
        sizes=count[is_f] - 1,
        f_line=line[is_f] + 1,
        f_nv=np.cumsum(is_v)[is_f],
        f_nvt=np.cumsum(is_vt)[is_f],
        changes=changes,
        libraries=libraries,
    )


def _joined(buf: Array, starts: Array, ends: Array, lines_first: Array, skip: int,
            take: int | Array) -> str:
    """Tokens ``skip`` to ``skip + take`` of each line (``lines_first``: its first token),
    one space between: their bytes gathered in one go."""
    take = np.broadcast_to(take, lines_first.shape)
    which = np.repeat(lines_first + skip - _offsets(take), take) + np.arange(int(take.sum()))
    lengths = ends[which] - starts[which] + 1  # each token and the space after it
    at = np.repeat(starts[which] - _offsets(lengths), lengths) + np.arange(int(lengths.sum()))
    out = buf[at]
    out[np.cumsum(lengths) - 1] = ord(" ")
    return out[:-1].tobytes().decode("ascii")


def _offsets(counts: Array) -> Array:
    """Where each run of ``counts`` starts in their concatenation."""
    return np.cumsum(counts) - counts
