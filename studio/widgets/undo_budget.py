"""A memory budget for the undo history: long painting sessions do not grow without bound.

Commands that hold real data (a stroke's before/after patch) report it with ``nbytes()``, or
are measured by the numpy arrays they hold; each command also counts
:data:`SMALL_COMMAND_BYTES` for itself. When the done steps add up to more than the
budget (QSettings ``undo/budget_mb``, default 512 MB), the oldest ones are dropped.

Why not ``QUndoStack.setUndoLimit``: it counts steps, not bytes, and can only be set while the
stack is empty. QUndoStack cannot remove its bottom commands either, so a dropped step is marked
obsolete instead — Qt never undoes or redoes an obsolete command, and deletes it when undo reaches
it — and its Python data is released at once. Dropped steps are always the oldest contiguous
ones, so undoing down into them simply stops changing anything, exactly as if the history had
been cut there (the History panel shows them as "(dropped)" until then).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject, Slot
from PySide6.QtGui import QUndoCommand, QUndoStack

from studio.widgets.app_settings import settings

BUDGET_KEY = "undo/budget_mb"
DEFAULT_BUDGET_MB = 512.0
SMALL_COMMAND_BYTES = 1024
DROPPED_PREFIX = "(dropped) "


def command_bytes(command: QUndoCommand) -> int:
    """The estimated memory a command holds.

    Its own ``nbytes()`` where it has one; otherwise the numpy arrays among its attributes (and
    in lists, tuples and dicts of them, one level down — a stroke's tiles), or a small constant.
    """
    nbytes = getattr(command, "nbytes", None)
    if callable(nbytes):
        try:
            return max(int(nbytes()), 0)
        except Exception:  # a broken estimate must not break editing
            return SMALL_COMMAND_BYTES
    total = SMALL_COMMAND_BYTES
    for value in getattr(command, "__dict__", {}).values():
        total += _array_bytes(value, depth=2)
    return total


def _array_bytes(value: object, depth: int) -> int:
    if isinstance(value, np.ndarray):
        return int(value.nbytes)
    if depth <= 0:
        return 0
    if isinstance(value, list | tuple):
        return sum(_array_bytes(v, depth - 1) for v in value)
    if isinstance(value, dict):
        return sum(_array_bytes(v, depth - 1) for v in value.values())
    return 0


class UndoBudget(QObject):
    """Keeps one undo stack's done steps within ``budget`` bytes.

    Why the step sizes are remembered: measuring every command on every change of the stack
    costs time in proportion to the history — 30 ms a push with 2 000 steps, paid again at each
    move of a slider drag (a merge also announces an index change) — so a long session would
    grow slower and slower. QUndoStack only ever changes commands from just below the lower of
    the old and new index upwards (push, merge, undo and redo, which may delete obsolete ones,
    a jump in the History panel), or clears them all, so only that part is measured again.
    """

    def __init__(self, stack: QUndoStack, budget: int, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.stack = stack
        self.budget = int(budget)
        self.dropped = 0  # steps dropped so far
        self._sizes: list[int | None] = []  # bytes of each command in the stack; None: obsolete
        self._total = 0  # sum of the known sizes
        self._index = 0  # the stack's index when the sizes were last brought up to date
        self._bottom = 0  # commands below this one are all dropped (or obsolete)
        stack.indexChanged.connect(self._index_changed)

    @Slot(int)
    def _index_changed(self, _index: int) -> None:
        self.trim()

    def total_bytes(self) -> int:
        """Estimated bytes of the steps that can still be undone or redone (measured afresh)."""
        total = 0
        for i in range(self.stack.count()):
            command = self.stack.command(i)
            if not command.isObsolete():
                total += command_bytes(command)
        return total

    def tracked_bytes(self) -> int:
        """The running total that ``trim`` keeps (equals ``total_bytes`` after each change)."""
        return self._total

    def _sync(self, stack: QUndoStack) -> None:
        """Measure again the commands that may have changed since the last call."""
        count, index = stack.count(), stack.index()
        first = min(max(min(self._index, index) - 1, 0), count, len(self._sizes))
        if stack.undoLimit() > 0:  # a step limit removes the oldest commands: count them all
            first = 0
        self._total -= sum(size for size in self._sizes[first:] if size is not None)
        del self._sizes[first:]
        self._bottom = min(self._bottom, first)
        for i in range(first, count):
            command = stack.command(i)
            size = None if command.isObsolete() else command_bytes(command)
            self._sizes.append(size)
            self._total += size or 0
        self._index = index

    def trim(self) -> int:
        """Drop the oldest done steps until the history fits; returns how many were dropped.

        The newest done step and the redo steps are always kept.
        """
        stack = getattr(self, "stack", None)
        try:
            stack.count()
        except (RuntimeError, AttributeError):  # the stack or this object is being destroyed
            return 0
        self._sync(stack)
        sizes = self._sizes
        dropped = 0
        i = self._bottom
        while self._total > self.budget and i < self._index - 1:
            if sizes[i] is not None:
                self._total -= sizes[i]
                sizes[i] = None
                _drop(stack.command(i))
                dropped += 1
            i += 1
        if dropped:
            self._bottom = i
        self.dropped += dropped
        return dropped


def _drop(command: QUndoCommand) -> None:
    """Make a command obsolete and let go of its Python data (Qt never runs it again)."""
    command.setObsolete(True)
    command.setText(DROPPED_PREFIX + command.text())
    state = getattr(command, "__dict__", None)
    if state is not None:
        state.clear()


def _budget_bytes() -> int:

    try:
        megabytes = float(settings().value(BUDGET_KEY, DEFAULT_BUDGET_MB))
    except (TypeError, ValueError):
        megabytes = DEFAULT_BUDGET_MB
    return int(megabytes * (1 << 20))


def install_undo_budget(stack: QUndoStack, parent: QObject | None = None,
                        budget: int | None = None) -> UndoBudget:
    """Keep ``stack`` within ``budget`` bytes (default: the ``undo/budget_mb`` setting)."""
    return UndoBudget(stack, _budget_bytes() if budget is None else budget,
                      stack if parent is None else parent)
