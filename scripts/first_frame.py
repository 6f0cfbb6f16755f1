"""Launch to first frame: the wall time from starting the interpreter to the viewport's first
frame on the bundled sample, through the studio's own start-up steps (``studio.app.run``'s:
OpenGL set up, the crash log armed, the window made and shown, the sample read from the user's
cache), under its own Xvfb and in fresh user folders.

    python scripts/first_frame.py [RUNS]

The first run sets the sample up and keeps it in the (fresh) cache, as a first start does;
the later runs are what a user meets on every start after that.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHILD = r"""
import sys, time
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication
from studio.app import configure_opengl
from studio.widgets.crash_log import enable_crash_log
from studio.widgets.main_window import MainWindow
configure_opengl()
app = QApplication(sys.argv[:1])
app.setApplicationName("Wrinkle Studio")
app.setOrganizationName("WrinkleStudio")
enable_crash_log()
window = MainWindow()
window.show()
while window.viewport.frames_rendered == 0:
    QTest.qWait(2)
print(time.time(), flush=True)
QTest.qWait(8000 if sys.argv[1:] == ["first"] else 0)  # the cache is written meanwhile
window.doc.undo_stack.setClean()
window.close()
"""


def main(runs: int) -> None:
    display = ":97"
    xvfb = subprocess.Popen(["Xvfb", display, "-screen", "0", "1600x1000x24"],
                            stderr=subprocess.DEVNULL)
    time.sleep(1.5)
    try:
        with tempfile.TemporaryDirectory() as home:
            env = dict(os.environ, DISPLAY=display, PYTHONPATH=str(ROOT),
                       **{f"XDG_{k}_HOME": str(Path(home) / k.lower())
                          for k in ("CACHE", "DATA", "CONFIG")})
            for run in range(runs):
                began = time.time()
                done = subprocess.run([sys.executable, "-c", CHILD, "first" if run == 0 else ""],
                                      env=env, cwd=ROOT, capture_output=True, text=True,
                                      check=True)
                shown = float(done.stdout.split()[0])
                what = "first start (sets the sample up)" if run == 0 else "a later start"
                print(f"{what}: first frame {shown - began:.2f} s after launch")
    finally:
        xvfb.kill()


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
