"""Where a set-up spends its time and memory, stage by stage (reading, face finding,
orientation, strain, synthesis, masks, vectors, writing): what ``wrinkle-studio bench --setup``
tables, so every change to the set-up is judged by its figures.

The set-up's code marks its stages with ``with stage("masks"):``; that costs nothing unless a
``StageClock`` is running (``with clock.running():``), which then adds each stage's wall time,
the process's CPU time (all threads: a stage may run poses on several) and the peak resident
memory while it ran. Stages may nest: the inner one's time is its own, not the outer's. The
peak is the kernel's high-water mark (``VmHWM``), reset as each stage starts
(``/proc/self/clear_refs``), so a stage's peak is its own, not an earlier one's; where the
kernel offers neither, the peak is the process's largest so far (``ru_maxrss``)."""

from __future__ import annotations

import resource
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path

_CLEAR_REFS = Path("/proc/self/clear_refs")
_STATUS = Path("/proc/self/status")


@dataclass
class StageFigures:
    """One stage's totals over every time it ran."""

    wall_s: float = 0.0
    cpu_s: float = 0.0
    peak_mb: float = 0.0


def peak_mb() -> float:
    """The process's peak resident memory since the last reset, in MB (10⁶ bytes)."""
    try:
        for line in _STATUS.read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024 / 1e6
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e6


def reset_peak() -> None:
    """Start a new high-water mark at the current resident memory (Linux), where allowed."""
    with suppress(OSError):
        _CLEAR_REFS.write_text("5")


class StageClock:
    """Each stage's wall time, CPU time and peak memory (``figures``, in the order first run);
    ``heard``, if given, hears each stage's name as it first starts (the command line's
    progress)."""

    def __init__(self, heard: Callable[[str], None] | None = None) -> None:
        self.heard = heard
        self.figures: dict[str, StageFigures] = {}
        self._stack: list[str] = []
        self._wall = self._cpu = 0.0

    @contextmanager
    def running(self) -> Iterator[StageClock]:
        """Make this the clock that ``stage`` reports to, in this thread, while the block runs."""
        token = _current.set(self)
        try:
            yield self
        finally:
            _current.reset(token)

    def _switch(self) -> None:
        """Charge the time and peak since the last switch to the stage running then."""
        wall, cpu = time.perf_counter(), time.process_time()
        if self._stack:
            figures = self.figures[self._stack[-1]]
            figures.wall_s += wall - self._wall
            figures.cpu_s += cpu - self._cpu
            figures.peak_mb = max(figures.peak_mb, peak_mb())
        reset_peak()
        self._wall, self._cpu = time.perf_counter(), time.process_time()

    def enter(self, name: str) -> None:
        self._switch()
        if name not in self.figures and self.heard is not None:
            self.heard(name)
        self.figures.setdefault(name, StageFigures())
        self._stack.append(name)

    def leave(self) -> None:
        self._switch()
        self._stack.pop()


_current: ContextVar[StageClock | None] = ContextVar("stage_clock", default=None)


@contextmanager
def stage(name: str) -> Iterator[None]:
    """Count the block as stage ``name`` on the running clock, if any."""
    clock = _current.get()
    if clock is None:
        yield
        return
    clock.enter(name)
    try:
        yield
    finally:
        clock.leave()
