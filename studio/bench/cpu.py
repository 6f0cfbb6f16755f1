"""The CPU side of a frame, part by part: ``python -m studio.bench.cpu [--vertices N] [--poses N]``.

``wrinkle-studio bench`` times whole frames (the GPU included); this prints what each piece of the
per-frame CPU work costs on the sample face, as medians of this thread's CPU time (other
processes sharing the machine do not count): the key-pose weights of a frame of the thesis's
animation, the blend, normals + tangents for the frames in which the face moves and for a frame in
which every vertex moves, and technique 1's activation vector with few and many areas.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable, Sequence

import numpy as np

from studio.bench.areas import benchmark_areas
from studio.bench.configs import Config
from studio.bench.poses import bench_animation, bench_project
from studio.core.animation.poses import PoseBlender
from studio.core.mesh.geometry import DeformCache


def _median_ms(step: Callable[[int], object], count: int, repeat: int) -> float:
    """Median CPU time of ``step(i)`` over ``repeat`` passes of ``i = 0 … count - 1``."""
    times = []
    for _ in range(repeat):
        for i in range(count):
            start = time.thread_time()
            step(i)
            times.append(time.thread_time() - start)
    return statistics.median(times) * 1000.0


def measure(vertices: int, repeat: int = 5, areas: Sequence[int] = (16, 256),
            poses: int = 0) -> dict[str, float]:
    """Median ms of each part of the per-frame CPU work on a sample face of ``vertices``; with
    ``poses``, for a capture take's animation of that many poses instead of the thesis's."""
    config = Config("none", 0, vertices, poses=poses)
    project = bench_project(config)
    timeline = bench_animation(project, config)
    poses_named = [p.name for p in project.poses]
    cycle = [timeline.weights_at(f) for f in range(timeline.end)]
    moving = [cycle[f] for f in range(timeline.end) if cycle[f] != cycle[f - 1]]
    blender = PoseBlender(project.mesh.rest, project.poses)
    cache = DeformCache(project.mesh, "thesis")
    mikk = DeformCache(project.mesh, "mikktspace")  # the viewport's default frame
    positions = [blender.blend(w).copy() for w in moving]
    rng = np.random.default_rng(0)
    shaken = [project.mesh.rest + rng.normal(0.0, 1e-3, project.mesh.rest.shape).astype("f4")
              for _ in range(2)]
    n = len(moving)
    result = {
        "timeline weights": _median_ms(lambda i: timeline.weights_at(i), timeline.end, repeat),
        "blend": _median_ms(lambda i: blender.blend(moving[i]), n, repeat),
        "normals + tangents, the face moving": _median_ms(
            lambda i: cache.update(positions[i]), n, repeat),
        "normals + tangents, every vertex moving": _median_ms(
            lambda i: cache.update(shaken[i % 2]), 20, repeat),
        "normals + MikkTSpace tangents, the face moving": _median_ms(
            lambda i: mikk.update(positions[i]), n, repeat),
        "normals + MikkTSpace tangents, every vertex moving": _median_ms(
            lambda i: mikk.update(shaken[i % 2]), 20, repeat),
    }
    for count in areas:
        influence = benchmark_areas(project.influence, count, poses_named)
        result[f"activations, {count} areas"] = _median_ms(
            lambda i, s=influence: s.activations(moving[i]), n, repeat)
    return result


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studio.bench.cpu", description=__doc__)
    parser.add_argument("--vertices", type=int, default=30000, help="sample face size (30000)")
    parser.add_argument("--repeat", type=int, default=5, help="passes over the animation (5)")
    parser.add_argument("--areas", type=int, nargs="+", default=[16, 256],
                        help="technique-1 area counts to time the activations with (16 256)")
    parser.add_argument("--poses", type=int, default=0,
                        help="time a capture take of this many ARKit poses, all moving (0: the "
                             "thesis's animation of the sample's own poses)")
    args = parser.parse_args(argv)
    for part, ms in measure(args.vertices, args.repeat, args.areas, args.poses).items():
        print(f"{part:<52}{ms:8.3f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
