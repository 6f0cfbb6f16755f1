"""The timeline as a glTF morph-weight animation, and back.

Out: one ``animations`` entry whose single channel drives the mesh node's ``weights`` (glTF
allows one weights channel per node, so every key pose shares one sampler). The timeline is
*sampled*: at every frame from ``start`` to ``end`` and at every key in between, with LINEAR
interpolation between samples. Sampling is exact at frames and keys whatever the key's own
interpolation (cosine, smooth and constant have no glTF equivalent; CUBICSPLINE tangents could
fit cosine and smooth but not a constant's jump); between two frames a viewer interpolates
linearly, which at the project's frame rate is what the studio's own playback shows. Times are
seconds from ``start``.

Technique 1's per-area activations are not glTF-animatable properties (KHR_animation_pointer
targets only properties the specification or an extension defines, and an activation is
neither), so they ride in the animation's ``extras.wrinkleStudio``: the area names and one
value per area per sample, on the sampler's own time accessor. A reader that knows the studio
plays the same wrinkles; any other plays the same poses.

In: a file without the studio's own timeline (``extras.wrinkleStudio.timeline``; another tool
re-exported it) gets one back from its weights animation: a linear key per sample (STEP
samples become constant keys; CUBICSPLINE ones keep their values, linearly), so it plays the
same weights at every sample.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np

from studio.core.animation.timeline import Key, Timeline, Track
from studio.core.files.budgets import FRAMES, TIMELINE_KEYS
from studio.core.files.errors import MeshError

if TYPE_CHECKING:
    from studio.core.project.model import Project

Array = np.ndarray
EXTRAS_KEY = "wrinkleStudio"


class AccessorSink(Protocol):
    """What the glTF writer offers: a float accessor of rows, with bounds when asked, on a
    buffer view that is no vertex buffer when ``vertex`` is False."""

    def accessor(self, array: Array, kind: str, bounds: bool = False,
                 indices: bool = False, vertex: bool = True) -> int: ...


def sample_frames(timeline: Timeline) -> Array:
    """Every whole frame from start to end, and every key in that range, ascending, once."""
    whole = np.arange(timeline.start, timeline.end + 1, dtype=np.float64)
    keys = np.array([k.frame for t in timeline.tracks for k in t.keys], dtype=np.float64)
    keys = keys[(keys >= timeline.start) & (keys <= timeline.end)]
    return np.unique(np.concatenate([whole, keys]))


def pose_weights(timeline: Timeline, poses: Sequence[str], frames: Array) -> Array:
    """``(len(frames), len(poses))`` weights: each pose's track, 0 for a pose without one."""
    tracks = {t.pose: t for t in timeline.tracks if t.keys}
    out = np.zeros((len(frames), len(poses)))
    for j, pose in enumerate(poses):
        if pose in tracks:
            out[:, j] = tracks[pose].values_at(frames)
    return out


def animation_spec(project: Project, sink: AccessorSink, node: int = 0) -> dict | None:
    """The ``animations`` entry for the project's timeline (None when it has no keys or there
    are no morph targets to drive: a weights channel on a mesh without targets is invalid).
    The activations are the studio's own at each sample, the poses' onsets baked in."""
    timeline, influence = project.timeline, project.influence
    poses = [p.name for p in project.poses]
    if not poses or not timeline.has_keys:
        return None
    frames = sample_frames(timeline)
    weights = pose_weights(timeline, poses, frames)
    times = sink.accessor(((frames - timeline.start) / timeline.fps)[:, None], "SCALAR",
                          bounds=True, vertex=False)
    values = sink.accessor(weights.reshape(-1, 1), "SCALAR", vertex=False)
    values_by_frame = [project.activations(dict(zip(poses, row, strict=True)))
                       for row in weights.tolist()]
    by_area = np.array(values_by_frame, dtype=np.float64).reshape(len(frames), -1).T
    return {
        "name": "timeline",
        "channels": [{"sampler": 0, "target": {"node": node, "path": "weights"}}],
        "samplers": [{"input": times, "output": values, "interpolation": "LINEAR"}],
        "extras": {EXTRAS_KEY: {
            "fps": timeline.fps, "start": timeline.start, "end": timeline.end,
            "activations": {"input": times, "areas": [
                {"name": area.name, "values": [float(np.float32(v)) for v in values_]}
                for area, values_ in zip(influence.areas, by_area.tolist(), strict=True)]}}},
    }


def timeline_from_animation(doc: dict, node_of_mesh: int, pose_names: Sequence[str],
                            accessor: Callable[[int], Array], source: object = None
                            ) -> Timeline | None:
    """A timeline from the first animation with a weights channel on the mesh's node (None
    when there is none). ``accessor`` reads an accessor index as float rows; ``source`` names
    the file in the MeshError of an animation over the budgets (keys, frames), refused before
    its keys are made."""
    for animation in doc.get("animations", []):
        for channel in animation.get("channels", []):
            target = channel.get("target", {})
            if target.get("node") != node_of_mesh or target.get("path") != "weights":
                continue
            sampler = animation["samplers"][channel["sampler"]]
            studio = animation.get("extras", {}).get(EXTRAS_KEY, {})
            interpolation = str(sampler.get("interpolation", "LINEAR"))
            times = accessor(sampler["input"]).ravel()
            # the keys as Python objects, checked before the weights are read
            TIMELINE_KEYS.check(len(times) * len(pose_names), f"the morph-weight animation's "
                                f"keys ({len(times):,} samples × {len(pose_names)} key poses)",
                                source, MeshError)
            return _timeline(times, accessor(sampler["output"]).ravel(), interpolation,
                             pose_names, studio, source)
    return None


def _frame(value: object) -> int:
    """A frame number from the studio's extras (a number, or its text), refusing text of
    thousands of digits with plain words (``int`` would suggest changing a Python setting)."""
    if len(str(value)) > 40:
        raise ValueError(f"the frame number {str(value)[:20]}… is not a frame number")
    return int(value)  # type: ignore[call-overload]


def _timeline(times: Array, values: Array, interpolation: str, pose_names: Sequence[str],
              studio: dict, source: object = None) -> Timeline:
    n, p = len(times), len(pose_names)
    per_key = 3 if interpolation == "CUBICSPLINE" else 1  # (in-tangent, value, out-tangent)
    if len(values) != n * p * per_key:
        raise ValueError(f"the animation has {len(values):,} weights for {n:,} keys of {p} "
                         "key poses")
    weights = values.reshape(n, per_key, p)[:, per_key // 2]
    fps = float(studio.get("fps", 24.0))
    start = _frame(studio.get("start", 0))
    if not (0 < fps <= 1000 and abs(start) <= FRAMES.value):
        raise ValueError("the animation's frame rate or range is invalid")
    with np.errstate(over="ignore", invalid="ignore"):  # t = 3e38 s: checked just below
        # float32 seconds carry ~1e-5 of a frame of rounding: snap to a thousandth of a frame
        frames = np.round(start + times * fps, 3)
    with np.errstate(over="ignore", invalid="ignore"):
        last = float(np.max(np.abs(frames - start), initial=0.0))
    FRAMES.check(int(last), f"the morph-weight animation's length (a key at "
                 f"{float(np.max(np.abs(times), initial=0.0)):.3g} s, at {fps:g} fps)",
                 source, MeshError)
    mode = "constant" if interpolation == "STEP" else "linear"
    tracks = [Track(name, [Key(float(f), float(v), mode)
                           for f, v in zip(frames.tolist(), weights[:, j].tolist(), strict=True)])
              for j, name in enumerate(pose_names)]
    end = _frame(studio.get("end", max(int(np.ceil(frames.max())), start + 1)))
    FRAMES.check(end - start, "the morph-weight animation's frame range", source, MeshError)
    timeline = Timeline(tracks, fps, start, end)
    if not (timeline.fps > 0 and timeline.end > timeline.start):
        raise ValueError("the animation's frame rate or range is invalid")
    return timeline
