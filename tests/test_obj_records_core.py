"""The OBJ reader's bulk sorting of lines (core/mesh/obj_records.py) against a reading written
the plain way, line by line, here in the test: a hand-made file with every form an exporter
writes (comments, blank lines, tabs, CR LF, ``v`` with ``w`` or colours, ``vt`` with ``w``,
``vn``, ``o``/``g``/``usemtl``/``mtllib``, triangles, quads and n-gons, the ``v``, ``v/vt``,
``v/vt/vn`` and ``v//vn`` corners, negative indices, a part name beyond ASCII).

Why: the bulk sorting is what makes a head with 50 expressions load in seconds, and it is
numpy over bytes, where an off-by-one loses a vertex or moves a face to the wrong line without
any error. Every position, UV, corner, line number and part name must be what the plain
reading finds; files it hands to the line-by-line reading (other line breaks, Unicode spaces)
must come out the same too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.mesh.meshio import _parse_obj
from studio.core.mesh.obj_records import _records_in_bulk, records_by_line, sort_records

pytestmark = pytest.mark.core

# millimetres, Z up, far from the origin; UVs on the UDIM tile 1002
EVERY_FORM = (
    "# exported by hand\r\n"
    "mtllib  head skin.mtl \r\n"
    "o Head\r\n"
    "v 250.5 -40.25 1600 1.0\r\n"
    "v 251.5\t-40.25 1600 0.8 0.2 0.1\r\n"
    "\tv 251.5 -39.25 1600.125  \r\n"
    "v 250.5 -39.25 1601\r\n"
    "v 252 -40 1.5e3\r\n"
    "\r\n"
    "vt 1.25 0.5\r\n"
    "vt 1.75 0.5 0\r\n"
    "vt 1.75 0.75\r\n"
    "vt 1.25 0.75\r\n"
    "vn 0 -1 0\r\n"
    "g left cheek\r\n"
    "usemtl skin\r\n"
    "s 1\r\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\r\n"  # a quad, v/vt/vn
    "f -5/-4 -4/-3 -1/-2\r\n"  # relative v/vt
    "g café\r\n"  # beyond ASCII: read as text
    "usemtl\r\n"  # unnamed
    "f 1//1 3//1 5//1\r\n"  # v//vn: no texture index
    "v 253 -41 1599\r\n"
    "f 1 2 5 6 3\r\n"  # a pentagon, plain v
    "o\r\n"
    "f\t-6/1 -5/2\t-4/3\r\n"
)


def _plain_reading(text: str) -> dict[str, object]:
    """What the file holds, read the plain way: 0-based resolved indices, -1 for no UV."""
    v: list[list[float]] = []
    vt: list[list[float]] = []
    faces: list[tuple[int, list[int], list[int]]] = []  # line, v, vt
    names = {"o": "(no object)", "g": "default", "usemtl": "(no material)"}
    per_face: dict[str, list[str]] = {key: [] for key in names}
    libraries: list[str] = []
    for number, line in enumerate(text.splitlines(), 1):
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            v.append([float(x) for x in words[1:4]])
        elif words[0] == "vt":
            vt.append([float(x) for x in words[1:3]])
        elif words[0] in names:
            names[words[0]] = " ".join(words[1:]) or {
                "o": "(no object)", "g": "default", "usemtl": "(no material)"}[words[0]]
        elif words[0] == "mtllib":
            libraries.append(line.strip()[len("mtllib"):].strip())
        elif words[0] == "f":
            corners = [w.split("/") for w in words[1:]]
            vs = [int(c[0]) - 1 if int(c[0]) > 0 else len(v) + int(c[0]) for c in corners]
            vts = [-1 if len(c) < 2 or not c[1] else
                   int(c[1]) - 1 if int(c[1]) > 0 else len(vt) + int(c[1]) for c in corners]
            faces.append((number, vs, vts))
            for key, name in names.items():
                per_face[key].append(name)
    return {"positions": np.array(v), "uvs": np.array(vt), "faces": faces,
            "per_face": per_face, "libraries": libraries}


def _as_read(path: Path, raw: bytes) -> dict[str, object]:
    data = _parse_obj(path, raw)
    starts = np.cumsum(data.sizes) - data.sizes
    faces = [(int(line), data.corner_v[s:s + n].tolist(),
              [-1 if t < 0 else int(t) for t in data.corner_vt[s:s + n]])
             for line, s, n in zip(data.face_lines, starts, data.sizes, strict=True)]
    kinds = {"o": "object", "g": "group", "usemtl": "material"}
    unnamed = (["(unnamed)"], np.zeros(len(data.sizes), int))  # a kind the file never names
    per_face = {key: [names[i] for i in ids] for key, kind in kinds.items()
                for names, ids in [data.labels.get(kind, unnamed)]}
    return {"positions": data.positions, "uvs": data.uvs, "faces": faces,
            "per_face": per_face, "libraries": data.libraries}


def _same(found: dict[str, object], expected: dict[str, object]) -> None:
    np.testing.assert_array_equal(found["positions"], expected["positions"])
    np.testing.assert_array_equal(found["uvs"], expected["uvs"])
    assert found["faces"] == expected["faces"]
    for key, names in expected["per_face"].items():
        if found["per_face"][key] != ["(unnamed)"] * len(names):
            assert found["per_face"][key] == names
    assert found["libraries"] == expected["libraries"]


def test_every_form_is_read_as_the_plain_reading_reads_it(tmp_path: Path) -> None:
    raw = EVERY_FORM.encode("utf-8")
    assert _records_in_bulk(raw) is not None  # the bulk sorting, not its fallback, read it
    expected = _plain_reading(EVERY_FORM)
    _same(_as_read(tmp_path / "head.obj", raw), expected)
    # spot checks that the plain reading itself reads what the file says
    assert expected["faces"][1] == (19, [0, 1, 4], [0, 1, 2])  # -5 of 5 v is the first
    assert expected["per_face"]["g"] == ["left cheek", "left cheek", "café", "café", "café"]
    assert expected["libraries"] == ["head skin.mtl"]


@pytest.mark.parametrize(
    "variant",
    [
        pytest.param(lambda t: t.replace("\r\n", "\n"), id="LF"),
        pytest.param(lambda t: t.replace("\r\n", "\r"), id="CR alone"),
        pytest.param(lambda t: t.replace("\r\n", "\n").replace("\ns 1", "\fs 1"), id="form feed"),
        pytest.param(lambda t: t.replace("\tv 251.5", "\u00a0v 251.5"), id="a no-break space"),
        pytest.param(lambda t: t.replace("g left", "g\u2028left"), id="a Unicode line break"),
    ],
)
def test_line_breaks_and_spaces_read_line_by_line_give_the_same(tmp_path: Path, variant) -> None:
    """Whatever path a file takes, its records are those of the line-by-line reading, and
    what is read matches the plain reading."""
    text = variant(EVERY_FORM)
    raw = text.encode("utf-8")
    path = tmp_path / "head.obj"
    found, by_line = sort_records(path, raw), records_by_line(path, text)
    for name, value in vars(by_line).items():
        other = getattr(found, name)
        assert np.array_equal(other, value) if isinstance(value, np.ndarray) else other == value
    _same(_as_read(path, raw), _plain_reading(text))


def _uniform(form: str) -> str:
    """A strip of quads and triangles, every corner written alike (``form`` of v, t, n), with
    relative indices on its last faces and numbers of several digits."""
    rows = [f"v {250 + i % 11}.{i:03d} -{40 + i // 11}.5 {1600 + i}" for i in range(132)]
    rows += [f"vt {1 + (i % 11) / 10} {i // 11 / 12}" for i in range(132)]
    rows.append("vn 0 -1 0")
    for i in range(120):
        if i % 11 == 10:
            continue
        a, b, c, d = i + 1, i + 2, i + 13, i + 12
        quad = i % 3 != 0
        ids = (a, b, c, d) if quad else (a, b, c)
        if i > 100:  # relative: counted back from the 264 records before
            ids = tuple(x - 133 for x in ids)
        rows.append("f " + " ".join(form.format(v=x, t=x, n=1 if x > 0 else -1) for x in ids))
    return "\n".join(rows) + "\n"


@pytest.mark.parametrize("form", ["{v}", "{v}/{t}", "{v}/{t}/{n}"])
def test_corners_written_alike_read_in_one_pass_match_the_plain_reading(
    tmp_path: Path, form: str
) -> None:
    text = _uniform(form)
    _same(_as_read(tmp_path / "strip.obj", text.encode()), _plain_reading(text))
