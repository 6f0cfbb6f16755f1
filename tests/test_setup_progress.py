"""``new --auto`` says how far it got: each stage as it starts, a bar of the set-up's steps
with the time left; and Ctrl+C halfway leaves nothing half-made (no project file, no temporary
file, one line saying so). The head is one in production conventions (millimetres, Z up, its
eyes and teeth separate objects, ARKit pose names), written as the OBJ files a user brings."""

from __future__ import annotations

import io
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from studio.cli import main
from studio.commands.progress_bar import ProgressBar
from studio.core.setup.time_left import TimeLeft
from tests.production_head import build_head

pytestmark = pytest.mark.core

ROOT = Path(__file__).resolve().parents[1]
BAR = re.compile(r"\[([#.]+)\] (\d+)/(\d+)")


def head_files(folder: Path) -> list[str]:
    """``new`` arguments for the production head's neutral OBJ and its key poses."""
    files = build_head("mm").write_set(folder)
    args = ["new", "--mesh", str(files.pop("neutral"))]
    for name, path in files.items():
        args += ["--pose", f"{name}={path}"]
    return args


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_the_time_left_is_the_pace_of_the_steps_since_the_first():
    clock = Clock()
    left = TimeLeft(clock)
    clock.now += 30.0  # reading and finding the face before the first step: not a step's pace
    assert left.words(1, 10) == ""
    clock.now += 4.0
    assert left.seconds(3, 10) == pytest.approx(14.0)  # 2 s a step, 7 steps to go
    assert left.words(3, 10) == "about 14 s left"
    clock.now += 200.0
    assert left.words(4, 10) == "about 7 min left"  # 68 s a step, 6 to go
    assert left.words(10, 10) == "less than a second left"


def test_the_bar_redraws_in_place_on_a_terminal():
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    clock, out = Clock(), Terminal()
    bar = ProgressBar(out, clock)
    bar.stage("synthesis")
    for done in range(1, 5):
        clock.now += 2.0
        assert bar.step(done, 4)
    bar.close()
    text = out.getvalue()
    assert text.startswith("synthesising wrinkled normal maps …\n")
    assert text.count("\r") == 4 and text.endswith("\n")
    assert "[" + "#" * 15 + "." * 15 + "] 2/4  about 4 s left" in text


def test_new_auto_says_its_stages_and_a_bar_with_the_time_left(tmp_path, capsys):
    out = tmp_path / "head.wrinkle"
    assert main([*head_files(tmp_path / "obj"), "--auto", "-o", str(out)]) == 0
    printed = capsys.readouterr()
    lines = printed.out.splitlines()
    stages = [line for line in lines if line.endswith(" …")]
    assert stages[:2] == ["reading the files …", "finding the face …"]
    assert {"synthesising wrinkled normal maps …", "drawing the masks …",
            "making the wrinkle vectors …"} <= set(stages)
    assert stages[-1] == "writing the project …"
    bars = [BAR.search(line) for line in lines if BAR.search(line)]
    assert bars and bars[-1].group(2) == bars[-1].group(3)  # it ends full
    assert all(len(b.group(1)) == len(bars[0].group(1)) for b in bars)
    assert any(line.endswith("s left") for line in lines)
    # the progress comes before what was made; standard error stays empty for a good run
    assert lines.index(next(x for x in lines if x.startswith("wrote "))) > lines.index(stages[-1])
    assert printed.err == "" and out.exists()


def test_ctrl_c_partway_through_the_set_up_writes_nothing(tmp_path):
    """Ctrl+C once a quarter of the set-up is done: nothing written. (A quarter, not half: this
    process reads the child's bar late on a loaded machine, and the child must still be working
    when the signal arrives.)"""
    args = [*head_files(tmp_path / "obj"), "--auto", "-o", str(tmp_path / "head.wrinkle")]
    before = sorted(p.name for p in tmp_path.rglob("*"))
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONUNBUFFERED="1")
    child = subprocess.Popen([sys.executable, "-m", "studio.cli", *args], cwd=tmp_path, env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seen = []
    for line in child.stdout:
        seen.append(line)
        bar = BAR.search(line)
        if bar and 4 * int(bar.group(2)) >= int(bar.group(3)):
            child.send_signal(signal.SIGINT)  # what Ctrl+C in the terminal does
            break
    rest, err = child.communicate(timeout=300)
    assert any(BAR.search(line) for line in seen), "".join(seen) + rest + err
    assert child.returncode == 130, err
    assert err.strip().splitlines() == [f"cancelled: {tmp_path / 'head.wrinkle'} not written"]
    assert "wrote" not in rest
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # no file, no temporary one
