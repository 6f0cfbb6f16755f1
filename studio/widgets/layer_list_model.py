"""The rules of a list of layers (technique 1's areas, technique 2's vector areas), with no Qt.

Why shared: both panels' lists solo, move and keep a selection the same way, as Blender's and
Substance Painter's layer stacks do; one set of rules serves both, tested in milliseconds.
"""

from __future__ import annotations


def solo(shown: tuple[bool, ...], index: int, name: str) -> tuple[tuple[bool, ...], str]:
    """Solo: only layer ``index`` shows; pressed again (or for a layer already alone), all do.
    Returns what shows and the undo step's name."""
    alone = tuple(i == index for i in range(len(shown)))
    if shown == alone:
        return tuple(True for _ in shown), "Show all areas"
    return alone, f"Solo {name}"


def can_move(index: int, step: int, count: int) -> bool:
    """Whether Up (-1) or Down (+1) can move the selected layer."""
    return 0 <= index < count and 0 <= index + step < count


def kept_selection(current: int, count: int) -> int:
    """The row a rebuilt list keeps selected: the same row, or the last when it is gone
    (-1: an empty list)."""
    return min(max(current, 0), count - 1) if count else -1
