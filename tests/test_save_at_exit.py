"""A project saved while the interpreter shuts down is still written whole.

The studio keeps the set-up sample in the user's cache on a thread that outlives a window
closed at once (studio/widgets/sample_cache.py), and an autosave may be finishing its write as
the studio quits. Python's exit first stops every thread pool from starting threads, then waits
for such threads: a save that compressed its images on a pool then failed ("cannot schedule new
futures after interpreter shutdown") and left no file. Run in a child process, as the exit is."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.core

CHILD = textwrap.dedent("""
    import sys, threading
    from studio.core.project import reader, writer
    from studio.core.sample.synthetic import make_test_face

    project = make_test_face(561, texture_size=64, mask_size=32)
    out = sys.argv[1]
    main_done = threading.Event()

    def keep() -> None:
        main_done.wait()
        # past the main thread's end: Python's exit has run its thread-pool hook by now, and
        # waits for this (non-daemon) thread
        threading.main_thread().join()
        writer.save_project(project, out, backup=False)

    threading.Thread(target=keep, name="keeper").start()
    main_done.set()
""")


def test_a_thread_saving_as_python_exits_writes_the_whole_project(tmp_path: Path) -> None:
    out = tmp_path / "kept.wrinkle"
    done = subprocess.run([sys.executable, "-c", CHILD, str(out)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    from studio.core.project import reader

    back = reader.load_project(out)
    assert len(back.poses) > 0 and back.influence.areas
