"""The benchmark's faces and animations: the thesis's (each key pose in turn), and a capture take's
(every one of many poses changing every frame, as 52 ARKit curves from a phone do).

Why a case of its own: the thesis's animation moves one or two poses at a time, so the blend
reads one or two poses a frame and normals are recomputed only where the face moved; a capture
take moves every pose every frame, and the per-frame deformation must stay flat in pose count.
"""

from __future__ import annotations

import numpy as np

from studio.bench.configs import Config
from studio.core.animation.pose_names import ARKIT_NAMES
from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import Key, Timeline, Track, sequence_all_poses
from studio.core.project.model import Project
from studio.core.sample.synthetic import make_test_face

CAPTURE_FPS = 30.0
CAPTURE_FRAMES = 120  # four seconds of take: the animation loops


def with_arkit_poses(project: Project, count: int, seed: int = 5) -> Project:
    """``project`` with ``count`` key poses named as ARKit's shapes, each a different mix of the
    sample's own poses (so each moves much of the face, as a worst case), and none of its old
    animation."""
    rest = project.mesh.rest
    deltas = np.stack([p.positions - rest for p in project.poses])
    mix = np.random.default_rng(seed).uniform(0.0, 1.0, (count, len(deltas)))
    mix /= mix.sum(axis=1, keepdims=True)
    project.poses = [KeyPose(ARKIT_NAMES[k], rest + np.tensordot(mix[k], deltas, axes=1))
                     for k in range(count)]
    project.timeline = Timeline(fps=CAPTURE_FPS)
    return project


def capture_animation(poses: list[str], frames: int = CAPTURE_FRAMES,
                      fps: float = CAPTURE_FPS) -> Timeline:
    """A key on every frame of every pose, each pose's weight a sine of its own frequency and
    phase: no two consecutive frames share any pose's weight."""
    t = np.arange(frames + 1) / fps
    tracks = []
    for k, pose in enumerate(poses):
        values = 0.5 + 0.4 * np.sin(2.0 * np.pi * (0.5 + 0.05 * k) * t + k)
        tracks.append(Track(pose, [Key(float(f), float(v), "linear")
                                   for f, v in enumerate(values.tolist())]))
    return Timeline(tracks, fps, 0, frames)


def bench_project(config: Config) -> Project:
    """A fresh sample face for ``config``: its own poses, or ``config.poses`` ARKit ones."""
    project = make_test_face(config.vertices)
    return with_arkit_poses(project, config.poses) if config.poses else project


def bench_animation(project: Project, config: Config) -> Timeline:
    """The animation ``config`` is timed over (a still face: none, the neutral pose held)."""
    if config.still:
        return Timeline(fps=24.0, end=24)
    names = [p.name for p in project.poses]
    return capture_animation(names) if config.poses else sequence_all_poses(names, fps=24.0)
