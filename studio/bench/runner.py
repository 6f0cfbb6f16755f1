"""Times the studio's per-frame work for each configuration: interpolate the key poses,
recompute normals and tangents (in the configuration's tangent frame), upload what changed,
draw, and wait for the GPU to finish; and, apart, the main thread's CPU time of all of it but
the wait. A configuration this driver cannot draw is skipped, with the reason."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import moderngl
import numpy as np

from studio.bench.areas import benchmark_areas
from studio.bench.configs import Config
from studio.bench.poses import bench_animation
from studio.core.animation.poses import PoseBlender
from studio.core.animation.timeline import Timeline
from studio.core.files.errors import StudioError
from studio.core.mesh.geometry import DeformCache
from studio.core.project.model import Project
from studio.core.project.view_settings import ViewSettings
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import render_settings


@dataclass
class Result:
    config: Config
    width: int
    height: int
    frame_ms: np.ndarray  # one entry per frame
    deform_ms: float  # mean CPU time of a frame's deformation (see deformation_cpu_ms)
    cpu_ms: np.ndarray  # per frame: the main thread's CPU time, the wait for the GPU left out

    @property
    def mean_ms(self) -> float:
        return float(self.frame_ms.mean())

    @property
    def fps(self) -> np.ndarray:
        return 1000.0 / self.frame_ms

    def row(self) -> dict:
        fps = self.fps
        c = self.config
        return {"technique": c.technique, "areas": c.areas, "vertices": c.vertices,
                "width": self.width, "height": self.height, "frames": len(self.frame_ms),
                "mean_ms": round(self.mean_ms, 3), "fps_mean": round(float(fps.mean()), 2),
                "fps_min": round(float(fps.min()), 2), "fps_max": round(float(fps.max()), 2),
                "fps_std": round(float(fps.std()), 2), "deform_ms": round(self.deform_ms, 3),
                "relief": c.relief, "draw": c.draw, "poses": c.poses, "frame": c.frame,
                "cpu_ms": round(float(self.cpu_ms.mean()), 3), "look": c.look}


def deformation_cpu_ms(project: Project, timeline: Timeline, frames: int, frame: str,
                       warmup: int = 3) -> np.ndarray:
    """CPU time (ms, this thread) of the deformation of each of ``frames`` frames of the
    animation in which the face moves: the key-pose weights at the frame, the blend, and normals
    + tangents in ``frame`` (frames that hold a pose are not deformed again, so not counted):
    the numpy path, whichever path the renderer takes. Timed apart from
    drawing, as CPU time, so that neither the GL driver's threads nor other processes on a shared
    machine count."""
    cycle = [timeline.weights_at(f) for f in range(timeline.end)]
    moving = [f for f in range(timeline.end) if cycle[f] != cycle[f - 1]] or range(timeline.end)
    blender = PoseBlender(project.mesh.rest, project.poses)
    cache = DeformCache(project.mesh, frame)
    times = np.empty(frames)
    for i in range(-warmup, frames):
        start = time.thread_time()
        cache.update(blender.blend(timeline.weights_at(moving[i % len(moving)])))
        if i >= 0:
            times[i] = (time.thread_time() - start) * 1000.0
    return times


PASSES = 4  # each configuration's frames come in this many turns, interleaved with the others


class _Timed:
    """One configuration set up to draw: its own project copy, renderer and animation."""

    def __init__(self, ctx: moderngl.Context, project: Project, config: Config,
                 size: tuple[int, int]) -> None:
        if config.technique == "t1":
            poses = [p.name for p in project.poses]
            project.influence = benchmark_areas(project.influence, config.areas, poses)
        self.ctx, self.project, self.config, self.size = ctx, project, config, size
        self.timeline = bench_animation(project, config)
        self.studio = OffscreenStudio(project, *size, samples=0, ctx=ctx)
        self.studio.renderer.split_draws = config.draw == "split"
        # the tangent frame recomputed as the face moves: the user's default, or the thesis's
        self.settings = render_settings(ViewSettings(technique=config.technique,
                                                     relief=config.relief,
                                                     tangent_frame=config.frame,
                                                     look=config.look))
        self.times: list[float] = []
        self.cpu: list[float] = []
        self._frame = 0

    def run(self, frames: int, warmup: int) -> None:
        """Draw ``warmup`` untimed frames, then time ``frames`` more, continuing the animation:
        each frame is the wall-clock time of the studio's per-frame work, from the pose weights
        to the GPU having finished drawing, and the main thread's CPU time of it up to the draw
        submitted. Raises what the renderer raises where the driver cannot draw it."""
        studio, timeline = self.studio, self.timeline
        for i in range(warmup + frames):
            start, cpu_start = time.perf_counter(), time.thread_time()
            studio.scene.set_pose_weights(timeline.weights_at(self._frame % timeline.end))
            studio.renderer.render(studio.target.fbo, studio.camera, self.settings)
            cpu = time.thread_time() - cpu_start
            self.ctx.finish()
            if i >= warmup:
                self.times.append((time.perf_counter() - start) * 1000.0)
                self.cpu.append(cpu * 1000.0)
            self._frame += 1

    def result(self) -> Result:
        deform = deformation_cpu_ms(self.project, self.timeline, len(self.times),
                                    self.config.frame)
        return Result(self.config, *self.size, np.array(self.times), float(deform.mean()),
                      np.array(self.cpu))


def time_configurations(ctx: moderngl.Context, projects: Sequence[Project],
                        configs: Sequence[Config], frames: int, size: tuple[int, int],
                        passes: int = PASSES, warmup: int = 3,
                        skipped: Callable[[Config, str], None] | None = None) -> list[Result]:
    """Run ``frames`` frames of the thesis's evaluation animation (each pose in turn) for each
    configuration, with its own copy of the project. The frames come in ``passes`` turns that
    go round all the configurations, each turn starting at another one, so that a slow spell
    of a shared machine, or a drift through a turn, falls on all of them alike rather than on
    whichever ran then: the ratios between them are what is judged. A configuration the driver
    cannot draw (relief "displace" below OpenGL 4.0, say) is left out and reported to
    ``skipped`` with the reason; the others are timed all the same."""
    timed: list[_Timed] = []

    def drop(config: Config, exc: Exception, t: _Timed | None = None) -> None:
        if t is not None:
            timed.remove(t)
            t.studio.release()
        if skipped is not None:
            text = str(exc).strip()
            skipped(config, text.splitlines()[0] if text else repr(exc))

    try:
        for project, config in zip(projects, configs, strict=True):
            try:
                timed.append(_Timed(ctx, project, config, size))
            except (StudioError, moderngl.Error) as exc:
                drop(config, exc)
        for k, turn in enumerate(np.array_split(np.arange(frames), passes)):
            start = k * len(timed) // passes  # each turn starts further on: no configuration
            for t in timed[start:] + timed[:start]:  # is always first or last in a turn
                if len(turn):  # a frame untimed after the others ran: their caches are warm
                    try:
                        t.run(len(turn), warmup if k == 0 else 1)
                    except (StudioError, moderngl.Error) as exc:
                        drop(t.config, exc, t)
        return [t.result() for t in timed]
    finally:
        for t in timed:
            t.studio.release()
