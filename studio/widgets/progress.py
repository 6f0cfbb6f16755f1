"""A modal progress dialog for long work run on the GUI thread in steps (synthesis, set-up):
the work calls ``step(done, total)`` and stops when it returns False (Cancel pressed); the
dialog says the time left below its text, as the command line's bar does (``time_left``)."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QProgressDialog, QWidget

from studio.core.setup.time_left import TimeLeft

Step = Callable[[int, int], bool]


def progress_dialog(parent: QWidget, title: str, text: str) -> tuple[QProgressDialog, Step]:
    """The dialog (shown only if the work takes more than a moment; close it when done) and
    the step callback to hand to the work."""
    dialog = QProgressDialog(text, "Cancel", 0, 1, parent)
    dialog.setWindowTitle(title)
    dialog.setWindowModality(Qt.WindowModality.WindowModal)
    dialog.setMinimumDuration(400)

    time_left = TimeLeft()

    def step(done: int, total: int) -> bool:
        left = time_left.words(done, total)
        dialog.setLabelText(f"{text}\n{left[0].upper() + left[1:]}." if left else text)
        dialog.setMaximum(total)
        dialog.setValue(done)
        return not dialog.wasCanceled()

    return dialog, step
