"""The furrow controls as command-line flags (``new``): ``--furrow-depth``, ``--furrow-spacing``,
``--furrow-sharpness`` and ``--furrow-onset``, each ``VALUE`` for all poses or ``POSE=VALUE`` for
one, repeatable (a later one wins), as the Furrows panel sets them in the studio. A value that is
no number or out of its range is a usage error (one line, exit 2) before any file is read; a pose
the files do not have is said once they are read (``new_setup.new_project``)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from studio.core.wrinkles.furrow_controls import RANGES, FurrowControls

Values = dict[str | None, dict[str, float]]  # pose (None: all poses) -> {control: value}
HELP = {"depth": "× the furrows' depth (1: as synthesised)",
        "spacing": "× the distance between neighbouring furrows (1: as synthesised)",
        "sharpness": "× how narrow each furrow is (1: as synthesised)",
        "onset": "the pose weight below which its lines do not show (0: from the start)"}


def flag(name: str) -> str:
    return f"--furrow-{name}"


def _value_type(name: str) -> Callable[[str], tuple[str | None, float]]:
    """argparse's type for one control's flag: ``VALUE`` or ``POSE=VALUE``, checked."""
    def parse(text: str) -> tuple[str | None, float]:
        pose, sep, number = text.rpartition("=")
        if sep and not pose:
            raise argparse.ArgumentTypeError(f"'{text}' names no pose (VALUE or POSE=VALUE)")
        try:
            value = float(number)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"'{number}' is not a number (VALUE or POSE=VALUE)") from None
        try:
            FurrowControls(**{name: value})
        except ValueError as exc:
            shown = f"{value:g}" if math.isfinite(value) else number
            raise argparse.ArgumentTypeError(f"{exc} (not {shown})") from None
        return (pose if sep else None), value

    parse.__name__ = f"furrow {name}"  # what argparse names in its message
    return parse


def add_furrow_flags(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "furrow controls", "for every pose (VALUE) or one (POSE=VALUE); repeatable")
    for name, (low, high) in RANGES.items():
        group.add_argument(flag(name), action="append", default=[], type=_value_type(name),
                           metavar="[POSE=]VALUE", dest=f"furrow_{name}",
                           help=f"{HELP[name]}, {low:g} to {high:g}")


def furrow_values(args: argparse.Namespace) -> Values:
    """The flags given, {pose (None: all poses): {control: value}}, the last of each kept."""
    values: Values = {}
    for name in RANGES:
        for pose, value in getattr(args, f"furrow_{name}"):
            values.setdefault(pose, {})[name] = value
    return values
