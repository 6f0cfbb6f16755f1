"""What ``wrinkle-studio bench --setup`` measures besides setting heads up (issue 51's goals):
the studio's first start on a fresh user folder, a later start, and a frame of a
250 000-vertex head.

A start is timed as a user waits for it: from launching ``wrinkle-studio --screenshot`` in a
process of its own to the window's first drawn frame of the sample (the screenshot is taken
once the viewport has drawn, then the studio exits). The first start gets an empty home,
cache and settings folder, so it builds the sample as a new user's does; the second start
reuses that folder (the sample kept in the cache). A window needs a display: without one
(no ``DISPLAY`` or ``WAYLAND_DISPLAY``; run the benchmark under ``xvfb-run``) the starts are
not timed, and the reason is said instead."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

START_LIMIT_S = 600.0  # a start that takes longer has failed for the benchmark
RENDER_VERTICES = 250_000
RENDER_FRAMES = 20


def start_seconds() -> tuple[list[float], str]:
    """([first start, later start] in seconds, "") or ([], why they were not timed)."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return [], "no display (run the benchmark under xvfb-run to time the studio's start)"
    with tempfile.TemporaryDirectory(prefix="wrinkle-start-") as folder:
        home = Path(folder)
        env = {**os.environ, "HOME": str(home), "XDG_CACHE_HOME": str(home / ".cache"),
               "XDG_CONFIG_HOME": str(home / ".config"),
               "XDG_DATA_HOME": str(home / ".local" / "share")}
        times = []
        for turn in ("first", "later"):
            shot = home / f"{turn}.png"
            began = time.perf_counter()
            try:
                done = subprocess.run([sys.executable, "-m", "studio.cli", "--screenshot",
                                       str(shot)], env=env, capture_output=True, text=True,
                                      timeout=START_LIMIT_S, check=False)
            except subprocess.TimeoutExpired:
                return times, f"the {turn} start drew nothing in {START_LIMIT_S:.0f} s"
            if done.returncode != 0 or not shot.is_file():
                last = (done.stderr.strip().splitlines() or ["no message"])[-1]
                return times, f"the {turn} start failed (exit code {done.returncode}: {last})"
            times.append(time.perf_counter() - began)
    return times, ""


def render_ms(vertices: int = RENDER_VERTICES, frames: int = RENDER_FRAMES,
              size: tuple[int, int] = (1280, 720)) -> float:
    """The mean time of a frame (technique 2, its poses moving) of the procedural test face at
    ``vertices`` vertices, drawn offscreen as ``bench`` draws."""
    from studio.bench.configs import Config
    from studio.bench.poses import bench_project
    from studio.bench.runner import time_configurations
    from studio.render.gl_info import create_standalone_context

    ctx = create_standalone_context()
    try:
        config = Config("t2", 0, vertices)
        result = time_configurations(ctx, [bench_project(config)], [config], frames, size)
        return result[0].mean_ms
    finally:
        ctx.release()


def lines() -> list[str]:
    """The figures as lines for ``setup.md`` and the command line."""
    times, why = start_seconds()
    out = []
    if len(times) == 2:
        out.append(f"first start on a fresh user folder, to the first frame of the sample: "
                   f"{times[0]:.1f} s; a later start: {times[1]:.1f} s")
    else:
        out.append(f"the studio's start was not timed: {why}")
    from studio.core.files.errors import StudioError

    try:
        out.append(f"a frame of the {RENDER_VERTICES}-vertex test face (technique 2, "
                   f"1280×720): {render_ms():.1f} ms")
    except StudioError as exc:  # no OpenGL here: the set-ups' figures stand without it
        out.append(f"the {RENDER_VERTICES}-vertex frame was not timed: {exc}")
    return out
