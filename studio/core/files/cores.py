"""How many threads work that splits into independent pieces may use: the set-up's poses, the
project writer's images. Numpy, PIL and zlib let go of the interpreter while they work, so such
pieces run side by side on the cores this process is allowed (not all the machine's: a
container or ``taskset`` may give it fewer)."""

from __future__ import annotations

import os


def usable_cores(most: int) -> int:
    """The cores this process may run on, at least 1 and at most ``most``."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(cores, most))
