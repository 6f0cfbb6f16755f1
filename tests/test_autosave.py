"""Autosave → crash → recovery, the .bak of a second save, autosaving on a worker thread, and
the undo memory budget."""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest
from PySide6.QtGui import QUndoCommand, QUndoStack

from studio.core.project import writer as project_writer
from studio.core.project.reader import load_project
from studio.core.project.writer import backup_path
from studio.core.wrinkles.brush import Brush
from studio.widgets.autosave import INTERVAL_KEY, find_recoveries, recovery_dir
from studio.widgets.main_window import MainWindow, settings
from studio.widgets.paint.edits import PaintSession
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
    assert "stopped unexpectedly at" in text and "is recovered" in text
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
    # kept, and now the second window's own: a crash right after recovering loses nothing
    assert recovery.exists() and second.autosaver.project_file == recovery
    assert find_recoveries() == []  # (a running window's file is not offered)

    # the recovered document is saved where the user wants; a second save keeps a .bak
    path = tmp_path / "face.wrinkle"
    assert second.save_to(path)
    assert not recovery.exists() and find_recoveries() == []  # saved: nothing to recover
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
    w.doc.set_expression_factor(0.3)
    qtbot.waitUntil(lambda: w.autosaver.autosaves >= 1, timeout=10000)
    recovery = w.autosaver.project_file
    assert recovery.exists()
    assert w.save_to(tmp_path / "a.wrinkle")  # saved: nothing left to recover
    assert not recovery.exists()
    w.doc.set_expression_factor(0.4)
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


class _HeldWriter:
    """Replaces save_project: a write on a thread other than the GUI thread waits until the
    test lets it go, so that the test can edit the document while an autosave is writing."""

    def __init__(self) -> None:
        self.started = threading.Event()
        self.release = threading.Event()
        self.threads: list[threading.Thread] = []
        self.real = project_writer.save_project

    def __call__(self, project, path, backup=True) -> None:
        if threading.current_thread() is not threading.main_thread():
            self.threads.append(threading.current_thread())
            self.started.set()
            self.release.wait(20)
        self.real(project, path, backup=backup)


@pytest.fixture
def held_writer(monkeypatch):
    writer = _HeldWriter()
    monkeypatch.setattr(project_writer, "save_project", writer)
    yield writer
    writer.release.set()


def _stroke(doc, index: int) -> None:
    """A brush stroke across the middle of an area's mask (written into the mask in place)."""
    h, w = doc.project.influence.areas[index].mask.shape
    session = PaintSession(doc, index, Brush(radius=w / 8))
    session.jump(w * 0.3, h * 0.5)
    session.to(w * 0.7, h * 0.5)
    assert session.end() is not None


def test_autosave_writes_a_snapshot_off_the_gui_thread(qtbot, sample, dialogs, fast_autosave,
                                                        held_writer):
    w = _open(qtbot, sample)
    doc = w.doc
    doc.set_pose_weight("frown", 0.6)  # view state, saved with the edit that follows
    doc.set_expression_factor(0.7)
    masks = [a.mask.copy() for a in doc.project.influence.areas]  # what the snapshot holds
    directions = doc.project.wdv.areas[0].directions.copy()
    qtbot.waitUntil(held_writer.started.is_set, timeout=10000)
    w.autosaver.timer.stop()  # this test looks at one autosave
    assert held_writer.threads[0] is not threading.main_thread()
    assert w.autosaver.writing and w.autosaver.autosaves == 0

    # the artist goes on while it writes: the GUI thread is free, and its edits change arrays
    # in place (the stroke writes into the mask, the WDV edit into the directions)
    _stroke(doc, 0)
    doc.project.wdv.areas[0].directions[:] = 0.0
    doc.set_pose_weight("frown", 0.9)
    doc.set_expression_factor(0.2)
    assert not np.array_equal(doc.project.influence.areas[0].mask, masks[0])

    held_writer.release.set()
    qtbot.waitUntil(lambda: w.autosaver.autosaves == 1, timeout=10000)
    assert not w.autosaver.writing
    recovered = load_project(w.autosaver.project_file)
    assert recovered.view["pose_weights"]["frown"] == pytest.approx(0.6)
    assert recovered.wdv.expression_factor == pytest.approx(0.7)
    for area, mask in zip(recovered.influence.areas, masks, strict=True):
        assert np.abs(area.mask - mask).max() <= 1 / 65535
    assert np.array_equal(recovered.wdv.areas[0].directions, directions)
    meta = json.loads(w.autosaver.project_file.with_suffix(".json").read_text("utf-8"))
    assert meta["name"] == "Sample face" and meta["original"] is None

    # the edits made during the write are autosaved next time
    w.autosaver.autosave()
    qtbot.waitUntil(lambda: w.autosaver.autosaves == 2, timeout=10000)
    recovered = load_project(w.autosaver.project_file)
    assert recovered.view["pose_weights"]["frown"] == pytest.approx(0.9)
    assert np.abs(recovered.influence.areas[0].mask
                  - doc.project.influence.areas[0].mask).max() <= 1 / 65535
    _close(w)


def test_saving_during_an_autosave_leaves_no_recovery_file(qtbot, sample, dialogs, fast_autosave,
                                                           held_writer, tmp_path):
    w = _open(qtbot, sample)
    w.doc.set_expression_factor(0.6)
    qtbot.waitUntil(held_writer.started.is_set, timeout=10000)
    assert w.save_to(tmp_path / "face.wrinkle")  # saved while the autosave still writes
    held_writer.release.set()
    qtbot.waitUntil(lambda: not w.autosaver.writing, timeout=10000)
    recovery = w.autosaver.project_file
    assert not recovery.exists() and not recovery.with_suffix(".json").exists()
    assert w.autosaver.autosaves == 0
    assert load_project(tmp_path / "face.wrinkle").wdv.expression_factor == pytest.approx(0.6)
    _close(w)


def test_closing_during_an_autosave_leaves_no_recovery_file(qtbot, sample, dialogs,
                                                            fast_autosave, held_writer):
    w = _open(qtbot, sample)
    w.doc.set_expression_factor(0.6)
    qtbot.waitUntil(held_writer.started.is_set, timeout=10000)
    recovery = w.autosaver.project_file
    threading.Timer(0.2, held_writer.release.set).start()  # the write ends during the close
    _close(w)
    qtbot.waitUntil(lambda: not recovery.with_suffix(".lock").exists(), timeout=10000)
    assert not recovery.exists() and find_recoveries() == []


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


class _Value(QUndoCommand):
    """A mergeable edit whose size grows as it merges (like a stroke that goes on)."""

    def __init__(self, size: int, key: int = 1) -> None:
        super().__init__("Value")
        self.data = np.ones(size, np.uint8)
        self.key = key

    def id(self) -> int:
        return self.key

    def mergeWith(self, other: QUndoCommand) -> bool:
        self.data = np.concatenate([self.data, other.data])
        return True

    def redo(self) -> None:
        pass

    def undo(self) -> None:
        pass


def test_undo_budget_keeps_count_through_every_kind_of_change(qtbot):
    """The budget measures only the steps that changed; its running total must still equal a
    fresh measurement after pushes, merges, undo, redo, jumps, obsolete steps and clear."""
    stack = QUndoStack()
    budget = install_undo_budget(stack, budget=6 << 20)

    def check() -> None:
        assert budget.tracked_bytes() == budget.total_bytes()
        assert budget.total_bytes() <= 6 << 20 or stack.index() <= 1

    for _ in range(8):
        stack.push(_Stroke(1 << 19))
        check()
    stack.push(_Value(1 << 18))  # merges grow the newest step
    for _ in range(3):
        stack.push(_Value(1 << 18))
        check()
    stack.undo()
    stack.undo()
    check()
    stack.push(_Stroke(1 << 20))  # drops the two redo steps
    check()
    stack.setIndex(2)  # a click in the History panel
    check()
    stack.setIndex(stack.count())
    check()
    obsolete = _Stroke(1 << 20)
    stack.push(obsolete)
    obsolete.setObsolete(True)  # a command may declare itself void; undo then deletes it
    stack.undo()
    check()
    for size in (3 << 18, 1 << 18, 1 << 19):
        stack.push(_Stroke(size))
    for _ in range(3):
        stack.undo()
    stack.command(stack.index()).setObsolete(True)  # the jump's first redo deletes it
    stack.setIndex(stack.count())
    check()
    for _ in range(40):  # well past the budget: the oldest steps go
        stack.push(_Stroke(1 << 20))
        check()
    assert budget.dropped > 0 and budget.total_bytes() <= 6 << 20
    while stack.canUndo():
        stack.undo()
        check()
    stack.clear()
    check()
    assert budget.tracked_bytes() == 0


def test_the_budget_counts_a_paint_strokes_tiles(qtbot, sample):
    """A stroke's undo step holds its tiles (before and after); the budget must count them,
    or a long painting session would grow past it unseen."""
    from studio.core.wrinkles.brush import Brush
    from studio.widgets.document import Document
    from studio.widgets.paint.edits import PaintSession
    from studio.widgets.undo_budget import command_bytes

    doc = Document(sample)
    session = PaintSession(doc, 0, Brush(radius=40.0))
    session.jump(100, 100)
    for i in range(1, 30):
        session.to(100 + 8 * i, 100 + 3 * i)
    command = session.end()
    tiles = sum(before.nbytes + after.nbytes for _, _, before, after in command.tiles)
    assert tiles > 100_000
    assert command_bytes(command) >= tiles


def test_a_snapshot_copies_again_only_what_changed_since_the_last(qtbot, sample, dialogs,
                                                                  fast_autosave):
    """Autosaving after each edit must not copy the whole project each time (a hitch on a real
    head), and must never write a stale copy: a stroke's mask is copied again, and what it
    wrote is in the recovery file. Seen red: with every copy kept, the second file lacks the
    stroke."""
    from studio.widgets.paint.edits import set_link

    w = _open(qtbot, sample)
    w.autosaver.set_interval(0)  # this test starts each autosave itself
    doc, saver = w.doc, w.autosaver
    doc.set_expression_factor(0.3)
    assert saver.autosave()
    qtbot.waitUntil(lambda: saver.autosaves == 1, timeout=10000)
    first = dict(saver._copies.kept)
    masks = [id(a.mask) for a in doc.project.influence.areas]
    assert all(m in first for m in masks)

    set_link(doc, "frown", doc.project.influence.areas[0].name, 0.7)  # no array changes
    assert saver.autosave()
    qtbot.waitUntil(lambda: saver.autosaves == 2, timeout=10000)
    assert all(saver._copies.kept[m][1] is first[m][1] for m in masks)  # shared, not copied

    _stroke(doc, 1)
    assert saver.autosave()
    qtbot.waitUntil(lambda: saver.autosaves == 3, timeout=10000)
    kept = saver._copies.kept
    assert kept[masks[1]][1] is not first[masks[1]][1]  # the painted mask was copied again
    assert kept[masks[0]][1] is first[masks[0]][1]
    recovered = load_project(saver.project_file)
    assert np.abs(recovered.influence.areas[1].mask
                  - doc.project.influence.areas[1].mask).max() <= 1 / 65535
    assert recovered.influence.links["frown"][doc.project.influence.areas[0].name] == \
        pytest.approx(0.7)
    _close(w)
