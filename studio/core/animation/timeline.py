"""Key-pose animation: a track of keyframes per pose, evaluated at any frame.

Times are in frames (fractions allowed) at the timeline's frame rate. Each key's interpolation
mode shapes the way from that key to the next: linear, Parke's cosine, smooth (ease in/out), or
constant (hold until the next key).
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import ease, parke_cosine

INTERPOLATIONS = ("linear", "cosine", "smooth", "constant")


@dataclass
class Key:
    frame: float
    value: float  # the pose's weight, 0..1
    interpolation: str = "cosine"  # toward the next key

    def __post_init__(self) -> None:
        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f"unknown interpolation '{self.interpolation}'")


def _eased(f: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Eased fraction per sample; ``modes`` indexes INTERPOLATIONS."""
    return np.select(
        [modes == 0, modes == 1, modes == 2],
        [f, parke_cosine(f), f * f * (3.0 - 2.0 * f)],
        np.where(f >= 1.0, 1.0, 0.0),
    )


@dataclass
class Track:
    pose: str
    keys: list[Key] = field(default_factory=list)

    def sort(self) -> None:
        self.keys.sort(key=lambda k: k.frame)

    def values_at(self, frames: Sequence[float] | np.ndarray) -> np.ndarray:
        """The weight at each frame: held before the first key and after the last."""
        frames = np.asarray(frames, dtype=np.float64)
        if not self.keys:
            return np.zeros_like(frames)
        times = np.array([k.frame for k in self.keys])
        values = np.array([k.value for k in self.keys])
        modes = np.array([INTERPOLATIONS.index(k.interpolation) for k in self.keys])
        i = np.clip(np.searchsorted(times, frames, side="right") - 1, 0, len(times) - 1)
        j = np.minimum(i + 1, len(times) - 1)
        span = times[j] - times[i]
        f = np.where(span > 0, (frames - times[i]) / np.where(span > 0, span, 1.0), 0.0)
        f = np.clip(f, 0.0, 1.0)
        out = values[i] + _eased(f, modes[i]) * (values[j] - values[i])
        return np.where(frames < times[0], values[0], out)

    def value_at(self, frame: float) -> float:
        """One frame's weight, as ``values_at`` gives it, in plain Python: playback asks for
        one frame per track, where numpy's per-call overhead would dominate."""
        keys = self.keys
        if not keys:
            return 0.0
        frame = float(frame)
        if frame < keys[0].frame:
            return float(keys[0].value)
        i = max(bisect.bisect_right(keys, frame, key=lambda k: k.frame) - 1, 0)
        a, b = keys[i], keys[min(i + 1, len(keys) - 1)]
        span = b.frame - a.frame
        f = min(max((frame - a.frame) / span, 0.0), 1.0) if span > 0 else 0.0
        return float(a.value + ease(f, a.interpolation) * (b.value - a.value))


@dataclass
class Timeline:
    tracks: list[Track] = field(default_factory=list)
    fps: float = 24.0
    start: int = 0
    end: int = 96

    def track(self, pose: str) -> Track:
        """The pose's track, created empty if it has none."""
        for track in self.tracks:
            if track.pose == pose:
                return track
        track = Track(pose)
        self.tracks.append(track)
        return track

    def weights_at(self, frame: float) -> dict[str, float]:
        return {t.pose: t.value_at(frame) for t in self.tracks if t.keys}

    @property
    def has_keys(self) -> bool:
        return any(t.keys for t in self.tracks)

    def to_dict(self) -> dict:
        return {"fps": self.fps, "start": self.start, "end": self.end,
                "tracks": [{"pose": t.pose, "keys": [[k.frame, k.value, k.interpolation]
                                                      for k in t.keys]} for t in self.tracks]}

    @classmethod
    def from_dict(cls, data: dict) -> Timeline:
        """Raises ``ValueError``/``TypeError``/``KeyError`` on malformed data (callers wrap it)."""
        tracks = []
        for t in data.get("tracks", []):
            keys = [Key(float(f), float(v), str(m)) for f, v, m in t["keys"]]
            track = Track(str(t["pose"]), keys)
            track.sort()
            tracks.append(track)
        timeline = cls(tracks, float(data.get("fps", 24.0)), int(data.get("start", 0)),
                       int(data.get("end", 96)))
        if not (timeline.fps > 0 and timeline.end > timeline.start):
            raise ValueError("the timeline needs a positive frame rate and end after start")
        return timeline


KeyTuple = tuple[float, float, str]  # frame, value, interpolation toward the next key


def insert_key(keys: Sequence[KeyTuple], new: KeyTuple, start: float, end: float
               ) -> list[KeyTuple]:
    """``keys`` (in frame order) with ``new`` added as a local change: the curve keeps its
    shape away from the new key.

    Between two keys that is so by itself (each key shapes only the way to the next one). Past
    the last key a track holds that key's value to the end, so a new key there would hold *its*
    value to the end instead: the curve goes back to what it held, keyed at the frame range's
    end (and before the first key, from the range's start). A key on the frame of another
    replaces it; a key at the value the track already held needs no way back.
    """
    frame, value, mode = new
    kept = [k for k in keys if abs(k[0] - frame) > 1e-6]
    added = [new]
    after = kept[-1][1] if kept else 0.0  # what the track held past its last key (or 0)
    before = kept[0][1] if kept else 0.0
    if (not kept or frame > kept[-1][0]) and frame < end and abs(value - after) > 1e-9:
        added.append((float(end), after, mode))
    if (not kept or frame < kept[0][0]) and frame > start and abs(value - before) > 1e-9:
        added.append((float(start), before, mode))
    return sorted(kept + added, key=lambda k: k[0])


def sequence_all_poses(poses: Sequence[str], fps: float = 24.0, rise: float = 0.5,
                       hold: float = 0.5, fall: float = 0.5,
                       interpolation: str = "cosine") -> Timeline:
    """neutral → pose → neutral for each pose in turn, like the thesis's evaluation animation."""
    timeline = Timeline(fps=fps)
    frame = 0.0
    step = [round(s * fps) for s in (rise, hold, fall)]
    for pose in poses:
        keys = [Key(frame, 0.0, interpolation), Key(frame + step[0], 1.0, interpolation),
                Key(frame + step[0] + step[1], 1.0, interpolation),
                Key(frame + sum(step), 0.0, interpolation)]
        timeline.tracks.append(Track(pose, keys))
        frame += sum(step)
    timeline.end = max(int(frame), 1)
    return timeline
