"""Saving killed at random moments: the file on disk is always the old or the new version.

A child process saves the same project over and over (a new name each time, announced on stdout
after each save returns) and is killed with SIGKILL after a random delay — mid-write, mid-fsync,
mid-rename or between saves. After every kill the file must load, and hold the last announced
version or the one after it (a save that completed but was not announced yet). Temporary files a
killed save leaves behind are removed by the next save.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from studio.core.project.reader import load_project
from studio.core.project.writer import backup_path, save_project
from studio.core.sample.synthetic import make_test_face

KILLS = int(os.environ.get("WRINKLE_SAVE_KILLS", "30"))
ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import sys
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
path, run = sys.argv[1], sys.argv[2]
project = load_project(path)
print("ready", flush=True)
for i in range(1_000_000):
    project.name = f"{run}-{i}"
    save_project(project, path)
    print(i, flush=True)
"""

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="needs SIGKILL (POSIX)")


def _temps(folder: Path, name: str) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(f".{name}."))


def test_killed_saves_never_leave_a_broken_file(tmp_path: Path) -> None:
    path = tmp_path / "face.wrinkle"
    project = make_test_face(561, texture_size=64, mask_size=32)
    project.name = "start"
    save_project(project, path)
    rng = random.Random(561)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get(
        "PYTHONPATH", "")])}
    on_disk = "start"
    most_temps = 0
    mid_save = 0
    for run in range(KILLS):
        child = subprocess.Popen([sys.executable, "-c", CHILD, str(path), str(run)],
                                 stdout=subprocess.PIPE, text=True, env=env, cwd=ROOT)
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.0, 0.25))
        child.send_signal(signal.SIGKILL)
        lines = child.stdout.read().split()
        child.wait()
        child.stdout.close()
        assert child.returncode == -signal.SIGKILL
        done = [int(x) for x in lines]
        allowed = ({on_disk, f"{run}-0"} if not done
                   else {f"{run}-{done[-1]}", f"{run}-{done[-1] + 1}"})
        loaded = load_project(path)  # never broken: raises if it were
        assert loaded.name in allowed, (run, loaded.name, allowed)
        on_disk = loaded.name
        if backup_path(path).exists():
            load_project(backup_path(path))  # the backup is a whole file too
        temps = _temps(tmp_path, path.name)
        most_temps = max(most_temps, len(temps))
        mid_save += bool(temps)
        assert len(temps) <= 2  # this kill's temp file and backup link; earlier ones swept
    save_project(project, path)
    assert _temps(tmp_path, path.name) == []
    print(f"\n{KILLS} saves killed ({mid_save} mid-write), 0 broken files, "
          f"at most {most_temps} leftover files between saves, none after the next save")
