"""What the timeline panel shows and what its gestures mean, with no Qt in it.

Why apart from the panel: where a pose's row is, what weight a click at some height keys, which
frames the time axis shows, when the view pages after the playhead and which way a key drag
goes are rules a person relies on; here they are plain numbers, tested in milliseconds, and
``panel.py`` only draws them and turns gestures into calls (napari's model and view).

Rows are counted from the bottom (the first pose is the top row), one unit of the track view's
height each; a row's weight band (0..1) sits ``ROW_PAD`` in from its edges.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.timeline import INTERPOLATIONS, KeyTuple, Timeline
from studio.core.project.model import Project

ROW_PAD = 0.12  # empty part of a track row above and below its 0..1 band (row units)
ROW_BAND = 1.0 - 2 * ROW_PAD
VALUE_SNAP = 0.05
SNAP_PIXELS = 4.0  # a click this close to a row's baseline (or top) is weight 0 (or 1)
ROW_PIXELS = 32  # a row's height unless the user chose one: 0.05 of weight is over a pixel
ROW_PIXELS_RANGE = (18, 120)  # the heights a user may give the rows
FOLLOW_MARGIN = 0.05  # share of the shown time kept before the playhead when the view pages
DRAG_PIXELS = 4  # a key drag picks time or weight once it has moved this far
MAX_SAMPLES = 4000  # points of a drawn curve, however long the animation

KeyRef = tuple[str, int]  # (pose, index of the key in its track, frame order)


def clamp_row_pixels(pixels: float) -> int:
    """A row height within the range a user may choose."""
    return min(max(int(pixels), ROW_PIXELS_RANGE[0]), ROW_PIXELS_RANGE[1])


@dataclass
class TrackRows:
    """The track rows: which pose is where, and the weight a height in a row means."""

    poses: list[str] = field(default_factory=list)
    row_pixels: int = ROW_PIXELS

    def row_of(self, pose: str) -> int:
        """Row index from the bottom (the first pose is the top row)."""
        return len(self.poses) - 1 - self.poses.index(pose)

    def key_y(self, pose: str, value: float) -> float:
        """The height a key of ``value`` is drawn at in ``pose``'s row."""
        return self.row_of(pose) + ROW_PAD + ROW_BAND * value

    def pose_at(self, y: float) -> str | None:
        """The pose whose row holds height ``y`` (None outside the rows)."""
        row = int(np.floor(y))
        if not 0 <= row < len(self.poses):
            return None
        return self.poses[len(self.poses) - 1 - row]

    def value_at_y(self, y: float) -> float:
        """The weight a click at height ``y`` means: 0.05 steps, with the baseline (0) and the
        top (1) a few pixels wide, so a click on the drawn baseline is 0 at any row height."""
        value = (y - np.floor(y) - ROW_PAD) / ROW_BAND
        snap = SNAP_PIXELS / (self.row_pixels * ROW_BAND)
        value = 0.0 if value < snap else 1.0 if value > 1 - snap else value
        return float(np.clip(np.round(value / VALUE_SNAP) * VALUE_SNAP, 0.0, 1.0))

    def visible(self, lo: float, hi: float) -> list[str]:
        """The poses whose rows lie whole between heights ``lo`` and ``hi``, top first."""
        return [p for p in self.poses
                if lo - 1e-6 <= self.row_of(p) and self.row_of(p) + 1 <= hi + 1e-6]

    def fit(self, pixels: float) -> tuple[int, float]:
        """How many rows ``row_pixels`` tall fit whole in a view ``pixels`` high (at least
        one), and how many rows' worth of height it is."""
        shown = max(pixels / self.row_pixels, 1.0)
        return max(int(shown), 1), shown

    def shown_heights(self, shown: float, top: int) -> tuple[float, float]:
        """The heights a view ``shown`` rows high covers with ``top`` rows scrolled away above:
        the rows keep their height, empty space below the last (as in Blender's dope sheet)."""
        count = max(len(self.poses), 1)
        return count - top - shown, count - top

    def scrolled_to(self, pose: str, top: int, fit: int, most: int) -> int:
        """The first shown row once ``pose``'s row is brought into view (``top`` if it is)."""
        index = self.poses.index(pose)
        return top if top <= index < top + fit else min(index, most)

    def row_drag_rows(self, view_top: float, y: float) -> float:
        """A press in the names' column takes the row edge nearest ``y``: the rows above it."""
        return max(view_top - round(y), 1.0)


@dataclass(frozen=True)
class KeyMark:
    """One key as drawn: where, whether selected, and its shape (a held key is a square)."""

    ref: KeyRef
    frame: float
    y: float
    selected: bool
    held: bool


def key_marks(tracks: tuple[tuple[str, tuple[KeyTuple, ...]], ...], rows: TrackRows,
              selection: set[KeyRef]) -> list[KeyMark]:
    """Every key of the shown poses' tracks as drawn in the rows."""
    return [KeyMark((pose, i), frame, rows.key_y(pose, value), (pose, i) in selection,
                    mode == "constant")
            for pose, keys in tracks if pose in rows.poses
            for i, (frame, value, mode) in enumerate(keys)]


def time_span(timeline: Timeline) -> tuple[float, float]:
    """The frame range and every key beyond it."""
    frames = [k.frame for t in timeline.tracks for k in t.keys]
    return min([timeline.start, *frames]), max([timeline.end, *frames])


def framed_time(timeline: Timeline) -> tuple[float, float]:
    """The time axis that shows all of :func:`time_span` with a small margin (panning and
    zooming stop at its left end: nothing is ever before the first frame)."""
    lo, hi = time_span(timeline)
    margin = max(0.02 * max(hi - lo, 1), 1.0)
    return lo - margin, hi + margin


def sample_frames(timeline: Timeline) -> np.ndarray:
    """The frames the curves are drawn at: four a frame, ten frames past either end."""
    lo, hi = time_span(timeline)
    lo, hi = lo - 10, hi + 10
    return np.linspace(lo, hi, int(min((hi - lo) * 4, MAX_SAMPLES)) + 2)


def paged_start(lo: float, hi: float, frame: float) -> float | None:
    """Where the shown time starts once the playhead at ``frame`` has left ``lo..hi`` (playing,
    stepping, jumping): a page on, the playhead just inside. None while it is shown."""
    if lo <= frame <= hi:
        return None
    return frame - FOLLOW_MARGIN * (hi - lo)


def frame_in_range(timeline: Timeline, x: float) -> int:
    """The whole frame nearest ``x`` within the frame range (scrubbing, stepping)."""
    return int(min(max(round(x), timeline.start), timeline.end))


def frame_text(timeline: Timeline, frame: float) -> str:
    """The frame and its time from the start, as the panel shows them."""
    seconds = (frame - timeline.start) / timeline.fps
    return f"Frame {frame:.0f}   ·   {seconds:.2f} s"


def drag_axis(dx_pixels: float, dy_pixels: float) -> str | None:
    """The first clear movement of a key drag picks time or weight (None until it is clear)."""
    if max(dx_pixels, dy_pixels) < DRAG_PIXELS:
        return None
    return "time" if dx_pixels >= dy_pixels else "value"


def drag_offset(axis: str, dx: float, dy: float) -> tuple[float, float]:
    """Whole frames along time, or weight in 0.05 steps (rows' heights ``dy``) along weight."""
    if axis == "time":
        return float(round(dx)), 0.0
    return 0.0, float(np.round(dy / ROW_BAND / VALUE_SNAP) * VALUE_SNAP)


def clicked_selection(selection: set[KeyRef], hit: KeyRef, extend: bool) -> set[KeyRef]:
    """A click on a key selects it; with Ctrl or Shift it joins or leaves the selection."""
    return selection ^ {hit} if extend else {hit}


def shared_interpolation(keys: list[KeyTuple]) -> int:
    """The index of the selected keys' interpolation when they share one (-1: none, mixed)."""
    modes = {k[2] for k in keys}
    return INTERPOLATIONS.index(modes.pop()) if len(modes) == 1 else -1


def activation_curves(project: Project, frames: np.ndarray, base: dict[str, float]
                      ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Pose weights and technique-1 activations at many frames at once.

    Poses without keys keep their ``base`` weight (as ``Document.show_frame`` does); the
    activations are ``Project.activations_over`` — own value plus Σ gain·curve(weight),
    hidden areas at 0, clamped — for every frame at once instead of a call per frame.
    """
    timeline = project.timeline
    animated = {t.pose: t.values_at(frames) for t in timeline.tracks if t.keys}
    names = [p.name for p in project.poses]
    weights = np.stack([animated.get(n, np.full(len(frames), base.get(n, 0.0))) for n in names],
                       axis=1) if names else np.zeros((len(frames), 0))
    return animated, project.activations_over(names, weights)
