"""Emptying a panel's layout without deleting a widget whose own event is still running.

Why: a panel that rebuilds its rows in answer to a document change can be answering a change
one of those rows started — a spin box's Return, a check box's click, a combo's choice. Qt is
still inside that widget's event handler when the signal reaches the panel; deleting the widget
there (``QFormLayout.removeRow``, ``del``, ``setParent(None)``) returns Qt into freed memory and
the studio dies with a segmentation fault. Widgets taken out here are hidden at once and
deleted by the event loop (``deleteLater``), after every handler on the stack has returned.
"""

from __future__ import annotations

from PySide6.QtWidgets import QFormLayout, QLayout, QLayoutItem


def clear_form(form: QFormLayout) -> None:
    """Take every row out of ``form``; its widgets go once the current event is over."""
    while form.rowCount():
        row = form.takeRow(0)
        for item in (row.labelItem, row.fieldItem):
            if item is not None:
                _discard(item)


def clear_layout(layout: QLayout) -> None:
    """Take every item out of ``layout`` (nested layouts too), deleting its widgets later."""
    while layout.count():
        item = layout.takeAt(0)
        if item is not None:
            _discard(item)


def _discard(item: QLayoutItem) -> None:
    widget = item.widget()
    if widget is not None:
        widget.hide()
        widget.deleteLater()
    elif item.layout() is not None:
        clear_layout(item.layout())
