"""Whether another process that left a file behind is still running.

Why: a save, an autosave or a backup killed half-way leaves a file with its process id in the
name; the next one must remove it only if its maker is gone, and process ids are reused.
"""

from __future__ import annotations

import os
from pathlib import Path


def process_alive(pid: int, since: float | None = None) -> bool:
    """Whether process ``pid`` (the one that made a file at ``since``) still runs. Process ids
    are reused, and on Linux a thread's id answers ``kill`` too: there a live id counts only if
    it leads a process that started before the file was made."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, but someone else's
        return True
    if since is None or not os.path.exists("/proc/stat"):
        return True
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        tgid = next(int(line.split()[1]) for line in status.splitlines()
                    if line.startswith("Tgid:"))
        if tgid != pid:
            return False  # a thread of another process that got the same number
        boot = next(float(line.split()[1]) for line in Path("/proc/stat").read_text()
                    .splitlines() if line.startswith("btime"))
        ticks = float(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
        return boot + ticks / os.sysconf("SC_CLK_TCK") <= since + 1.0
    except (OSError, ValueError, IndexError, StopIteration):
        return True
