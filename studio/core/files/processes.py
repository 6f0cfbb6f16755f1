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


def _start_ticks(pid: int) -> int | None:
    """When process ``pid`` started, in clock ticks since boot (Linux), or None."""
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def process_tag() -> str:
    """This process's id, with its start time where the system tells it (``PID`` or
    ``PID-TICKS``), for names of files it may leave behind. Why: a file's own times say
    nothing about its maker when it is a hard link to an inode other saves link and unlink
    later, and ids are reused; id and start time together name one process."""
    ticks = _start_ticks(os.getpid())
    return str(os.getpid()) if ticks is None else f"{os.getpid()}-{ticks}"


def tag_alive(tag: str, since: float | None = None) -> bool | None:
    """Whether the process named by ``tag`` (from ``process_tag``) still runs; None when the tag
    is not one. A tag without a start time falls back to ``process_alive(pid, since)``."""
    pid_text, _, ticks_text = tag.partition("-")
    if not pid_text.isdigit() or (ticks_text and not ticks_text.isdigit()):
        return None
    pid = int(pid_text)
    if not ticks_text:
        return process_alive(pid, since)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        pass
    ticks = _start_ticks(pid)
    return True if ticks is None else ticks == int(ticks_text)
