"""How long the GUI thread stops while the studio autosaves the bundled sample head.

    xvfb-run -a python scripts/autosave_pause.py [--saves 6]

A 1 ms timer on the GUI thread notes the longest gap between its ticks (a person feels a gap
of over ~50 ms as a hitch) while autosaves run: an edit (an undo step), then the autosave it
starts, written on the worker thread. Prints the snapshot's time on the GUI thread, the whole
write's time, and the longest gap during writes against the longest gap with the window idle.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--saves", type=int, default=6)
    args = parser.parse_args()
    import os

    os.environ["XDG_DATA_HOME"] = tempfile.mkdtemp(prefix="autosave-pause-")
    os.environ["XDG_CONFIG_HOME"] = tempfile.mkdtemp(prefix="autosave-pause-")
    from PySide6.QtCore import QElapsedTimer, QTimer
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QApplication

    from studio.app import configure_opengl

    configure_opengl()
    app = QApplication(sys.argv[:1])
    from studio.widgets.main_window import MainWindow

    window = MainWindow()
    window.resize(1440, 900)
    window.show()
    while window.viewport.frames_rendered == 0:
        QTest.qWait(20)
    QTest.qWait(2000)  # the panels' first checks settle
    clock = QElapsedTimer()
    clock.start()
    gaps: list[float] = []
    last = [clock.nsecsElapsed()]

    def tick() -> None:
        now = clock.nsecsElapsed()
        gaps.append((now - last[0]) / 1e6)
        last[0] = now

    ticker = QTimer()
    ticker.setInterval(1)
    ticker.timeout.connect(tick)
    ticker.start()
    QTest.qWait(3000)
    idle = max(gaps)
    saver = window.autosaver
    during: list[float] = []
    writes: list[float] = []
    snapshots: list[float] = []
    for i in range(args.saves):
        window.doc.set_area_activation(0, 0.1 * (i % 9 + 1))
        QTest.qWait(200)
        gaps.clear()
        last[0] = clock.nsecsElapsed()
        start = time.perf_counter()
        assert saver.autosave()
        snapshots.append((time.perf_counter() - start) * 1000)
        done = saver.autosaves + 1
        while saver.autosaves < done:
            QTest.qWait(1)
        writes.append((time.perf_counter() - start) * 1000)
        during.append(max(gaps))
    ticker.stop()
    print(f"autosave of the sample ({window.doc.project.mesh.n_vertices} vertices), "
          f"{args.saves} writes:")
    print(f"  snapshot on the GUI thread: median {statistics.median(snapshots):.1f} ms, "
          f"max {max(snapshots):.1f} ms")
    print(f"  write (worker thread): median {statistics.median(writes):.0f} ms")
    print(f"  longest GUI-thread gap while writing: median {statistics.median(during):.1f} ms, "
          f"max {max(during):.1f} ms (idle window: {idle:.1f} ms)")
    window.doc.undo_stack.setClean()
    window.close()
    app.processEvents()
    return 0


if __name__ == "__main__":
    sys.exit(main())
