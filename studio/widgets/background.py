"""Long work (opening a project, say) on a worker thread while the window stays responsive: a
progress dialog with Cancel, shown if the work takes more than a moment.

Why a local event loop rather than callbacks: the caller reads as straight-line code (open,
then replace the document or show the error) and still gets a live window, a moving progress
bar and a Cancel button that works; the worker never touches a widget.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TypeVar

from PySide6.QtCore import QEventLoop, Qt, QTimer
from PySide6.QtWidgets import QProgressDialog, QWidget

from studio.core.files.errors import Cancelled

T = TypeVar("T")
Progress = Callable[[int, int], bool]  # (done, total) -> go on?

POLL_MS = 30


def run_with_progress(parent: QWidget, title: str, text: str,
                      work: Callable[[Progress], T]) -> T:
    """``work(progress)`` on a worker thread; returns its result or raises its exception
    (``Cancelled`` when the user pressed Cancel and the work stopped)."""
    cancel = threading.Event()
    state: dict[str, object] = {"done": 0, "total": 1}

    def progress(done: int, total: int) -> bool:
        state["done"], state["total"] = done, max(total, 1)
        return not cancel.is_set()

    def run() -> None:
        try:
            state["result"] = work(progress)
        except BaseException as exc:  # handed to the GUI thread, raised there
            state["error"] = exc

    dialog = QProgressDialog(text, "Cancel", 0, 1000, parent)
    dialog.setWindowTitle(title)
    dialog.setWindowModality(Qt.WindowModality.WindowModal)
    dialog.setMinimumDuration(300)
    dialog.setAutoReset(False)
    dialog.canceled.connect(cancel.set)
    loop = QEventLoop()
    thread = threading.Thread(target=run, name=title, daemon=True)
    timer = QTimer()
    timer.setInterval(POLL_MS)

    def poll() -> None:
        dialog.setValue(int(1000 * int(state["done"]) / int(state["total"])))
        if not thread.is_alive():
            loop.quit()

    timer.timeout.connect(poll)
    thread.start()
    timer.start()
    loop.exec()
    timer.stop()
    dialog.canceled.disconnect(cancel.set)  # closing a progress dialog emits "canceled"
    dialog.close()
    dialog.deleteLater()
    if "error" in state:
        raise state["error"]  # type: ignore[misc]
    if cancel.is_set() or "result" not in state:  # cancelled, even if the work did not stop
        raise Cancelled()
    return state["result"]  # type: ignore[return-value]
