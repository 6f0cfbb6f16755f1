"""The ``wrinkle-studio`` command: the studio window, and headless rendering.

Every problem the user can cause ends with one line on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from pathlib import Path

from studio.commands.options import EXIT_USAGE
from studio.core.files.errors import StudioError
from studio.core.files.naming import shown

# The longest error message printed: a message naming a file's parts can list many.
MESSAGE_CHARACTERS = 4000


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (and exit code 2), like every other error."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


# Each command lives in studio/commands/<name>.py with ``add_parser(subparsers)`` that sets
# ``run`` (a function of the parsed arguments returning the exit code).
COMMANDS = ("render", "sample", "bench", "new", "export", "bake", "capture")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="wrinkle-studio",
                     description="Author and preview real-time facial expression wrinkles.")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    for name in COMMANDS:
        importlib.import_module(f"studio.commands.{name}").add_parser(sub)
    return parser


def build_gui_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="wrinkle-studio",
        description="Open the studio window (on the bundled sample face by default). "
                    f"Commands: {', '.join(COMMANDS)} (see wrinkle-studio COMMAND -h).")
    parser.add_argument("project", nargs="?", help="a .wrinkle project to open")
    parser.add_argument("--screenshot", metavar="OUT.png",
                        help="save a screenshot of the window once it has drawn, then exit")
    return parser


def run_gui(args: argparse.Namespace) -> int:
    from studio.app import run

    if args.project is not None and not Path(args.project).is_file():
        raise StudioError("no such project file", args.project)
    if args.screenshot:
        from studio.core.files.safe_io import check_output

        check_output(args.screenshot, [args.project], what="screenshot")
    return run(args.project, args.screenshot)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in COMMANDS:
        args = build_parser().parse_args(argv)
    else:
        args = build_gui_parser().parse_args(argv)
        args.run = run_gui
    try:
        return args.run(args)
    except StudioError as exc:  # one line, whatever names the file put in it
        print(f"wrinkle-studio: error: {shown(exc, MESSAGE_CHARACTERS)}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
