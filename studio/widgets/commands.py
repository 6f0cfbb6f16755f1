"""Undo commands. Most edits set one value; a continuous gesture (a slider drag) merges into one
undo step by sharing a gesture token."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Hashable
from typing import Any

from PySide6.QtGui import QUndoCommand

_VALUE_COMMAND_ID = 1001
_gestures = itertools.count(1)


def new_gesture() -> int:
    """A token for one continuous user gesture: commands carrying it merge into one step."""
    return next(_gestures)


class ValueCommand(QUndoCommand):
    """Sets a value through ``apply``; undo applies the value it had before."""

    def __init__(self, text: str, read: Callable[[], Any], apply: Callable[[Any], None],
                 value: Any, merge_key: Hashable | None = None) -> None:
        super().__init__(text)
        self._apply = apply
        self.old = read()
        self.new = value
        self.merge_key = merge_key

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)

    def id(self) -> int:
        return _VALUE_COMMAND_ID if self.merge_key is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, ValueCommand) or other.merge_key != self.merge_key:
            return False
        self.new = other.new
        return True


def push_flags(stack, items: list, attr: str, values: tuple[bool, ...], text: str,
               changed: Callable[[], None]) -> None:
    """One flag (``attr``) of every item at once as one undo step — Solo, show all, mute all —
    then ``changed()`` to tell the views; nothing is pushed when the flags are already so."""
    def read() -> tuple[bool, ...]:
        return tuple(getattr(item, attr) for item in items)

    def apply(flags: tuple[bool, ...]) -> None:
        for item, flag in zip(items, flags, strict=True):
            setattr(item, attr, flag)
        changed()

    if read() != tuple(values):
        stack.push(ValueCommand(text, read, apply, tuple(values)))
