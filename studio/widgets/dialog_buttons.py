"""The studio's dialogs end in one way: Cancel and a button named for what the dialog does."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtWidgets import QDialog, QDialogButtonBox


def action_buttons(dialog: QDialog, action: str, on_accept: Callable[[], None]
                   ) -> QDialogButtonBox:
    """OK renamed ``action`` (Bake, Export, …) running ``on_accept``; Cancel rejects."""
    box = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                           | QDialogButtonBox.StandardButton.Cancel)
    box.button(QDialogButtonBox.StandardButton.Ok).setText(action)
    box.accepted.connect(on_accept)
    box.rejected.connect(dialog.reject)
    return box
