"""The command line's progress: each stage of a set-up as it starts, and a bar of its steps with
the time left (``time_left``), on standard output before what was made is listed: standard
error keeps the one line a bad input gets.

On a terminal the bar is one line redrawn in place; into a file or a pipe (a log, a build
script), a line at each stage and at every tenth of the steps, so the log stays short."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

from studio.core.setup.time_left import TimeLeft

WIDTH = 30  # characters of the bar
# the set-up's stages (``stage_clock``), as the command line says them
WORDS = {"reading": "reading the files", "face finding": "finding the face",
         "orientation": "finding the face's up and front", "strain": "measuring the skin's strain",
         "synthesis": "synthesising wrinkled normal maps", "masks": "drawing the masks",
         "vectors": "making the wrinkle vectors", "writing": "writing the project"}


class ProgressBar:
    """``stage(name)`` as each stage starts (a ``StageClock``'s ``heard``), ``step(done,
    total)`` as the work progresses (the set-up's ``progress``: it always goes on; Ctrl+C
    stops it), ``close()`` at the end."""

    def __init__(self, stream: TextIO | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.stream = stream if stream is not None else sys.stdout
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self._time = TimeLeft(clock)
        self._stage = ""
        self._tenth = -1
        self._drawn = False

    def stage(self, name: str) -> None:
        self._end_line()
        self._stage = name
        self.stream.write(f"{WORDS.get(name, name)} …\n")
        self.stream.flush()

    def step(self, done: int, total: int) -> bool:
        tenth = 10 * done // max(total, 1)
        if self.live or tenth != self._tenth:
            self._tenth = tenth
            filled = round(WIDTH * done / max(total, 1))
            left = self._time.words(done, total)
            line = (f"  [{'#' * filled}{'.' * (WIDTH - filled)}] {done}/{total}"
                    f"{'  ' + left if left else ''}")
            if self.live:
                self.stream.write(f"\r{line:<{WIDTH + 40}}")
                self._drawn = True
            else:
                self.stream.write(line + "\n")
            self.stream.flush()
        return True

    def close(self) -> None:
        self._end_line()

    def _end_line(self) -> None:
        if self._drawn:
            self.stream.write("\n")
            self._drawn = False
