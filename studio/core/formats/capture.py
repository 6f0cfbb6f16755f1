"""Facial capture in: an ARKit blend-shape recording onto the timeline as keyed weight curves.

A take is a Live Link Face CSV file or a glTF animation of morph-target weights (its channels
targeting a mesh's ``weights``, the targets named by ``mesh.extras.targetNames``). Epic's Live
Link Face app writes a CSV file::

    Timecode,BlendShapeCount,EyeBlinkLeft,EyeLookDownLeft,…,TongueOut,HeadYaw,HeadPitch,…
    14:23:07:12.345,61,0.0213,0.1,…

one row per sample. The timecode is ``HH:MM:SS:FF.fff`` where ``FF.fff`` is a fractional frame
number at the take's frame rate, which the file does not state: like Epic's own importer, a take
whose frame numbers reach 30 was recorded at 60 fps, otherwise at 30. Besides the 52 ARKit shapes
the app writes head and eye rotations (``HeadYaw``, ``LeftEyePitch``, …), which are not blend
shapes: they are ignored and reported.

Columns are matched to the project's key poses through :mod:`studio.core.animation.pose_names`
(any ARKit spelling, sides as ``Left`` or ``_L``, case ignored; other names must agree apart from
case and separators). Each matched curve is resampled linearly to the timeline's frame rate and
keyed with linear keys, keeping only the keys the curve needs: a key is dropped where the
straight line between its neighbours stays within :data:`KEY_TOLERANCE` of every frame it spans,
so the keys reproduce the resampled curve within half an 8-bit step at every frame.

Everything a bad file can cause is a :class:`CaptureError` naming the file and, where there is
one, the line; sizes are checked against budgets before the work is done.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.animation.pose_names import canonical
from studio.core.animation.timeline import Key, Timeline, Track
from studio.core.files.budgets import FRAMES, Budget
from studio.core.files.errors import StudioError
from studio.core.files.safe_io import read_regular

Array = np.ndarray

#: Keys reproduce the resampled curve within this at every frame (half of 1/255).
KEY_TOLERANCE = 0.5 / 255.0
#: Rounds of key reduction; each halves at most the keys left, so a few dozen reach the end of
#: any real curve. A curve still reducible after them keeps a few more keys, never a wrong one.
_MAX_ROUNDS = 64
TIMECODE = "timecode"
SHAPE_COUNT = "blendshapecount"
# head and eye rotations Live Link Face writes after the blend shapes (radians, not weights)
_ROTATION = re.compile(r"^(head|lefteye|righteye)(yaw|pitch|roll)$", re.IGNORECASE)
_TIMECODE = re.compile(r"^\s*(\d+):(\d+):(\d+)[:;](\d+(?:\.\d*)?)\s*$")
_SECONDS_PER_DAY = 86400.0
RATE_60_FROM = 30.0  # a frame number this high cannot be at 30 fps

CAPTURE_BYTES = Budget("MAX_CAPTURE_BYTES", 256 << 20, "bytes")
CAPTURE_VALUES = Budget("MAX_CAPTURE_VALUES", 20_000_000, "values")


class CaptureError(StudioError):
    """A capture take that cannot be read or used."""


@dataclass(frozen=True)
class Take:
    """A recording: one curve per column, sampled at ``times``."""

    path: Path
    columns: tuple[str, ...]  # the value columns, in file order
    ignored: tuple[str, ...]  # head and eye rotations: not blend shapes
    times: Array  # (S,) seconds from the first sample, non-decreasing
    values: Array  # (S, C) float64, one column per entry of ``columns``
    rate: float  # the take's own frame rate (timecode frames per second); 0: none (glTF)

    @property
    def duration(self) -> float:
        return float(self.times[-1])


@dataclass(frozen=True)
class CaptureReport:
    """What an import did, for the command's output and the GUI's report dialog."""

    path: Path
    matched: tuple[tuple[str, str], ...]  # (column, pose)
    unmatched: tuple[str, ...]  # columns no pose takes
    ignored: tuple[str, ...]  # head and eye rotations
    missing: tuple[str, ...]  # poses without a column
    samples: int
    rate: float
    fps: float
    frames: int
    duration: float
    keys: int
    clipped: int  # values outside 0–1, clipped

    def lines(self) -> list[str]:
        rate = f" at {self.rate:g} fps" if self.rate else ""  # a glTF's keys have no rate
        out = [f"{self.path.name}: {self.samples} samples{rate}, "
               f"{self.duration:.3f} s → {self.frames} frames at {self.fps:g} fps, "
               f"{self.keys} keys on {len(self.matched)} tracks",
               f"matched ({len(self.matched)}): "
               + ", ".join(c if c == p else f"{c} → {p}" for c, p in self.matched)]
        if self.unmatched:
            out.append(f"columns without a pose ({len(self.unmatched)}): "
                       + ", ".join(self.unmatched))
        if self.ignored:
            out.append(f"ignored, not blend shapes ({len(self.ignored)}): "
                       + ", ".join(self.ignored))
        if self.missing:
            out.append(f"poses without a column ({len(self.missing)}), left as they were: "
                       + ", ".join(self.missing))
        if self.clipped:
            out.append(f"{self.clipped} values outside 0–1 were clipped")
        return out


# --- reading --------------------------------------------------------------------------------

def _text(path: Path) -> str:
    data = read_regular(path, CAPTURE_BYTES.value, CaptureError, "capture file",
                        CAPTURE_BYTES.setting)
    if not data.strip():
        raise CaptureError("the capture file is empty", path)
    if b"\0" in data:
        raise CaptureError("binary data, not a CSV text file", path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise CaptureError(f"not a CSV text file: byte {exc.start} is not UTF-8 text",
                           path) from None


def _header(row: list[str], path: Path) -> tuple[list[str], int]:
    """The stripped column names and the Timecode column's index."""
    names = [name.strip() for name in row]
    lowered = [name.lower() for name in names]
    if TIMECODE not in lowered:
        shown = ",".join(names[:3]) + ("…" if len(names) > 3 else "")
        raise CaptureError(f"no Timecode column (the header starts '{shown}'; a Live Link Face "
                           "take starts 'Timecode,BlendShapeCount,EyeBlinkLeft,…')", path)
    seen: set[str] = set()
    for name in lowered:
        if name in seen:
            raise CaptureError(f"the column '{names[lowered.index(name)]}' appears twice", path)
        if name == "":
            raise CaptureError("a column has no name", path)
        seen.add(name)
    return names, lowered.index(TIMECODE)


def _first_bad_number(cells: list[list[str]], first_line: list[int], columns: list[str],
                      path: Path) -> CaptureError:
    """The error for the first cell that is not a finite number (only searched on failure)."""
    for r, row in enumerate(cells):
        for c, cell in enumerate(row):
            try:
                ok = np.isfinite(float(cell))
            except ValueError:
                ok = False
            if not ok:
                return CaptureError(f"line {first_line[r]}, column '{columns[c]}': '{cell}' is "
                                    "not a finite number", path)
    return CaptureError("a value is not a number", path)


def read_live_link_csv(path: str | Path, rate: float | None = None) -> Take:
    """A Live Link Face CSV take; ``rate`` is the take's frame rate (inferred when None)."""
    path = Path(path)
    lines = _text(path).splitlines()
    reader = csv.reader(lines)
    try:
        header = next(row for row in reader if row)
    except csv.Error as exc:
        raise CaptureError(f"line {reader.line_num}: {exc}", path) from None
    names, tc = _header(header, path)
    kept = [i for i, n in enumerate(names) if i != tc and n.lower() != SHAPE_COUNT]
    CAPTURE_VALUES.check(len(lines) * len(names), "the take", path, CaptureError)
    timecodes: list[str] = []
    cells: list[list[str]] = []
    line_of: list[int] = []
    try:
        for row in reader:
            if not row or (len(row) == 1 and not row[0].strip()):
                continue  # blank lines (a trailing newline, a hand edit)
            if len(row) != len(names):
                raise CaptureError(f"line {reader.line_num} has {len(row)} values, the header "
                                   f"names {len(names)} columns", path)
            timecodes.append(row[tc])
            cells.append([row[i] for i in kept])
            line_of.append(reader.line_num)
    except csv.Error as exc:
        raise CaptureError(f"line {reader.line_num}: {exc}", path) from None
    if not cells:
        raise CaptureError("no samples: the file has a header but no rows", path)
    columns = [names[i] for i in kept]
    try:
        values = np.array(cells, dtype=np.float64).reshape(len(cells), len(kept))
    except ValueError:
        raise _first_bad_number(cells, line_of, columns, path) from None
    if not np.isfinite(values).all():
        raise _first_bad_number(cells, line_of, columns, path)
    times, rate = _timecodes(timecodes, line_of, rate, path)
    blend = [i for i, n in enumerate(columns) if not _ROTATION.match(n)]
    return Take(path, tuple(columns[i] for i in blend),
                tuple(n for n in columns if _ROTATION.match(n)), times,
                np.ascontiguousarray(values[:, blend]), rate)


def _timecodes(texts: list[str], line_of: list[int], rate: float | None,
               path: Path) -> tuple[Array, float]:
    """Seconds from the first sample, and the take's rate."""
    parts = []
    for text, line in zip(texts, line_of, strict=True):
        match = _TIMECODE.match(text)
        if match is None:
            raise CaptureError(f"line {line}: the timecode '{text}' is not HH:MM:SS:FF", path)
        parts.append(match.groups())
    hms_f = np.array(parts, dtype=np.float64)
    frame = hms_f[:, 3]
    if rate is None:
        rate = 60.0 if (frame >= RATE_60_FROM).any() else 30.0
    elif not (np.isfinite(rate) and rate > 0):
        raise CaptureError(f"the take's frame rate must be positive, not {rate:g}", path)
    over = np.flatnonzero(frame >= rate)
    if len(over):
        raise CaptureError(f"line {line_of[over[0]]}: frame {frame[over[0]]:g} of the timecode "
                           f"is not below the take's rate of {rate:g} fps", path)
    seconds = hms_f[:, 0] * 3600.0 + hms_f[:, 1] * 60.0 + hms_f[:, 2] + frame / rate
    step = np.diff(seconds)
    # a take recorded over midnight starts again from 00:00:00
    seconds[1:] += np.cumsum(step < -_SECONDS_PER_DAY / 2) * _SECONDS_PER_DAY
    back = np.flatnonzero(np.diff(seconds) < 0)
    if len(back):
        raise CaptureError(f"line {line_of[back[0] + 1]}: the timecode goes back in time "
                           f"(from {texts[back[0]]} to {texts[back[0] + 1]})", path)
    return seconds - seconds[0], float(rate)


# --- matching, resampling, keys -------------------------------------------------------------

def _squashed(name: str) -> str:
    return re.sub(r"[_.\-\s]", "", name).lower()


def match_columns(columns: Sequence[str], poses: Sequence[str]
                  ) -> tuple[list[tuple[str, str]], list[str], list[str]]:
    """(matched (column, pose) pairs, columns without a pose, poses without a column).

    A column and a pose match when they spell the same ARKit shape (``EyeBlinkLeft`` and
    ``eyeBlink_L``) or, for other names, agree apart from case and separators; each pose takes
    the first column that matches it.
    """
    by_key: dict[str, str] = {}
    for pose in poses:
        for key in (canonical(pose), _squashed(pose)):
            if key is not None:
                by_key.setdefault(key, pose)
    matched, unmatched, taken = [], [], set()
    for column in columns:
        known = canonical(column)
        pose = by_key.get(known) if known is not None else None
        pose = pose or by_key.get(_squashed(column))
        if pose is None or pose in taken:
            unmatched.append(column)
        else:
            matched.append((column, pose))
            taken.add(pose)
    return matched, unmatched, [p for p in poses if p not in taken]


def resample(times: Array, values: Array, fps: float) -> Array:
    """``values`` (S, C) sampled at ``times`` (seconds from 0), linearly interpolated at every
    frame ``0, 1/fps, 2/fps, …`` up to the last sample: (F, C)."""
    frames = int(np.floor(times[-1] * fps + 1e-9)) + 1
    at = np.arange(frames) / fps
    i = np.clip(np.searchsorted(times, at, side="right") - 1, 0, len(times) - 1)
    j = np.minimum(i + 1, len(times) - 1)
    span = times[j] - times[i]
    f = np.where(span > 0, (at - times[i]) / np.where(span > 0, span, 1.0), 0.0)
    return values[i] + f[:, None] * (values[j] - values[i])


def reduce_keys(curve: Array, tolerance: float = KEY_TOLERANCE) -> Array:
    """Frames (indices into ``curve``) to key so that straight lines between the keys stay
    within ``tolerance`` of ``curve`` at every frame; the first and last frames are always kept.

    Vectorised in rounds: each round tries every other kept key at once (alternating which, so
    no two tried keys are neighbours and each judgement holds whatever the others decide) and
    drops those whose neighbours' chord stays within the tolerance of every frame between them.
    """
    curve = np.asarray(curve, dtype=np.float64)
    keep = np.arange(len(curve))
    parity, idle = 1, 0
    for _ in range(_MAX_ROUNDS):
        if idle >= 2 or len(keep) <= 2:
            break
        tried = np.arange(1 + (parity == 0), len(keep) - 1, 2)
        parity ^= 1
        if not len(tried):
            idle += 1
            continue
        lo, hi = keep[tried - 1], keep[tried + 1]
        inner = hi - lo - 1  # frames strictly between the neighbours
        owner = np.repeat(np.arange(len(tried)), inner)
        start = np.cumsum(inner) - inner
        frame = lo[owner] + 1 + np.arange(len(owner)) - start[owner]
        t = (frame - lo[owner]) / (hi - lo)[owner]
        chord = curve[lo][owner] + t * (curve[hi] - curve[lo])[owner]
        worst = np.zeros(len(tried))
        np.maximum.at(worst, owner, np.abs(chord - curve[frame]))
        drop = tried[worst <= tolerance]
        idle = 0 if len(drop) else idle + 1
        keep = np.delete(keep, drop)
    return keep


def apply_take(timeline: Timeline, take: Take, poses: Sequence[str], fps: float | None = None
               ) -> tuple[Timeline, CaptureReport]:
    """A new timeline: ``timeline`` with the take's curves as the matched poses' tracks, at
    ``fps`` (default the timeline's own; other tracks' keys keep their times), starting at the
    timeline's start frame, its range the take's. Raises ``CaptureError`` when nothing matches."""
    fps = float(timeline.fps if fps is None else fps)
    if not (np.isfinite(fps) and 0 < fps <= 1000):
        raise CaptureError(f"the frame rate must be above 0 and at most 1000, not {fps:g}")
    matched, unmatched, missing = match_columns(take.columns, poses)
    if not matched:
        raise CaptureError("no column of the take names a key pose of the project (columns: "
                           f"{', '.join(take.columns[:8]) or 'none'}"
                           f"{'…' if len(take.columns) > 8 else ''}; poses: "
                           f"{', '.join(poses) or 'none'})", take.path)
    FRAMES.check(int(take.duration * fps) + 1, f"the take at {fps:g} fps", take.path,
                 CaptureError)
    index = {c: i for i, c in enumerate(take.columns)}
    raw = take.values[:, [index[c] for c, _ in matched]]
    clipped = int(np.count_nonzero((raw < 0.0) | (raw > 1.0)))
    curves = resample(take.times, np.clip(raw, 0.0, 1.0), fps)
    start = timeline.start
    scale = fps / timeline.fps
    replaced = {pose for _, pose in matched}
    tracks = [Track(t.pose, [Key(start + (k.frame - start) * scale, k.value, k.interpolation)
                             for k in t.keys]) for t in timeline.tracks if t.pose not in replaced]
    keys = 0
    for (_, pose), curve in zip(matched, curves.T, strict=True):
        frames = reduce_keys(curve)
        keys += len(frames)
        tracks.append(Track(pose, [Key(float(start + f), float(v), "linear")
                                   for f, v in zip(frames.tolist(), curve[frames].tolist(),
                                                   strict=True)]))
    new = Timeline(tracks, fps, start, start + max(len(curves) - 1, 1))
    report = CaptureReport(take.path, tuple(matched), tuple(unmatched), take.ignored,
                           tuple(missing), len(take.times), take.rate, fps, len(curves),
                           take.duration, keys, clipped)
    return new, report


GLTF_SUFFIXES = (".glb", ".gltf")


def read_gltf_take(path: str | Path) -> Take:
    """The morph-weight animation of a glTF file as a take: one column per morph target (named
    by the mesh's ``extras.targetNames``), its keys as samples, from its first key on."""
    from studio.core.formats.gltf.codec import load_weight_animation

    path = Path(path)
    names, times, values = load_weight_animation(path)
    if len(set(n.lower() for n in names)) != len(names):
        raise CaptureError("two morph targets of the animated mesh share a name", path)
    if np.any(np.diff(times) < 0):
        raise CaptureError("the animation's key times go back in time", path)
    return Take(path, tuple(names), (), times - times[0], values, 0.0)


def read_take(path: str | Path, rate: float | None = None) -> Take:
    """A take from a Live Link Face CSV or, by its suffix, a glTF morph-weight animation."""
    if Path(path).suffix.lower() in GLTF_SUFFIXES:
        return read_gltf_take(path)
    return read_live_link_csv(path, rate)


def import_capture(path: str | Path, timeline: Timeline, poses: Sequence[str],
                   fps: float | None = None, rate: float | None = None
                   ) -> tuple[Timeline, CaptureReport]:
    """Read the take at ``path`` and key it onto a copy of ``timeline`` (see ``apply_take``)."""
    return apply_take(timeline, read_take(path, rate), poses, fps)
