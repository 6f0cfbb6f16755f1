"""Words for the formats the studio does not read (issue 49, point 6): ``new --mesh`` on a
Blender, Alembic, Collada or Maya file, or any unknown suffix, says in one line (exit code 2)
what the studio reads and, for a tool's own file, which export gives one it reads; a head file
(FBX, VRM, USD) given as a key pose says it is read whole."""

from __future__ import annotations

import io
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

from studio.cli import main

READS = "the studio reads OBJ, PLY, STL, OFF, glTF/GLB, VRM, FBX and USD"


def one_line_error(args: list[str]) -> str:
    """What ``wrinkle-studio ARGS`` prints: exit code 2 and one line, no traceback."""
    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()):
        assert main(args) == 2
    lines = err.getvalue().strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


@pytest.mark.parametrize("name, export", [
    ("head.blend", "from Blender use File > Export > glTF 2.0 or USD"),
    ("head.abc", "an Alembic cache holds no blend shapes: export the head from the tool that "
                 "made it as glTF, FBX or USD (Blender: File > Export > glTF 2.0 or USD)"),
    ("head.dae", "open it in Blender (File > Import > Collada) and use File > Export > glTF 2.0"),
    ("head.ma", "from Maya use File > Export All as FBX or USD"),
    ("head.MB", "from Maya use File > Export All as FBX or USD"),
    ("head.x3d", None),
])
def test_a_file_the_studio_does_not_read_names_what_it_reads_and_the_export(tmp_path: Path,
                                                                           name: str, export):
    path = tmp_path / name
    path.write_bytes(b"BLENDER-v405" + bytes(64))  # any bytes: the suffix decides
    line = one_line_error(["new", "--mesh", str(path), "-o", str(tmp_path / "x.wrinkle")])
    said = f"{path}: unknown mesh format '{path.suffix}': {READS}"
    assert line == f"wrinkle-studio: error: {said}" + (f"; {export}" if export else "")


@pytest.mark.parametrize("suffix", [".usdz", ".fbx", ".vrm"])
def test_a_head_file_given_as_a_key_pose_says_it_is_read_whole(tmp_path: Path, suffix: str):
    neutral = tmp_path / "neutral.obj"
    neutral.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    pose = tmp_path / f"smile{suffix}"
    pose.write_bytes(b"PK\x03\x04" + bytes(60))
    line = one_line_error(["new", "--mesh", str(neutral), "--pose", f"smile={pose}",
                           "-o", str(tmp_path / "x.wrinkle")])
    assert line == (f"wrinkle-studio: error: {pose}: a {suffix} file is read as a whole head, "
                    "its blend shapes the key poses (as the neutral mesh of a new project); "
                    "here use OBJ, PLY, STL, OFF, GLTF, GLB")
