"""The ``wrinkle-studio`` command: the studio window, and headless rendering.

Every problem the user can cause ends with one line on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from studio.core.errors import StudioError

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (and exit code 2), like every other error."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a size like 1280x720") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"'{text}': width and height must be 1 to 16384")
    return w, h


def parse_vertices(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 100 <= n <= 200_000:
        raise argparse.ArgumentTypeError(f"{n}: the sample face takes 100 to 200000 vertices")
    return n


def load_project_or_sample(path: str | None, vertices: int | None):
    """The project at ``path``, or the bundled sample face at the requested resolution."""
    if path is None:
        from studio.core.sample import make_sample

        return make_sample(vertices) if vertices else make_sample()
    from studio.core.project_file import load_project

    if vertices:
        raise StudioError("--vertices applies to the bundled sample, not to a project file")
    return load_project(Path(path))


def _add_render(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a project (or the bundled sample) to a PNG")
    p.add_argument("project", nargs="?", help="a .wrinkle project (default: the bundled sample)")
    p.add_argument("--technique", choices=("none", "t1", "t2", "flat"), default="t2")
    p.add_argument("--pose", default="neutral", help="key pose to show (default: neutral)")
    p.add_argument("--weight", type=float, default=1.0, help="weight of that pose, 0..1")
    p.add_argument("--size", type=parse_size, default=(1280, 720), help="WxH (default 1280x720)")
    p.add_argument("--vertices", type=parse_vertices, help="resolution of the bundled sample")
    p.add_argument("--view", choices=("shaded", "heat", "normals", "uv"), default="shaded",
                   help="debug view (heat = wrinkle visibility)")
    p.add_argument("--wireframe", action="store_true", help="draw the triangle edges on top")
    p.add_argument("--yaw", type=float, help="camera yaw in degrees (0 = front, 90 = profile)")
    p.add_argument("--pitch", type=float, help="camera pitch in degrees")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.set_defaults(run=run_render)


def run_render(args: argparse.Namespace) -> int:
    from PIL import Image

    from studio.render.offscreen import OffscreenStudio
    from studio.render.renderer import RenderSettings

    if not 0.0 <= args.weight <= 1.0:
        raise StudioError(f"--weight {args.weight}: a pose weight is between 0 and 1")
    project = load_project_or_sample(args.project, args.vertices)
    weights = project.single_pose_weights(args.pose, args.weight)
    settings = RenderSettings(technique=args.technique, view=args.view, wireframe=args.wireframe)
    with OffscreenStudio(project, *args.size) as studio:
        if args.yaw is not None:
            studio.camera.yaw = args.yaw
        if args.pitch is not None:
            studio.camera.pitch = args.pitch
        image = studio.render(settings, weights)
    out = Path(args.output)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(image).save(out)
    except OSError as exc:
        raise StudioError(f"cannot write the image: {exc.strerror or exc}", out) from None
    print(f"wrote {out} ({args.size[0]}x{args.size[1]}, {args.technique}, pose {args.pose})")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="wrinkle-studio",
                     description="Author and preview real-time facial expression wrinkles.")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    _add_render(sub)
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
    return run(args.project, args.screenshot)


COMMANDS = ("render",)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in COMMANDS:
        args = build_parser().parse_args(argv)
    else:
        args = build_gui_parser().parse_args(argv)
        args.run = run_gui
    try:
        return args.run(args)
    except StudioError as exc:
        print(f"wrinkle-studio: error: {exc}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
