"""Undoable timeline edits: keys, interpolation, range, frame rate and quick set-ups.

Why snapshots: a timeline is a few dozen numbers, so each command records the whole timeline
before and after (an immutable ``TimelineState``). Undo can then never drift out of step with a
key that was re-sorted, merged or deleted, and a drag that passes over other keys restores them
exactly. A drag is one undo step: every move of one gesture shares a merge key and is computed
from the state at the press, not from the previous move.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from studio.core.animation.timeline import (
    INTERPOLATIONS,
    Key,
    KeyTuple,
    Timeline,
    Track,
    insert_key,
    sequence_all_poses,
)
from studio.widgets.commands import ValueCommand
from studio.widgets.document import Document

KeyRef = tuple[str, int]  # (pose, index of the key in its track, frame order)
# a copied key: (pose, frame relative to the first copied key, value, interpolation)
ClipKey = tuple[str, float, float, str]


@dataclass(frozen=True)
class TimelineState:
    """An immutable copy of a timeline, comparable, for undo."""

    fps: float
    start: int
    end: int
    tracks: tuple[tuple[str, tuple[KeyTuple, ...]], ...]

    @classmethod
    def of(cls, timeline: Timeline) -> TimelineState:
        return cls(float(timeline.fps), int(timeline.start), int(timeline.end),
                   tuple((t.pose, tuple((float(k.frame), float(k.value), k.interpolation)
                                        for k in t.keys)) for t in timeline.tracks))

    def apply_to(self, timeline: Timeline) -> None:
        """Make ``timeline`` (the project's own object, shared by every view) equal to this."""
        timeline.fps, timeline.start, timeline.end = self.fps, self.start, self.end
        timeline.tracks = [Track(pose, [Key(*k) for k in keys]) for pose, keys in self.tracks]

    def keys(self, pose: str) -> tuple[KeyTuple, ...]:
        return next((keys for p, keys in self.tracks if p == pose), ())

    def with_keys(self, changed: dict[str, list[KeyTuple]]) -> TimelineState:
        """This state with some tracks' keys replaced (sorted; new tracks appended)."""
        tracks = [(p, tuple(sorted(changed.pop(p), key=lambda k: k[0])) if p in changed else keys)
                  for p, keys in self.tracks]
        tracks += [(p, tuple(sorted(keys, key=lambda k: k[0]))) for p, keys in changed.items()]
        return TimelineState(self.fps, self.start, self.end, tuple(tracks))


def _merge_frame(keys: list[KeyTuple], new: KeyTuple) -> list[KeyTuple]:
    """``keys`` plus ``new``; a key already on that frame gives way (one key per frame)."""
    return [k for k in keys if abs(k[0] - new[0]) > 1e-6] + [new]


class TimelineEdits:
    """The timeline edits of one document, each pushed onto its undo stack."""

    def __init__(self, doc: Document) -> None:
        self.doc = doc

    @property
    def timeline(self) -> Timeline:
        return self.doc.project.timeline

    def state(self) -> TimelineState:
        return TimelineState.of(self.timeline)

    def _apply(self, state: TimelineState) -> None:
        state.apply_to(self.timeline)
        self.doc.timelineChanged.emit()
        self.doc.show_frame(self.doc.frame)  # the face follows the edited animation

    def push(self, text: str, new: TimelineState, gesture: int | None = None) -> bool:
        """Push the change to ``new``; False (nothing pushed) when it changes nothing."""
        if new == self.state():
            return False
        key = None if gesture is None else ("timeline", text, gesture)
        self.doc.undo_stack.push(ValueCommand(text, self.state, self._apply, new, key))
        return True

    # --- keys ----------------------------------------------------------------------------------
    def add_key(self, pose: str, frame: float, value: float | None = None,
                interpolation: str | None = None) -> KeyRef:
        """A key on ``pose`` at ``frame``, with the weight the person set (by default the one
        the track has there); the rest of the curve keeps its shape (``insert_key``): a key
        past the last one does not hold its weight to the end."""
        state = self.state()
        keys = list(state.keys(pose))
        track = Track(pose, [Key(*k) for k in keys])
        if value is None:
            value = track.value_at(frame) if keys else 1.0
        if interpolation is None:
            before = [k for k in keys if k[0] <= frame]
            interpolation = before[-1][2] if before else (keys[0][2] if keys else "cosine")
        key = (float(frame), float(min(max(value, 0.0), 1.0)), interpolation)
        new = state.with_keys({pose: insert_key(keys, key, state.start, state.end)})
        self.push(f"Add key {pose} @ {frame:g}", new)
        return pose, list(new.keys(pose)).index(key)

    def moved(self, base: TimelineState, refs: Iterable[KeyRef], frames: float,
              value: float = 0.0) -> tuple[TimelineState, list[KeyRef]]:
        """``base`` with the keys ``refs`` shifted by ``frames`` and ``value`` (clamped to 0..1);
        a moved key landing on another key's frame replaces it. Also returns where they went."""
        by_pose: dict[str, set[int]] = {}
        for pose, index in refs:
            by_pose.setdefault(pose, set()).add(index)
        changed: dict[str, list[KeyTuple]] = {}
        moved: dict[str, list[KeyTuple]] = {}
        for pose, indices in by_pose.items():
            keys = list(base.keys(pose))
            shifted = [(k[0] + frames, min(max(k[1] + value, 0.0), 1.0), k[2])
                       for i, k in enumerate(keys) if i in indices]
            kept = [k for i, k in enumerate(keys) if i not in indices]
            for key in shifted:
                kept = _merge_frame(kept, key)
            changed[pose], moved[pose] = kept, shifted
        new = base.with_keys(changed)
        return new, [(p, new.keys(p).index(k)) for p, ks in moved.items() for k in ks]

    def move_keys(self, base: TimelineState, refs: Sequence[KeyRef], frames: float,
                  value: float = 0.0, gesture: int | None = None) -> list[KeyRef]:
        """Move keys by an offset from ``base`` (the state when the drag began)."""
        new, where = self.moved(base, refs, frames, value)
        self.push("Move keys", new, gesture)
        return where

    def delete_keys(self, refs: Iterable[KeyRef]) -> None:
        state = self.state()
        drop: dict[str, set[int]] = {}
        for pose, index in refs:
            drop.setdefault(pose, set()).add(index)
        changed = {p: [k for i, k in enumerate(state.keys(p)) if i not in d]
                   for p, d in drop.items()}
        self.push("Delete keys", state.with_keys(changed))

    def copy_keys(self, refs: Iterable[KeyRef]) -> list[ClipKey]:
        """The keys as a clipboard: frames relative to the earliest copied key."""
        state = self.state()
        keys = [(p, *state.keys(p)[i]) for p, i in refs]
        if not keys:
            return []
        first = min(k[1] for k in keys)
        return [(p, f - first, v, m) for p, f, v, m in keys]

    def paste_keys(self, clip: Sequence[ClipKey], frame: float) -> list[KeyRef]:
        """Copied keys placed so that the earliest lands on ``frame``; keys there give way."""
        if not clip:
            return []
        state = self.state()
        changed: dict[str, list[KeyTuple]] = {}
        pasted: list[tuple[str, KeyTuple]] = []
        for pose, offset, value, mode in clip:
            key = (float(frame + offset), value, mode)
            changed[pose] = _merge_frame(changed.get(pose, list(state.keys(pose))), key)
            pasted.append((pose, key))
        new = state.with_keys(changed)
        self.push("Paste keys", new)
        return [(p, new.keys(p).index(k)) for p, k in pasted]

    def set_interpolation(self, refs: Iterable[KeyRef], mode: str) -> None:
        if mode not in INTERPOLATIONS:
            raise ValueError(f"unknown interpolation '{mode}'")
        self._set_field(refs, 2, mode, f"Interpolation {mode}")

    def set_value(self, refs: Iterable[KeyRef], value: float, gesture: int | None = None) -> None:
        self._set_field(refs, 1, float(min(max(value, 0.0), 1.0)), "Key weight", gesture)

    def _set_field(self, refs: Iterable[KeyRef], field: int, value, text: str,
                   gesture: int | None = None) -> None:
        state = self.state()
        changed: dict[str, list[KeyTuple]] = {}
        for pose, index in refs:
            keys = changed.setdefault(pose, list(state.keys(pose)))
            k = list(keys[index])
            k[field] = value
            keys[index] = (k[0], k[1], k[2])
        self.push(text, state.with_keys(changed), gesture)

    # --- range, frame rate, quick set-ups ------------------------------------------------------
    def set_range(self, fps: float | None = None, start: int | None = None,
                  end: int | None = None) -> bool:
        """Frame rate and frame range; refused (False) unless fps > 0 and end > start."""
        s = self.state()
        new = TimelineState(float(fps if fps is not None else s.fps),
                            int(start if start is not None else s.start),
                            int(end if end is not None else s.end), s.tracks)
        if not (new.fps > 0 and new.end > new.start):
            return False
        what = "Frame rate" if fps is not None else "Frame range"
        return self.push(what, new) or True

    def sequence_all_poses(self, poses: Sequence[str] | None = None, rise: float = 0.5,
                           hold: float = 0.5, fall: float = 0.5,
                           interpolation: str = "cosine") -> None:
        """Replace the animation by neutral → pose → neutral for each key pose in turn."""
        poses = list(poses if poses is not None else (p.name for p in self.doc.project.poses))
        made = sequence_all_poses(poses, self.timeline.fps, rise, hold, fall, interpolation)
        self.push("Sequence all poses", TimelineState.of(made))
