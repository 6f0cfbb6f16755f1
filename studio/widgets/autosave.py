"""Autosave and crash recovery: hours of painting survive a crash, a kill or a power cut.

A change is on disk within seconds: every step on the undo stack (a stroke, a key, a link, a
rename) starts a short countdown (``DEBOUNCE_MS``), restarted by the next step so that a burst of
edits is written once, but never put off past ``MAX_DELAY_MS`` after the first unsaved step, so
that a person editing without pause still loses at most about ten seconds to a kill. A timer
every few minutes (QSettings ``autosave/interval_minutes``, default 3; 0 turns both off) catches
anything else. The document goes with :func:`save_project` (atomic) to a recovery file in the
user's data folder (``QStandardPaths.AppDataLocation/recovery``): what it is made of, its lock and
which ones are orphaned is ``studio.core.project.recovery``'s (Qt-free) business.

A clean close of the window, or saving the document, deletes the recovery file. At start-up the
window offers each orphaned one (a question box: when the studio stopped, how recent the work
is, project, original path, and the crash log when Python's faulthandler wrote one): Yes opens it
as an unsaved document (so the user chooses where to save it) and the window adopts the recovery
file as its own — kept, locked and updated, until the user saves or closes that document, so a
second crash right after recovering loses nothing; Discard deletes it; Ignore keeps it for the
next start.

Why a worker thread: writing the project (PNG and zip compression, fsync) takes most of a second
for the sample face and far longer for big masks, and the artist must not feel a hitch every few
minutes. The GUI thread only takes a snapshot — a private copy of the project
(:func:`snapshot_project`), because undo commands change arrays in place (a brush stroke writes
into its mask) and the writer must not store half a stroke — and a worker thread writes it; the
GUI thread hears back through a queued signal. One write at a time; a timer tick during a write
is skipped (the next one catches up).
"""

from __future__ import annotations

import contextlib
import itertools
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from PySide6.QtCore import QEvent, QObject, Qt, QTimer, Signal
from PySide6.QtWidgets import QMessageBox

from studio.core.files.errors import StudioError
from studio.core.project import reader, recovery
from studio.core.project.model import Project
from studio.core.project.recovery import (
    Recovery,
    RecoveryFile,
    recovery_meta,
    snapshot_project,
    write_recovery,
)
from studio.widgets.app_settings import data_folder, settings
from studio.widgets.crash_log import current_crash_log

if TYPE_CHECKING:
    from PySide6.QtWidgets import QStatusBar

    from studio.widgets.document import Document


class MainWindow(Protocol):
    """What autosave needs of the studio window (``studio.widgets.main_window.MainWindow``,
    which installs it — hence not imported here)."""

    doc: Document
    autosaver: Autosaver

    def show_error(self, title: str, error: Exception) -> None: ...

    def statusBar(self) -> QStatusBar: ...

    def show(self) -> None: ...


INTERVAL_KEY = "autosave/interval_minutes"
DEFAULT_MINUTES = 3.0
DEBOUNCE_MS = 2000  # a burst of edits is written once, this long after its last step
MAX_DELAY_MS = 8000  # ... but never later than this after the first unsaved step
HEARTBEAT_MS = 5000  # how often a live window touches its lock file
_sessions = itertools.count(1)
_offering = False  # one offer at a time (a recovered second window must not ask again)


def recovery_dir() -> Path:
    """The folder for recovery files (created on demand)."""
    return data_folder() / "recovery"


def find_recoveries(folder: Path | None = None) -> list[Recovery]:
    """Orphaned recovery files in ``folder`` (the user's recovery folder), newest first."""
    return recovery.find_recoveries(folder or recovery_dir())


class SnapshotCopies(QObject):
    """The arrays of the last autosave's snapshot, kept for the next one while the document
    says they have not changed: an edit of a link, a name or a key copies nothing large, a
    paint stroke copies the masks it touched (the ICT head's 141 MB of arrays cost 50 ms to
    copy, a hitch a person feels, against about 1 ms for the rest of the project).

    Conservative by design: any change that may write into arrays in place (poses, textures,
    masks, vectors, the timeline, another project) forgets every copy; painting forgets the
    painted layer's."""

    def __init__(self, doc: Document) -> None:
        super().__init__(doc)
        self.doc = doc
        self.kept: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        for signal in (doc.projectReplaced, doc.posesChanged, doc.texturesChanged,
                       doc.masksChanged, doc.wdvChanged, doc.timelineChanged):
            signal.connect(self.kept.clear)
        doc.maskRegionChanged.connect(self._painted)

    def _painted(self, layer: int, *_rect: int) -> None:
        areas = self.doc.project.influence.areas
        if 0 <= layer < len(areas):
            self.kept.pop(id(areas[layer].mask), None)
        else:
            self.kept.clear()


@dataclass
class _Job:
    """One autosave: what to write and, once written, how it went."""

    project: Project
    meta: dict[str, Any]
    target: Path
    undo_index: int
    generation: int
    error: Exception | None = None


class _Relay(QObject):
    """Carries a finished job from the worker thread to the GUI thread (a queued signal)."""

    finished = Signal(object)


class Autosaver(QObject):
    """Autosaves one window's document and offers recovery when the window starts."""

    def __init__(self, window: MainWindow) -> None:
        super().__init__(window)
        self.window = window
        self.files = RecoveryFile(recovery_dir(),
                                  f"{os.getpid()}-{int(time.time())}-{next(_sessions)}")
        self._saved_index: int | None = None  # undo index at the last autosave
        self.autosaves = 0
        self._closing = False
        self._generation = 0  # bumped by discard(): a write still running is then void
        self._job: _Job | None = None  # the write in progress
        self._thread: threading.Thread | None = None
        self._relay = _Relay(self)
        self._copies = SnapshotCopies(window.doc)
        self._relay.finished.connect(self._written, Qt.ConnectionType.QueuedConnection)
        self.timer = QTimer(self)
        self.timer.timeout.connect(self.autosave)
        self.soon = QTimer(self)  # the countdown after an undo step (DEBOUNCE_MS, MAX_DELAY_MS)
        self.soon.setSingleShot(True)
        self.soon.timeout.connect(self.autosave)
        self._first_unsaved: float | None = None  # when the oldest step not yet written came
        self.heartbeat = QTimer(self)
        self.heartbeat.timeout.connect(self.files.beat)
        self.heartbeat.start(HEARTBEAT_MS)
        self.enabled = True
        self.set_interval(_interval_minutes())
        window.installEventFilter(self)
        window.doc.modifiedChanged.connect(self._modified_changed)
        window.doc.undo_stack.indexChanged.connect(self._stepped)

    @property
    def project_file(self) -> Path:
        return self.files.project_file

    @property
    def writing(self) -> bool:
        """Whether an autosave is being written right now (on the worker thread)."""
        return self._job is not None

    def set_interval(self, minutes: float) -> None:
        """Autosave every ``minutes`` and seconds after each edit (0 or less: never)."""
        self.timer.stop()
        self.soon.stop()
        self.enabled = minutes > 0
        if self.enabled:
            self.timer.start(max(1, round(minutes * 60_000)))

    def _stepped(self, _index: int = 0) -> None:
        """An undo step was done, undone or redone: write it soon (see the module's words)."""
        if not self.enabled:
            return
        now = time.monotonic()
        if self._first_unsaved is None:
            self._first_unsaved = now
        left = MAX_DELAY_MS - (now - self._first_unsaved) * 1000.0
        self.soon.start(max(0, round(min(DEBOUNCE_MS, left))))

    # --- autosaving ----------------------------------------------------------------------------
    def autosave(self) -> bool:
        """Start writing the document to the recovery file if it changed since the last
        autosave; returns whether a write started. The GUI thread only snapshots the project;
        the write runs on a worker thread (``autosaves`` counts the finished ones)."""
        doc = self.window.doc
        if self._job is not None:  # still writing the last one: written again when it ends
            return False
        self._first_unsaved = None
        if not doc.modified or self._saved_index == doc.undo_stack.index():
            return False
        try:
            self.files.take_lock()
        except OSError as exc:  # never interrupt the user: say it and go on
            self._failed(exc)
            return False
        doc.store_view_state()
        meta = recovery_meta(doc.display_name, doc.path, current_crash_log())
        job = _Job(snapshot_project(doc.project, self._copies.kept), meta, self.project_file,
                   doc.undo_stack.index(), self._generation)
        self._job = job
        self._thread = threading.Thread(target=self._write, args=(job, self._relay),
                                        name="autosave", daemon=True)
        self._thread.start()
        return True

    @staticmethod
    def _write(job: _Job, relay: _Relay) -> None:
        """The worker thread: write the snapshot atomically, then its description."""
        try:
            write_recovery(job.project, job.target, job.meta)
        except Exception as exc:  # any failure must reach the GUI thread,
            job.error = exc  # or autosaving would stop for good without a word
        with contextlib.suppress(RuntimeError):  # the window is gone: nobody to tell
            relay.finished.emit(job)

    def _written(self, job: _Job) -> None:
        """Back on the GUI thread: count the autosave, or say why it failed."""
        if job is not self._job:
            return
        self._job = None
        if job.generation != self._generation:  # saved or closed meanwhile: nothing to keep
            self.files.remove()
        elif job.error is not None:
            self._failed(job.error)
        else:
            self._saved_index = job.undo_index
            self.autosaves += 1
            self.window.statusBar().showMessage("Autosaved", 2000)
        if self.window.doc.undo_stack.index() != self._saved_index:
            self._stepped()  # edits made while it was writing: their own countdown

    def _failed(self, exc: Exception) -> None:
        self.window.statusBar().showMessage(f"Autosave failed: {exc}", 10_000)

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the write in progress (if any) to finish; False if it is still running."""
        thread = self._thread
        if thread is not None:
            thread.join(timeout)
            if thread.is_alive():
                return False
            self._thread = None
        return True

    def discard(self) -> None:
        """Delete this window's recovery file (the document is saved, or closed on purpose);
        a write still running is void, and its file is deleted when it ends."""
        self._generation += 1
        self.files.remove()
        self._saved_index = None

    def shut_down(self) -> None:
        """A clean exit: stop, let a running write end, delete the recovery file and the lock.

        Why wait: a write that ended after the window had gone would leave a recovery file that
        nobody deletes, offered at the next start as if the studio had crashed. (A write stuck
        for a minute, on a hung network disk say, is not waited for: at worst its file is
        offered once more at the next start.)"""
        self._stop_timers()
        self.wait(60.0)
        self._job = None
        self.discard()
        self.files.release(delete_lock=True)

    def abandon(self) -> None:
        """What a crash does (for tests): stop and let go of the files without deleting them
        (a write in progress ends first, so that the test knows what is on disk)."""
        self._stop_timers()
        self.wait()
        self._job = None
        self.window.removeEventFilter(self)
        with contextlib.suppress(RuntimeError, TypeError):
            self.window.doc.modifiedChanged.disconnect(self._modified_changed)
        with contextlib.suppress(RuntimeError, TypeError):
            self.window.doc.undo_stack.indexChanged.disconnect(self._stepped)
        self.files.release(delete_lock=False)

    def _stop_timers(self) -> None:
        for timer in (self.timer, self.soon, self.heartbeat):
            timer.stop()

    def adopt(self, item: Recovery) -> None:
        """Make a recovered file this window's own recovery file: kept on disk, locked and
        updated by later autosaves, until the document is saved or closed on purpose — so a
        crash right after recovering offers the same work again. This window's own files (it
        had written nothing worth keeping: it was just opened) are let go."""
        self.discard()
        try:
            self.files.adopt(item)
        except OSError as exc:  # the file stays where it is, offered again next time
            self._failed(exc)
            return
        self._saved_index = self.window.doc.undo_stack.index()  # the file holds this state

    def _modified_changed(self, modified: bool) -> None:
        if not modified:  # saved (or undone back to the saved state): nothing to recover
            self.discard()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """A clean exit is a Close the window accepted, which Qt follows at once with a Hide.

        Why not act on Close itself: the window's closeEvent runs after this filter and may
        still refuse (the user cancelled "save changes?").
        """
        if watched is self.window:
            if event.type() == QEvent.Type.Close:
                self._closing = True
                QTimer.singleShot(0, self._close_refused)
            elif event.type() == QEvent.Type.Hide and self._closing:
                self._closing = False
                self.shut_down()
        return False

    def _close_refused(self) -> None:
        self._closing = False

    # --- recovery ------------------------------------------------------------------------------
    def offer_recovery(self) -> int:
        """Ask about each orphaned recovery file; returns how many documents were recovered."""
        global _offering
        if _offering:
            return 0
        _offering = True
        try:
            return self._offer()
        finally:
            _offering = False

    def _offer(self) -> int:
        recovered = 0
        for item in find_recoveries(self.files.folder):
            buttons = (QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Discard
                       | QMessageBox.StandardButton.Ignore)
            answer = QMessageBox.question(
                self.window, "Recover unsaved work",
                f"{item.story()}\n\n{item.describe()}\n\nRecover it? (Yes: open it as an "
                "unsaved document, kept until you save it; Discard: delete it; Ignore: ask "
                "again next time)", buttons)
            if answer == QMessageBox.StandardButton.Discard:
                item.remove()
                continue
            if answer != QMessageBox.StandardButton.Yes:
                continue
            try:
                project = reader.load_project(item.project_file)
            except StudioError as exc:
                self.window.show_error("Cannot recover project", exc)
                continue
            target = self.window if recovered == 0 and not self.window.doc.modified \
                else _new_window(self.window)
            target.doc.replace_project(project, None)
            target.doc.undo_stack.resetClean()  # unsaved until the user saves it somewhere
            target.autosaver.adopt(item)  # on disk until saved: a second crash loses nothing
            target.statusBar().showMessage(
                f"Recovered “{item.name}” — save it to keep it", 10_000)
            recovered += 1
        return recovered


def _new_window(parent: MainWindow) -> MainWindow:
    """A further window for a second recovered document (kept alive by the first)."""
    window = type(parent)(parent.doc.project)
    parent._recovered_windows = [*getattr(parent, "_recovered_windows", []), window]
    window.show()
    return window


def _interval_minutes() -> float:

    try:
        return float(settings().value(INTERVAL_KEY, DEFAULT_MINUTES))
    except (TypeError, ValueError):
        return DEFAULT_MINUTES


def install_autosave(window: MainWindow) -> Autosaver:
    """Autosave ``window``'s document, keep its undo history in budget, offer recovery once
    the window is running (a queued call, so the window shows before any question)."""
    from studio.widgets.undo_budget import install_undo_budget

    window.autosaver = Autosaver(window)
    window.undo_budget = install_undo_budget(window.doc.undo_stack, window)
    QTimer.singleShot(0, window.autosaver.offer_recovery)
    return window.autosaver
