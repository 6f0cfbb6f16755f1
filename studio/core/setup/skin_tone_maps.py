"""The set-up's cavity and colour maps (core/wrinkles/skin_tone.py) for the wrinkled maps it
synthesised: made with the furrows (``auto_setup``), and the cavity made again when the furrow
controls remake a map (``furrow_maps``), since a deeper furrow lies deeper in shadow. The
colour comes from the poses' strain, which the controls do not change."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from studio.core.project.model import Project
from studio.core.wrinkles.skin_tone import cavity_map, colour_map


def add_tone_maps(project: Project, made: Mapping[str, Sequence[str]]) -> None:
    """Give each synthesised map ({map: its poses}) its cavity and colour maps, in place."""
    textures = project.textures
    known = {p.name for p in project.poses}
    for name, poses in made.items():
        normal = textures.wrinkle_maps[name]
        targets = [project.pose(p).positions for p in poses if p in known]
        colour = colour_map(project.skin_mesh(), project.skin_weights(), targets,
                            *normal.shape[:2])
        textures.set_tone(name, cavity_map(textures.normal_neutral, normal), colour)


def remake_cavity(project: Project, names: Iterable[str]) -> None:
    """The cavity of each named map that has one, from the map as it is now."""
    textures = project.textures
    for name in names:
        if name in textures.cavity_maps:
            textures.set_tone(name, cavity_map(textures.normal_neutral,
                                               textures.wrinkle_maps[name]))
