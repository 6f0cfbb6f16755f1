"""Hypothesis fuzzers over the glTF importer and the command-line options (the project file has
its own, tests/test_fuzz_project.py): whatever comes in, the answer is a result or a
StudioError / exit code 2 — never another exception. Fixed, small budgets keep them to a few
seconds each in CI (``WRINKLE_FUZZ_EXAMPLES`` scales them, as for the project fuzzer).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studio.cli import main
from studio.core.files.errors import StudioError
from studio.core.formats.gltf.codec import load_gltf
from tests.bad_inputs import gltf_doc, write_base, write_gltf

SCALE = int(os.environ.get("WRINKLE_FUZZ_EXAMPLES", "250")) / 250
FUZZ = settings(max_examples=max(int(200 * SCALE), 1), deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])

JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-2 ** 40, 2 ** 40) | st.sampled_from(
        [0, 1, 2, 3, 5126, 5125, 5121, 34962, -1, 2 ** 31, 1e308]) | st.floats(allow_nan=False)
    | st.sampled_from(["VEC3", "VEC2", "SCALAR", "MAT4", "", "../x.bin", "data:,", "2.0"]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                 max_size=4),
    max_leaves=8)


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, bytes]:
    folder = tmp_path_factory.mktemp("fuzz-gltf")
    write_base(folder)
    doc, binary = gltf_doc(folder)
    return folder, doc, binary


def _paths(node: object, prefix: tuple = ()) -> list[tuple]:
    """Every place in a JSON tree (dict keys and list indices), the root's children first."""
    out = []
    if isinstance(node, dict):
        items = list(node.items())
    elif isinstance(node, list):
        items = list(enumerate(node))
    else:
        return out
    for key, value in items:
        if key in ("images",):  # keep the fuzz on the mesh structure, not on image decoding
            continue
        out.append((*prefix, key))
        out += _paths(value, (*prefix, key))
    return out


@FUZZ
@given(data=st.data())
def test_gltf_importer_answers_a_project_or_a_studio_error(base, data) -> None:
    folder, doc, binary = base
    doc = json.loads(json.dumps(doc))
    places = _paths(doc)
    for _ in range(data.draw(st.integers(1, 3))):
        *parents, last = data.draw(st.sampled_from(places))
        node = doc
        try:
            for part in parents:
                node = node[part]
            if data.draw(st.booleans()) or not isinstance(node, dict):
                node[last] = data.draw(JSON_VALUES)
            else:
                del node[last]
        except (KeyError, IndexError, TypeError):
            continue
    suffix = data.draw(st.sampled_from([".glb", ".gltf"]))
    path = folder / f"case{suffix}"
    write_gltf(path, doc, binary)
    try:
        load_gltf(path)
    except StudioError as exc:
        assert str(path) in str(exc)


TOKENS = ["inf", "nan", "-1", "0", "1e-300", "1e308", "16384x16384", "0x0", "64x48", "0:10:0",
          "10:0", "0:2", "%999999999d", "%*d", "f%04d.png", "/dev/zero", "FIFO", "DIR", "MISSING",
          "P", "x" * 300, "", "=", "a=b", "t1", "heat", "displace", "-5"]
OPTIONS = {
    "render": ["--technique", "--pose", "--weight", "--size", "--vertices", "--view",
               "--relief", "--relief-depth", "--yaw", "--pitch", "--frames", "--blend"],
    "export": ["--bits"],
    "bake": ["--high", "--size", "--distance", "--map"],
    "new": ["--mesh", "--pose", "--diffuse", "--normal", "--wrinkle-normal", "--keep"],
    "sample": ["--vertices"],
}
# Where each command would write: always an existing folder, so a run that got this far stops
# at the output check instead of rendering or baking for seconds.
OUTPUT = {"render": ["-o", "DIR"], "export": ["--gltf", "DIR"], "bake": ["--png", "DIR"],
          "new": ["-o", "DIR"], "sample": ["-o", "DIR"]}


@pytest.fixture(scope="module")
def places(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    folder = tmp_path_factory.mktemp("fuzz-cli")
    write_base(folder)
    os.mkfifo(folder / "fifo")
    (folder / "dir").mkdir()
    return {"FIFO": str(folder / "fifo"), "DIR": str(folder / "dir"),
            "MISSING": str(folder / "missing.obj"), "P": str(folder / "p.wrinkle")}


@FUZZ
@given(command=st.sampled_from(sorted(OPTIONS)), data=st.data())
def test_command_line_answers_exit_0_or_2_never_a_traceback(places, command, data,
                                                            capsys) -> None:
    args = [command]
    if command in ("render", "export", "bake"):
        args.append(data.draw(st.sampled_from(TOKENS)))
    for _ in range(data.draw(st.integers(0, 4))):
        args += [data.draw(st.sampled_from(OPTIONS[command])),
                 data.draw(st.sampled_from(TOKENS))]
    args += OUTPUT[command]
    args = [places.get(a, a) for a in args]
    try:
        code = main(args)
    except SystemExit as exc:  # argparse: usage errors exit 2, -h exits 0
        code = exc.code
    assert code in (0, 2), args
    err = capsys.readouterr().err.strip().splitlines()
    if code == 2:
        assert len(err) == 1, (args, err)
