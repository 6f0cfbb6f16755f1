"""Work survives a kill (issue #34): a studio killed with SIGKILL ten seconds after an edit
offers that edit at the next start; killed again right after the recovery was accepted, the
start after offers it again; a studio that dies of a segmentation fault names its crash log.

Real processes (tests/crash_child.py), real kills, the shipped autosave settings. Seen red: with
autosave back on its three-minute timer only, nothing is offered after the first kill; with the
recovery file deleted on acceptance (as before), nothing is offered after the second.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


class Child:
    """A studio process whose printed lines the test reads as they come."""

    def __init__(self, mode: str, home: Path) -> None:
        env = dict(os.environ, XDG_CONFIG_HOME=str(home / "config"),
                   XDG_DATA_HOME=str(home / "data"), PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen([sys.executable, "-m", "tests.crash_child", mode], cwd=ROOT,
                                     env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.put(line.rstrip("\n"))

    def expect(self, word: str, timeout: float = 120) -> list[str]:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=0.2)
            except queue.Empty:
                if self.proc.poll() is not None and self.lines.empty():
                    break
                continue
            self.seen.append(line)
            if line.startswith(word + " ") or line == word:
                return line.split(" ", 2)[1:]
        raise AssertionError(f"no {word} from the studio; it said:\n" + "\n".join(self.seen))

    def kill(self) -> None:
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(30)

    def wait(self) -> int:
        return self.proc.wait(60)


def test_killed_twice_the_work_is_offered_twice(tmp_path):
    first = Child("edit", tmp_path)
    (edited,) = first.expect("EDITED")[:1]
    time.sleep(10)  # the figure: a kill -9 ten seconds after an edit loses nothing
    first.kill()

    second = Child("recover", tmp_path)
    count, offers = second.expect("RECOVERED")
    second.kill()  # right after accepting the offer
    assert count == edited, f"recovered {count} areas, the edit made {edited}"
    (offer,) = json.loads(offers)
    assert "stopped unexpectedly at" in offer and "is recovered" in offer

    third = Child("recover", tmp_path)
    count, offers = third.expect("RECOVERED")
    third.kill()
    assert count == edited and len(json.loads(offers)) == 1  # offered again, once


def test_a_segmentation_fault_leaves_a_crash_log_that_the_offer_names(tmp_path):
    first = Child("segv", tmp_path)
    first.expect("EDITED")
    assert first.wait() == -signal.SIGSEGV
    second = Child("recover", tmp_path)
    _count, offers = second.expect("RECOVERED")
    second.kill()
    (offer,) = json.loads(offers)
    log = Path(offer.split("Crash log: ", 1)[1].split("\n", 1)[0])
    assert log.is_file() and log.parent.name == "crash-logs"
    assert "Fatal Python error: Segmentation fault" in log.read_text()
