"""Tools ▸ Auto Setup from Poses says the time left while it works, and Cancel halfway leaves
the project as it was: no area, no link, no undo step, the same picture. Driven like a person:
the menu opened with a click and walked with the keys, Cancel clicked while the set-up runs."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QApplication, QProgressDialog, QPushButton

from tests.gui_helpers import viewport_image
from tests.test_auto_gui import as_imported, open_plain
from tests.test_files_gui import click_menu_path


def cancel_halfway(qtbot, window, seen: dict) -> QTimer:
    """A timer that, once the set-up's progress dialog is up and half done, notes what it
    says and clicks its Cancel button (the dialog runs the events while the work goes on)."""
    timer = QTimer(window)

    def look() -> None:
        dialog = QApplication.activeModalWidget()
        if (isinstance(dialog, QProgressDialog) and dialog.maximum() > 1
                and 2 * dialog.value() >= dialog.maximum()):
            timer.stop()
            seen.update(label=dialog.labelText(), at=(dialog.value(), dialog.maximum()))
            qtbot.mouseClick(dialog.findChild(QPushButton), Qt.MouseButton.LeftButton)

    timer.timeout.connect(look)
    timer.start(1)
    return timer


def settle_docks(qtbot, window, polls: int = 20) -> None:
    """Let the window's docks take their sizes (Qt lays them out once more some moments after
    the window first shows): until the viewport has kept its size for ``polls`` looks."""
    seen = [window.viewport.size()]

    def still() -> bool:
        seen.append(window.viewport.size())
        return len(seen) > polls and all(size == seen[-1] for size in seen[-polls:])

    qtbot.waitUntil(still, timeout=10_000)


def test_cancel_halfway_through_auto_setup_leaves_the_project_as_it_was(open_window, sample,
                                                                        qtbot, dialogs):
    window = open_plain(open_window, as_imported(sample))
    doc = window.doc
    doc.set_pose_weight("surprise", 1.0)  # wrinkles would show on the forehead once set up
    settle_docks(qtbot, window)
    before = viewport_image(window)
    steps = doc.undo_stack.count()
    seen: dict = {}
    timer = cancel_halfway(qtbot, window, seen)
    click_menu_path(qtbot, window, "Tools", "Auto Setup from Poses")
    timer.stop()
    assert seen, "the progress dialog was not up halfway through the set-up"
    done, total = seen["at"]
    assert 2 * done >= total and done < total  # cancelled halfway, not at the end
    assert seen["label"].splitlines()[-1].endswith(" left."), seen["label"]
    qtbot.waitUntil(lambda: QApplication.activeModalWidget() is None, timeout=5000)
    assert doc.project.influence.areas == [] and doc.project.wdv.areas == []
    assert doc.project.influence.links == {}
    assert doc.undo_stack.count() == steps and dialogs == []
    assert np.array_equal(viewport_image(window), before)
