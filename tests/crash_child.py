"""A studio process for the crash tests (tests/test_crash_recovery.py): started, edited with a
real click, and killed by the test.

    python -m tests.crash_child edit      open the test face, click Areas ▸ Add, say EDITED n
    python -m tests.crash_child recover   open it again, answer Yes to the recovery offer and
                                          say RECOVERED n followed by the offer's text
    python -m tests.crash_child segv      as edit, then die of a segmentation fault once the
                                          edit is autosaved

It starts as the studio's own entry does (app name, crash log), on the small test face so that
a start takes seconds; autosave runs with its shipped settings.
"""

from __future__ import annotations

import faulthandler
import json
import sys

from PySide6.QtCore import Qt, QTimer
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QMessageBox, QPushButton


def _say(*parts: object) -> None:
    print(*parts, flush=True)


def main(mode: str) -> int:
    from studio.app import configure_opengl

    configure_opengl()
    app = QApplication(sys.argv[:1])
    app.setApplicationName("Wrinkle Studio")
    app.setOrganizationName("WrinkleStudio")
    from studio.core.sample.synthetic import make_test_face
    from studio.widgets.crash_log import enable_crash_log
    from studio.widgets.main_window import MainWindow

    enable_crash_log()
    offers: list[str] = []

    def question(parent, title, text, *args, **kwargs):
        offers.append(text)
        return QMessageBox.StandardButton.Yes

    QMessageBox.question = staticmethod(question)
    window = MainWindow(make_test_face())
    window.resize(1200, 800)
    window.show()
    window.activateWindow()
    while window.viewport.frames_rendered == 0:
        QTest.qWait(20)
    QTest.qWait(300)  # the recovery offer is queued after the first show
    areas = window.doc.project.influence.areas
    if mode == "recover":
        _say("RECOVERED", len(areas), json.dumps(offers))
    else:
        dock = window.docks["Areas"]
        dock.show()
        dock.raise_()
        add = next(b for b in dock.findChildren(QPushButton) if b.text() == "Add")
        QTest.mouseClick(add, Qt.MouseButton.LeftButton)
        QTest.qWait(50)
        _say("EDITED", len(window.doc.project.influence.areas))
        if mode == "segv":
            def crash_once_saved() -> None:
                if window.autosaver.autosaves:
                    faulthandler._sigsegv()
            timer = QTimer(window)
            timer.timeout.connect(crash_once_saved)
            timer.start(100)
    return app.exec()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
