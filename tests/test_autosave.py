"""Autosave → crash → recovery, the .bak of a second save, and the undo memory budget."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtGui import QUndoCommand, QUndoStack

from studio.core.project_file import backup_path, load_project
from studio.widgets.autosave import INTERVAL_KEY, find_recoveries, recovery_dir
from studio.widgets.main_window import MainWindow, settings
from studio.widgets.undo_budget import DROPPED_PREFIX, install_undo_budget


def _open(qtbot, project) -> MainWindow:
    w = MainWindow(project)
    w.resize(1000, 700)
    w.show()
    qtbot.waitExposed(w)
    return w


def _close(w: MainWindow) -> None:
    w.doc.undo_stack.setClean()  # no "save changes?" prompt
    w.close()
    w.deleteLater()


@pytest.fixture
def fast_autosave():
    """Autosave every 50 ms for windows made in the test; no recovery files before or after."""
    for item in find_recoveries():
        item.remove()
    s = settings()
    s.setValue(INTERVAL_KEY, 50 / 60_000)
    yield
    s.remove(INTERVAL_KEY)
    for item in find_recoveries():
        item.remove()


def test_autosave_crash_then_recovery(qtbot, sample, dialogs, fast_autosave, tmp_path):
    first = _open(qtbot, sample)
    first.doc.set_pose_weight("frown", 0.6)
    first.doc.set_expression_factor(0.7)
    first.doc.project.influence.areas[0].activation = 0.25
    qtbot.waitUntil(lambda: first.autosaver.autosaves >= 1, timeout=10000)
    recovery = first.autosaver.project_file
    assert recovery.exists() and recovery.parent == recovery_dir()
    assert find_recoveries() == []  # a running window's file is not offered
    edited = first.doc.project

    first.autosaver.abandon()  # the crash: the window dies without cleaning up
    first.hide()
    assert [r.project_file for r in find_recoveries()] == [recovery]

    second = _open(qtbot, sample)  # the next start
    qtbot.waitUntil(lambda: bool(dialogs), timeout=5000)
    kind, text = dialogs[0]
    assert kind == "question"
    assert "Sample face" in text and "never saved" in text and "Autosaved:" in text
    doc = second.doc
    assert doc.modified and second.isWindowModified()
    assert doc.path is None  # the user chooses where to save it
    assert doc.pose_weights["frown"] == pytest.approx(0.6)
    assert doc.project.wdv.expression_factor == pytest.approx(0.7)
    assert doc.project.influence.areas[0].activation == pytest.approx(0.25)
    for name in ("rest", "triangles", "uvs", "weld"):
        assert np.array_equal(getattr(doc.project.mesh, name), getattr(edited.mesh, name))
    for a, b in zip(doc.project.influence.areas, edited.influence.areas, strict=True):
        assert a.name == b.name and np.abs(a.mask - b.mask).max() <= 1 / 65535
    for name in ("diffuse", "normal_neutral", "normal_wrinkled"):
        assert np.array_equal(getattr(doc.project.textures, name),
                              getattr(edited.textures, name))
    assert not recovery.exists() and find_recoveries() == []  # cleaned up

    # the recovered document is saved where the user wants; a second save keeps a .bak
    path = tmp_path / "face.wrinkle"
    assert second.save_to(path)
    assert not backup_path(path).exists()
    doc.set_pose_weight("frown", 0.9)
    assert second.save_to(path)
    assert load_project(backup_path(path)).view["pose_weights"]["frown"] == pytest.approx(0.6)
    assert load_project(path).view["pose_weights"]["frown"] == pytest.approx(0.9)
    _close(first)
    _close(second)


def test_clean_close_and_saving_remove_the_recovery_file(qtbot, sample, dialogs, fast_autosave,
                                                          tmp_path):
    w = _open(qtbot, sample)
    w.doc.set_pose_weight("frown", 0.3)
    qtbot.waitUntil(lambda: w.autosaver.autosaves >= 1, timeout=10000)
    recovery = w.autosaver.project_file
    assert recovery.exists()
    assert w.save_to(tmp_path / "a.wrinkle")  # saved: nothing left to recover
    assert not recovery.exists()
    w.doc.set_pose_weight("frown", 0.4)
    qtbot.waitUntil(recovery.exists, timeout=10000)
    _close(w)
    qtbot.waitUntil(lambda: not recovery.exists(), timeout=5000)
    assert not recovery.with_suffix(".lock").exists()
    assert find_recoveries() == [] and dialogs == []


def test_unmodified_document_is_not_autosaved(qtbot, sample, dialogs, fast_autosave):
    w = _open(qtbot, sample)
    qtbot.wait(300)
    assert w.autosaver.autosaves == 0 and not w.autosaver.project_file.exists()
    _close(w)


class _Stroke(QUndoCommand):
    """A stand-in for a paint stroke holding a before/after patch."""

    def __init__(self, size: int) -> None:
        super().__init__("Stroke")
        self.patch = np.ones(size, np.uint8)

    def nbytes(self) -> int:
        return self.patch.nbytes

    def redo(self) -> None:
        pass

    def undo(self) -> None:
        pass


def test_undo_budget_drops_the_oldest_steps(qtbot):
    stack = QUndoStack()
    budget = install_undo_budget(stack, budget=10 << 20)
    for _ in range(30):
        stack.push(_Stroke(1 << 20))
    assert budget.total_bytes() <= 10 << 20
    assert budget.dropped == 20
    assert stack.command(0).text().startswith(DROPPED_PREFIX)
    assert not stack.command(29).text().startswith(DROPPED_PREFIX)
    for _ in range(30):  # undo all the way: the dropped steps vanish, nothing breaks
        stack.undo()
    assert stack.count() == 10 and stack.index() == 0
    stack.redo()
    assert stack.index() == 1
