"""``wrinkle-studio bench``: the thesis's performance study, reproduced and extended."""

from __future__ import annotations

import argparse
import os
import platform
from itertools import groupby
from pathlib import Path
from typing import TYPE_CHECKING

from studio.commands.options import parse_size
from studio.core.files.errors import StudioError

if TYPE_CHECKING:
    from studio.bench.configs import Config


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="time both techniques offscreen, like the thesis")
    p.add_argument("--frames", type=int, default=1000, help="frames per configuration (1000)")
    p.add_argument("--size", type=parse_size, default=(1280, 720), help="WxH (1280x720)")
    p.add_argument("--quick", action="store_true",
                   help="a small subset with few frames, in well under a minute")
    p.add_argument("--out", default="bench-results", help="folder for results.csv and plots")
    p.add_argument("--poses", type=parse_poses, default=0, metavar="N",
                   help="also time a capture take's case: N ARKit poses (up to 52), every "
                        "weight changing every frame, on a 30000-vertex face")
    p.add_argument("--setup", action="store_true",
                   help="time setting heads up instead (the sample, heads in other "
                        "conventions, a 250000-vertex head): wall time, CPU time and peak "
                        "memory per stage, into setup.md and setup.csv, then the studio's first "
                        "start on a fresh user folder and a 250000-vertex frame (with "
                        "--quick: the two small heads only)")
    p.set_defaults(run=run)


def parse_poses(text: str) -> int:
    from studio.core.animation.pose_names import ARKIT_NAMES

    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 1 <= n <= len(ARKIT_NAMES):
        raise argparse.ArgumentTypeError(f"{n}: choose 1 to {len(ARKIT_NAMES)} poses")
    return n


def run(args: argparse.Namespace) -> int:
    from studio.bench.configs import configurations
    from studio.bench.poses import bench_project
    from studio.bench.report import table, write_csv, write_plots
    from studio.bench.runner import PASSES, time_configurations
    from studio.render.gl_info import create_standalone_context, describe_gl

    frames = min(args.frames, 20) if args.quick else args.frames
    if frames < 1:
        raise StudioError(f"--frames {args.frames}: need at least one frame")
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise StudioError(f"cannot create the results folder: {exc.strerror}", out) from None
    if args.setup:
        return run_setup(args.quick, out)
    ctx = create_standalone_context()
    print(describe_gl(ctx), flush=True)
    print(f"machine: {platform.machine()}, {platform.processor() or platform.system()}, "
          f"Python {platform.python_version()}")
    print(f"{frames} frames per configuration at {args.size[0]}x{args.size[1]}, in "
          f"{PASSES} turns round each face's configurations")
    results = []

    def skipped(config: Config, reason: str) -> None:
        print(f"skipped {config.label}: {reason}", flush=True)

    for vertices, group in groupby(configurations(args.quick, args.poses),
                                   key=lambda c: c.vertices):
        group = list(group)
        print(f"timing {len(group)} configurations on the {vertices}-vertex face …", flush=True)
        projects = [bench_project(c) for c in group]
        timed = time_configurations(ctx, projects, group, frames, args.size, skipped=skipped)
        results += timed
        if timed:
            print("\n".join(table(timed).splitlines()[1:]), flush=True)
        write_csv(results, out / "results.csv")  # a later failure keeps what was timed
    print()
    print(table(results))
    plots = write_plots(results, out)
    print(f"wrote {out / 'results.csv'}, {', '.join(str(p) for p in plots)}")
    ctx.release()
    return 0


def run_setup(quick: bool, out: Path) -> int:
    """``bench --setup``: each head set up, its stages' figures printed and written."""
    from studio.bench.first_start import lines
    from studio.bench.setup_run import measure, write_results

    print(f"machine: {platform.machine()}, {platform.processor() or platform.system()}, "
          f"Python {platform.python_version()}, {os.cpu_count()} cores", flush=True)
    results = measure(quick, say=lambda text: print(text, flush=True))
    notes = [] if quick else lines()  # the starts and a 250 000-vertex frame: minutes more
    print("\n".join(notes))
    write_results(results, out, notes)
    print(f"wrote {out / 'setup.md'}, {out / 'setup.csv'}")
    return 0
