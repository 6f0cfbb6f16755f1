"""Times every frame of a pose sweep on the bundled sample head and says whether any frame is far
slower than the rest (issue #28 item 6: one pose at one angle took six seconds on llvmpipe).

``python scripts/frame_sweep.py`` sweeps browDown_R from 0 to 1 in 50 steps at yaw 0, 20 and 40,
482 × 543, with technique none and the default technique, and prints per technique the median,
the slowest frame (with its weight and yaw) and slowest / median; it exits 1 when a ratio is over
``--limit`` (3). ``--project``, ``--pose``, ``--steps``, ``--yaws``, ``--size`` and
``--techniques`` change the sweep. Each frame is timed from the pose change to the pixels read
back (the GPU's work included), as a viewport frame is.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from studio.core.project.view_settings import ViewSettings
from studio.render.gl_info import describe_gl
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import render_settings


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--project", type=Path, help="a .wrinkle project (default: the sample head)")
    p.add_argument("--pose", default="browDown_R")
    p.add_argument("--steps", type=int, default=50, help="weights from 0 to 1 (default 50)")
    p.add_argument("--yaws", default="0,20,40", help="camera yaws in degrees, comma separated")
    p.add_argument("--size", default="482x543")
    p.add_argument("--techniques", default=f"none,{ViewSettings().technique}")
    p.add_argument("--limit", type=float, default=3.0, help="largest slowest/median allowed")
    return p.parse_args(argv)


def load(path: Path | None):
    if path is None:
        from studio.core.setup.sample_setup import sample_project

        return sample_project()
    from studio.core.project.reader import load_project

    return load_project(path)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    project = load(args.project)
    width, height = (int(v) for v in args.size.lower().split("x"))
    yaws = [float(y) for y in args.yaws.split(",")]
    weights = np.linspace(0.0, 1.0, args.steps)
    worst = 0.0
    with OffscreenStudio(project, width, height) as studio:
        print(describe_gl(studio.ctx))
        studio.render(render_settings(ViewSettings()))  # compile and upload before timing
        for technique in args.techniques.split(","):
            settings = render_settings(ViewSettings(technique=technique))
            times: list[tuple[float, float, float]] = []  # ms, weight, yaw
            for yaw in yaws:
                studio.camera.yaw = yaw
                studio.render(settings, {})  # this view's first draw is not a pose's frame
                for w in weights:
                    start = time.perf_counter()
                    studio.render(settings, project.single_pose_weights(args.pose, float(w)))
                    times.append(((time.perf_counter() - start) * 1000.0, float(w), yaw))
            ms = np.array([t[0] for t in times])
            median = float(np.median(ms))
            slow_ms, slow_w, slow_yaw = times[int(ms.argmax())]
            ratio = slow_ms / median
            worst = max(worst, ratio)
            print(f"{technique:>6}: {len(ms)} frames, median {median:.0f} ms, max {slow_ms:.0f} ms"
                  f" ({args.pose} {slow_w:.3f}, yaw {slow_yaw:g}), max/median {ratio:.2f}")
    print(f"worst max/median {worst:.2f} (limit {args.limit:g}): "
          f"{'ok' if worst <= args.limit else 'TOO SLOW'}")
    return 0 if worst <= args.limit else 1


if __name__ == "__main__":
    sys.exit(main())
