"""What an artist turns to shape synthesised furrows: depth, spacing and sharpness, for all poses
and per pose, how soon along a pose's weight its lines appear (its onset), and the record of
which wrinkled maps were synthesised from which poses.

The controls are factors on what the synthesis grows from each pose's strain
(``studio.core.setup.wrinkle_synth``): 1 everywhere is exactly the look the blind review scored
best, so a project without controls (every file made before them) keeps its maps. A pose's
factors are the product of the "all poses" ones and its own, as Substance Painter multiplies a
layer's opacity by its folder's. A map is made again from its record (``SynthesisedMap``) when a
control of one of its poses changes, so the record keeps the size-independent options it was
made with; ``digest`` tells a map still as synthesised from one the user replaced since (loaded
from a file, painted elsewhere), which the controls must not overwrite.

The onset is not a factor on the map but on the pose's weight as the wrinkles see it: from 0
(today's behaviour, lines from the first movement) to ``MAX_ONSET``, the weight below which the
pose shows no lines; above it the lines grow over the rest of the weight
(``studio.core.wrinkles.response.onset_weight``), in every technique. A pose's onset on top of
all poses' composes as two such remaps do, ``1 - (1 - a)(1 - b)``.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

# (least, most) of each control: a furrow can vanish (depth 0) but never invert; spacing and
# sharpness stay within what the profile and the phase can draw without aliasing
# the onset stops short of 1: a pose fully on still shows a sliver of its lines
MAX_ONSET = 0.95
RANGES = {"depth": (0.0, 4.0), "spacing": (0.25, 4.0), "sharpness": (0.25, 4.0),
          "onset": (0.0, MAX_ONSET)}
LABELS = {"depth": "Depth", "spacing": "Spacing", "sharpness": "Sharpness", "onset": "Onset"}
# the controls that shape the synthesised maps (the onset shapes when they show, not the maps)
MAP_CONTROLS = ("depth", "spacing", "sharpness")


def _factor(value: Any, name: str) -> float:
    """``value`` as a float within ``RANGES[name]``, or ValueError naming the control."""
    low, high = RANGES[name]
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value) or not low <= value <= high:
        raise ValueError(f"{name} must be a number from {low:g} to {high:g}")
    return float(value)


@dataclass(frozen=True)
class FurrowControls:
    """Factors on a pose's synthesised furrows: 1 = as synthesised."""

    depth: float = 1.0  # × the furrows' depth (and so their walls' tilt, up to MAX_TILT)
    spacing: float = 1.0  # × the distance between neighbouring furrows
    sharpness: float = 1.0  # × the valley profile's exponent: narrower furrows, flatter skin
    onset: float = 0.0  # the pose's weight below which its lines do not show

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _factor(getattr(self, f.name), f.name))

    @property
    def is_default(self) -> bool:
        return self == DEFAULT

    def times(self, other: FurrowControls) -> FurrowControls:
        """These factors applied on top of ``other``'s (a pose's on the "all poses" ones); the
        onsets as one weight remap after the other."""
        factors = {n: min(max(getattr(self, n) * getattr(other, n), RANGES[n][0]), RANGES[n][1])
                   for n in MAP_CONTROLS}
        onset = 1.0 - (1.0 - self.onset) * (1.0 - other.onset)
        return FurrowControls(**factors, onset=min(onset, MAX_ONSET))

    @property
    def shape(self) -> FurrowControls:
        """Only what shapes the maps (the onset at its default): what a map is made with."""
        return replace(self, onset=0.0)

    def to_dict(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in RANGES}

    @classmethod
    def from_dict(cls, doc: Any) -> FurrowControls:
        if not isinstance(doc, dict):
            raise ValueError("must be a JSON object")
        unknown = set(doc) - set(RANGES)
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]} is not a furrow control")
        return cls(**doc)


DEFAULT = FurrowControls()


def map_digest(image: np.ndarray) -> str:
    """A short fingerprint of a map's pixels: whether it is still the one synthesised."""
    data = np.ascontiguousarray(image)
    return hashlib.blake2b(data.tobytes() + str((data.dtype, data.shape)).encode(),
                           digest_size=12).hexdigest()


@dataclass(frozen=True)
class SynthesisedMap:
    """How a wrinkled map was synthesised: enough to make it again with other controls."""

    poses: tuple[str, ...]
    spacing: float  # texels between furrows at the map's size, before the controls
    depth: float  # texels, before the controls
    anatomy: bool = True  # anatomy placed the primary lines (``new --auto``'s maps)
    digest: str = ""  # ``map_digest`` of the map as last synthesised
    over_neutral: bool = True  # laid over the neutral map's detail (the Synthesise dialog's
    # choice; the set-up's maps always are)

    def to_dict(self) -> dict[str, Any]:
        return {"poses": list(self.poses), "spacing": self.spacing, "depth": self.depth,
                "anatomy": self.anatomy, "digest": self.digest,
                "over_neutral": self.over_neutral}

    @classmethod
    def from_dict(cls, doc: Any) -> SynthesisedMap:
        if not isinstance(doc, dict):
            raise ValueError("must be a JSON object")
        poses, digest, anatomy = doc.get("poses"), doc.get("digest", ""), doc.get("anatomy", True)
        over_neutral = doc.get("over_neutral", True)
        if not isinstance(poses, list) or not all(isinstance(p, str) for p in poses):
            raise ValueError("poses must be a list of pose names")
        for name in ("spacing", "depth"):
            value = doc.get(name)
            if isinstance(value, bool) or not isinstance(value, int | float) \
                    or not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} must be a positive number")
        if not isinstance(digest, str) or not isinstance(anatomy, bool) \
                or not isinstance(over_neutral, bool):
            raise ValueError("digest must be text, anatomy and over_neutral true or false")
        return cls(tuple(poses), float(doc["spacing"]), float(doc["depth"]), anatomy, digest,
                   over_neutral)


@dataclass(eq=False)
class FurrowSettings:
    """The project's furrow controls and its synthesised maps' records."""

    all: FurrowControls = DEFAULT  # "All poses"
    poses: dict[str, FurrowControls] = field(default_factory=dict)  # a pose's own, if any
    maps: dict[str, SynthesisedMap] = field(default_factory=dict)  # map name -> its record

    def of(self, pose: str) -> FurrowControls:
        """The factors a pose's furrows are made with: its own on top of all poses'."""
        return self.poses.get(pose, DEFAULT).times(self.all)

    def onsets(self, poses: Iterable[str]) -> np.ndarray:
        """(P,) float64: each pose's combined onset, in the order given."""
        return np.array([self.of(p).onset for p in poses], dtype=np.float64).reshape(-1)

    def maps_of(self, pose: str | None) -> list[str]:
        """The synthesised maps a change of ``pose``'s controls remakes (None: all poses)."""
        return [name for name, record in self.maps.items()
                if pose is None or pose in record.poses]

    def controls(self, pose: str | None) -> FurrowControls:
        """The controls the artist set for ``pose`` (None: all poses), not combined."""
        return self.all if pose is None else self.poses.get(pose, DEFAULT)

    def with_controls(self, pose: str | None, controls: FurrowControls) -> FurrowSettings:
        """A copy with ``pose``'s (None: all poses') controls replaced. It shares the maps'
        records: they follow the maps (each remade map's digest), not the controls, so the
        settings an undo brings back know the map the controls made since."""
        if pose is None:
            return replace(self, poses=dict(self.poses), all=controls)
        poses = {k: v for k, v in self.poses.items() if k != pose}
        if not controls.is_default:
            poses[pose] = controls
        return replace(self, poses=poses)

    def with_values(self, values: Mapping[str | None, Mapping[str, float]]) -> FurrowSettings:
        """A copy with controls set by name, {pose (None: all poses): {control: value}}, the
        others kept (the command line's flags); ValueError naming a bad one."""
        out = self
        for pose, changes in values.items():
            current = out.controls(pose).to_dict()
            out = out.with_controls(pose, _named(lambda d: FurrowControls(**d),
                                                 {**current, **changes},
                                                 pose or "all poses"))
        return out

    def with_map(self, name: str, record: SynthesisedMap) -> FurrowSettings:
        """A copy with the named map's record added or replaced (a map just synthesised)."""
        return replace(self, maps={**self.maps, name: record})

    def pruned(self, poses: Iterable[str], maps: Iterable[str]) -> FurrowSettings:
        """A copy without the controls of poses, and the records of maps, that are gone
        (renamed or deleted since): what a project file keeps."""
        poses, maps = set(poses), set(maps)
        return FurrowSettings(self.all, {k: v for k, v in self.poses.items() if k in poses},
                              {k: v for k, v in self.maps.items() if k in maps})

    def to_dict(self) -> dict[str, Any]:
        """JSON form; empty when nothing was synthesised and nothing set."""
        doc: dict[str, Any] = {}
        if not self.all.is_default:
            doc["all"] = self.all.to_dict()
        if self.poses:
            doc["poses"] = {pose: c.to_dict() for pose, c in self.poses.items()}
        if self.maps:
            doc["maps"] = {name: record.to_dict() for name, record in self.maps.items()}
        return doc

    @classmethod
    def from_dict(cls, doc: Any) -> FurrowSettings:
        """What ``to_dict`` wrote; ValueError naming the field ("poses.smile.depth …")."""
        if not isinstance(doc, dict):
            raise ValueError("must be a JSON object")
        unknown = set(doc) - {"all", "poses", "maps"}
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]} is not a field of the furrow settings")
        out = cls()
        if "all" in doc:
            out.all = _named(FurrowControls.from_dict, doc["all"], "all")
        for key, parse, target in (("poses", FurrowControls.from_dict, out.poses),
                                   ("maps", SynthesisedMap.from_dict, out.maps)):
            entries = doc.get(key, {})
            if not isinstance(entries, dict):
                raise ValueError(f"{key} must be a JSON object")
            for name, value in entries.items():
                target[name] = _named(parse, value, f"{key}.{name}")
        return out


def _named(parse, value: Any, where: str):
    try:
        return parse(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None
