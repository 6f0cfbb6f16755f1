"""The time a piece of work still needs, from how fast its steps went so far: what the command
line's progress bar and the GUI's progress dialogs say beside the bar ("about 12 s left"),
both from this one estimate."""

from __future__ import annotations

import time
from collections.abc import Callable


class TimeLeft:
    """Seconds left, as the time per step since the first step was reported times the steps
    still to do. Timed from the first report, not from the start: what comes before the steps
    (reading, finding the face's frame) would make every step look slower than it is."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._first: tuple[int, float] | None = None

    def seconds(self, done: int, total: int) -> float | None:
        """Seconds left after ``done`` of ``total`` steps; None until a step has been timed."""
        now = self._clock()
        if self._first is None or done < self._first[0]:  # the first report (or a new run)
            self._first = (done, now)
            return None
        steps = done - self._first[0]
        if steps <= 0:
            return None
        return (now - self._first[1]) / steps * max(total - done, 0)

    def words(self, done: int, total: int) -> str:
        """"about 12 s left", "about 3 min left"; "" until a step has been timed."""
        left = self.seconds(done, total)
        if left is None:
            return ""
        if left < 1.0:
            return "less than a second left"
        if left < 90.0:
            return f"about {round(left)} s left"
        return f"about {round(left / 60.0)} min left"
