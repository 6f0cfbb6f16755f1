"""Times the thesis's per-frame work for one configuration: interpolate the key poses, recompute
normals and tangents, upload what changed, draw, and wait for the GPU to finish."""

from __future__ import annotations

import time
from dataclasses import dataclass

import moderngl
import numpy as np

from studio.bench.areas import benchmark_areas
from studio.bench.configs import Config
from studio.core.geometry import DeformCache
from studio.core.poses import PoseBlender
from studio.core.project import Project
from studio.core.timeline import Timeline, sequence_all_poses
from studio.render.offscreen import OffscreenStudio
from studio.render.renderer import RenderSettings


@dataclass
class Result:
    config: Config
    width: int
    height: int
    frame_ms: np.ndarray  # one entry per frame
    deform_ms: float  # mean CPU time of a frame's deformation (see deformation_cpu_ms)

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
                "relief": c.relief}


def deformation_cpu_ms(project: Project, timeline: Timeline, frames: int,
                       warmup: int = 3) -> np.ndarray:
    """CPU time (ms, this thread) of the deformation of each of ``frames`` frames of the
    animation in which the face moves: the key-pose weights at the frame, the blend, and normals
    + tangents (frames that hold a pose are not deformed again, so not counted). Timed apart from
    drawing, as CPU time, so that neither the GL driver's threads nor other processes on a shared
    machine count."""
    cycle = [timeline.weights_at(f) for f in range(timeline.end)]
    moving = [f for f in range(timeline.end) if cycle[f] != cycle[f - 1]] or range(timeline.end)
    blender = PoseBlender(project.mesh.rest, project.poses)
    cache = DeformCache(project.mesh)
    times = np.empty(frames)
    for i in range(-warmup, frames):
        start = time.thread_time()
        cache.update(blender.blend(timeline.weights_at(moving[i % len(moving)])))
        if i >= 0:
            times[i] = (time.thread_time() - start) * 1000.0
    return times


def time_configuration(ctx: moderngl.Context, project: Project, config: Config, frames: int,
                       size: tuple[int, int], warmup: int = 3) -> Result:
    """Run ``frames`` frames of the thesis's evaluation animation (each pose in turn): the frame
    time is the wall-clock time of the studio's per-frame work, from the pose weights to the GPU
    having finished drawing."""
    if config.technique == "t1":
        poses = [p.name for p in project.poses]
        project.influence = benchmark_areas(project.influence, config.areas, poses)
    timeline = sequence_all_poses([p.name for p in project.poses], fps=24.0)
    studio = OffscreenStudio(project, *size, samples=0, ctx=ctx)
    settings = RenderSettings(technique=config.technique, relief=config.relief)
    times = np.empty(frames)
    try:
        for i in range(-warmup, frames):
            start = time.perf_counter()
            studio.scene.set_pose_weights(timeline.weights_at(i % timeline.end))
            studio.renderer.render(studio.target.fbo, studio.camera, settings)
            ctx.finish()
            if i >= 0:
                times[i] = (time.perf_counter() - start) * 1000.0
    finally:
        studio.release()
    deform = deformation_cpu_ms(project, timeline, frames)
    return Result(config, size[0], size[1], times, float(deform.mean()))
