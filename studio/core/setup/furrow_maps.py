"""Synthesised wrinkled maps made again when their poses' furrow controls change, fast enough to
follow a slider.

A map's record (``FurrowSettings.maps``) names the poses it was synthesised from and the options;
laying one pose's furrows out (its strain, phase and anatomy's place) is the slow part, and only
its spacing changes it, so each pose's field is kept per spacing: a depth or sharpness drag, and
every other pose of the map, cost only the composition and the normal map. A map the user
replaced since it was synthesised (its ``digest`` no longer matches) is left alone.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from studio.core.project.model import Project
from studio.core.setup.anatomy import FacePlaces
from studio.core.setup.skin_tone_maps import cavities
from studio.core.setup.wrinkle_synth import (
    FurrowField,
    Progress,
    SynthOptions,
    face_places,
    grouped_maps,
    pose_fields,
)
from studio.core.wrinkles.furrow_controls import FurrowSettings, SynthesisedMap, map_digest

Array = np.ndarray
_Key = tuple[int, str, int, float, int, float, float, bool]  # see ``FurrowMaps._key``


class FurrowMaps:
    """Remakes one project's synthesised maps, keeping each pose's fields between calls."""

    def __init__(self) -> None:
        self._fields: dict[_Key, FurrowField] = {}
        self._made_with: dict[str, tuple] = {}  # map -> (its digest, its poses' controls)
        self._places: tuple[int, int, FacePlaces] | None = None  # the face's, by identity
        self._cavities: dict[str, tuple[Array, Array]] = {}  # map -> (image, its cavity)

    def adopt(self, project: Project) -> None:
        """Take the project's maps as made with its controls, as a project file holds them
        together: only a later change of a pose's controls makes its maps again (not every
        map, on the first change, to find it unchanged)."""
        self._made_with = {name: self._made_key(project, name) for name in project.furrows.maps}

    @staticmethod
    def _made_key(project: Project, name: str) -> tuple:
        record = project.furrows.maps[name]
        return record.digest, tuple(project.furrows.of(p).shape for p in record.poses)

    def pending(self, project: Project) -> dict[str, tuple]:
        """{map: what it is to be made with} for the synthesised maps whose poses' controls
        changed since they were last made (and that the user has not replaced since)."""
        out = {}
        for name in project.furrows.maps:
            key = self._made_key(project, name)
            if self._made_with.get(name) != key and self.is_synthesised(project, name):
                out[name] = key
        return out

    def make(self, project: Project, settings: FurrowSettings, names: Sequence[str],
             stop: Callable[[], bool] | None = None) -> dict[str, Array] | None:
        """The named maps as ``settings`` (a snapshot of the project's) make them. Nothing in
        the project changes, so the GUI runs this off its thread while the person drags on;
        None if ``stop`` said so (checked after each pose's furrows are laid out)."""
        out = {}
        for name in names:
            image = self.made(project, name, settings, stop)
            if stop is not None and stop():
                return None
            if image is not None:
                out[name] = image
        self._cavities.update({n: (out[n], c) for n, c in cavities(project, out).items()})
        return out

    def apply(self, project: Project, made: Mapping[str, tuple[Array, tuple]]) -> list[str]:
        """Put maps ``make`` made ({map: (image, what ``pending`` said it is made with)})
        into the project, unless the user replaced the map meanwhile; returns those that
        changed."""
        changed = []
        for name, (image, key) in made.items():
            if not self.is_synthesised(project, name):
                continue
            record = project.furrows.maps[name]
            old = project.textures.wrinkle_maps[name]
            if image.shape != old.shape or not np.array_equal(image, old):
                project.textures.set_wrinkle_map(name, image)
                record = replace(record, digest=map_digest(image))
                project.furrows.maps[name] = record
                changed.append(name)
            self._made_with[name] = (record.digest, key[1])
        for name in changed:  # made with it off the GUI's thread (``make``)
            image, cavity = self._cavities.pop(name, (None, None))
            if cavity is not None and image is made[name][0]:
                project.textures.set_tone(name, cavity=cavity)
        return changed

    def remake(self, project: Project, names: Sequence[str]) -> list[str]:
        """Make the named synthesised maps again with the current controls, in place (the
        texture and its record's digest), those whose controls changed only; returns those
        that changed."""
        todo = {n: k for n, k in self.pending(project).items() if n in names}
        made = self.make(project, project.furrows, list(todo)) or {}
        return self.apply(project, {n: (image, todo[n]) for n, image in made.items()})

    @staticmethod
    def is_synthesised(project: Project, name: str) -> bool:
        """Whether the named map has a record and is still the map last synthesised."""
        record = project.furrows.maps.get(name)
        image = project.textures.wrinkle_maps.get(name)
        return record is not None and image is not None and (
            not record.digest or map_digest(image) == record.digest)

    def made(self, project: Project, name: str, settings: FurrowSettings | None = None,
             stop: Callable[[], bool] | None = None) -> Array | None:
        """The named map as its record and the controls (``settings``, by default the
        project's) make it; None when it has no record, the map was replaced since it was
        synthesised, or ``stop`` said so."""
        if not self.is_synthesised(project, name):
            return None
        settings = settings or project.furrows
        size = int(project.textures.wrinkle_maps[name].shape[0])
        return self.draw(project, settings.maps[name], settings, size,
                         None if stop is None else lambda *_: not stop())

    def draw(self, project: Project, record: SynthesisedMap, settings: FurrowSettings,
             size: int, progress: Progress | None = None) -> Array | None:
        """A map of ``size`` texels as ``record`` and the controls in ``settings`` make it:
        the one way the set-up's maps, the Synthesise dialog's and every remake are drawn.
        None if ``progress`` (called with done, total) returned False."""
        known = {p.name for p in project.poses}
        poses = [p for p in record.poses if p in known]
        options = SynthOptions(size=size, spacing=record.spacing, depth=record.depth)
        controls = [settings.of(p) for p in poses]
        keys = [self._key(project, p, c.spacing, options, record.anatomy)
                for p, c in zip(poses, controls, strict=True)]
        missing = [i for i, key in enumerate(keys) if key not in self._fields]
        if missing:
            fields = pose_fields(project, [poses[i] for i in missing], options,
                                 [controls[i] for i in missing],
                                 places=self.places(project) if record.anatomy else None,
                                 progress=progress, anatomy=record.anatomy)
            if fields is None:
                return None
            for i, field in zip(missing, fields, strict=True):
                self._fields[keys[i]] = field
        fields = [self._fields[key] for key in keys]
        self._forget(keys)
        return grouped_maps(fields, controls, options, [list(range(len(fields)))],
                            project.textures.normal_neutral, record.over_neutral)[0]

    def took(self, project: Project, name: str) -> None:
        """The named map was just drawn with the project's controls (``draw``) and put in
        the project with its record: only a later change of its poses' controls remakes it."""
        self._made_with[name] = self._made_key(project, name)

    def places(self, project: Project) -> FacePlaces:
        """The face's places, found once per face (its mesh and not-face flags)."""
        skin = id(project.not_face)
        if self._places is None or self._places[:2] != (id(project.mesh), skin):
            self._places = (id(project.mesh), skin, face_places(project))
        return self._places[2]

    @staticmethod
    def _key(project: Project, pose: str, spacing: float, options: SynthOptions,
             anatomy: bool) -> _Key:
        """What a pose's field depends on: the face (its mesh and pose shape, by identity:
        a new import is a new object), the pose, the map's size and options, its spacing,
        whether anatomy places its lines."""
        return (id(project.mesh), pose, id(project.pose(pose).positions), spacing,
                options.size, options.spacing, options.depth, anatomy)

    def _forget(self, keep: Sequence[_Key]) -> None:
        """Drop the fields of these poses at spacings no longer in use (a drag's earlier
        ticks); other maps' poses keep theirs."""
        wanted = set(keep)
        poses = {key[1] for key in keep}
        for key in [k for k in self._fields if k not in wanted and k[1] in poses]:
            del self._fields[key]
