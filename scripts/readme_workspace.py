"""The README's pictures of the workspace at 1440 × 900, and a real-event run of the first task
a person meets: paint a frown area, link it to browDown_L, see it.

    xvfb-run -a -s "-screen 0 1600x1000x24" python scripts/readme_workspace.py

Writes docs/images/layout_default.png, layout_paint.png and timeline.png, and prints each
gesture of the task (clicks, key presses and drags, as tests/gui_monkey.py delivers them) with
the count and the scripted run's time.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "docs" / "images"


def main() -> int:
    os.environ.setdefault("XDG_CONFIG_HOME", tempfile.mkdtemp(prefix="readme-"))
    os.environ.setdefault("XDG_DATA_HOME", tempfile.mkdtemp(prefix="readme-"))
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QApplication

    from studio.app import configure_opengl

    configure_opengl()
    app = QApplication(sys.argv[:1])
    app.setApplicationName("Wrinkle Studio")
    app.setOrganizationName("WrinkleStudio")
    from studio.widgets.getting_started import SEEN_KEY
    from studio.widgets.main_window import MainWindow, settings
    from tests.gui_monkey import _button, click, type_then

    settings().setValue(SEEN_KEY, True)
    window = MainWindow()
    window.resize(1440, 900)
    window.show()
    while window.viewport.frames_rendered == 0:
        QTest.qWait(20)
    QTest.qWait(1500)
    OUT.mkdir(parents=True, exist_ok=True)
    window.grab().save(str(OUT / "layout_default.png"))
    window.docks["Timeline"].grab().save(str(OUT / "timeline.png"))

    # the task, gesture by gesture
    steps: list[str] = []

    def step(what: str) -> None:
        steps.append(what)
        print(f"{len(steps):2d}. {what}", flush=True)

    start = time.perf_counter()
    paint = next(a for a in window.menus["View"].actions() if "Paint Layout" in a.text()
                 .replace("&", ""))
    paint.trigger()
    step("View ▸ Paint Layout")
    QTest.qWait(300)
    panel = window.mask_tools.panel
    click(_button(window.pose_panel, "Back to neutral"))
    step("Poses ▸ Back to neutral")
    window.docks["Areas"].raise_()
    click(_button(panel, "Add"))
    step("Areas ▸ Add")
    type_then("browDown_L", Qt.Key.Key_Return)(panel.add_pose)
    step("Add pose… ▸ type “browDown_L”, Return")
    canvas = window.mask_tools.canvas
    view = canvas.view
    import numpy as np

    # where the sample's own frown area is: the stroke goes across its middle
    frown = next(a for a in window.doc.project.influence.areas if a.name == "browDown_L")
    ys, xs = np.nonzero(frown.mask > 0.5 * frown.mask.max())
    cx, cy, half = float(xs.mean()), float(ys.mean()), float(xs.max() - xs.min()) / 2
    points = [view.mapFromScene(cx - half + 2 * half * i / 12, cy) for i in range(13)]
    surface = view.viewport()
    QTest.mousePress(surface, Qt.MouseButton.LeftButton, pos=points[0])
    for p in points[1:]:
        QTest.mouseMove(surface, p)
        QTest.qWait(15)
    window.grab().save(str(OUT / "layout_paint.png"))
    QTest.mouseRelease(surface, Qt.MouseButton.LeftButton, pos=points[-1])
    step("UV Paint ▸ drag between the brows")
    window.docks["Poses"].raise_()
    QTest.qWait(100)
    slider = window.pose_panel.pose_rows["browDown_L"].slider
    click(slider)
    QTest.keyClick(slider, Qt.Key.Key_End)
    step("Poses ▸ browDown_L slider: click, End")
    # (no Shading ▸ technique 1: linking the area showed technique 1 already, issue #47)
    assert window.doc.view.technique == "t1", window.doc.view.technique
    QTest.qWait(500)
    seconds = time.perf_counter() - start
    print(f"{len(steps)} gestures, {seconds:.1f} s scripted")
    window.doc.undo_stack.setClean()
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
