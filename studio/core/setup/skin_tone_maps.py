"""The set-up's cavity and colour maps (core/wrinkles/skin_tone.py) for the wrinkled maps it
synthesised: made with the furrows (``auto_setup``), and the cavity made again when the furrow
controls remake a map (``furrow_maps``), since a deeper furrow lies deeper in shadow. The
colour comes from the poses' strain, which the controls do not change."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from studio.core.project.model import Project
from studio.core.setup.wrinkle_synth import UvRaster
from studio.core.wrinkles.skin_strain import SkinStrain
from studio.core.wrinkles.skin_tone import COLOUR_SIZE, cavity_map, colour_map, pose_strain

Array = np.ndarray


def add_tone_maps(project: Project, made: Mapping[str, Sequence[str]]) -> None:
    """Give each synthesised map ({map: its poses}) its cavity and colour maps, in place.
    Each pose's strain and the UV layout's raster are worked out once for all the maps."""
    textures = project.textures
    mesh = project.skin_mesh()
    strain = SkinStrain(mesh, project.skin_weights())
    known = {p.name for p in project.poses}
    strains = {p: pose_strain(strain, project.pose(p).positions)
               for poses in made.values() for p in poses if p in known}
    sizes = {min(COLOUR_SIZE, max(textures.wrinkle_maps[name].shape[:2])) for name in made}
    rasters = {size: UvRaster(mesh, size) for size in sizes}
    for name, poses in made.items():
        normal = textures.wrinkle_maps[name]
        raster = rasters[min(COLOUR_SIZE, max(normal.shape[:2]))]
        colour = colour_map([strains[p] for p in poses if p in strains], mesh.weld,
                            raster.image)
        textures.set_tone(name, cavity_map(textures.normal_neutral, normal), colour)


def cavities(project: Project, images: Mapping[str, Array]) -> dict[str, Array]:
    """The cavity maps of these new images of the named maps, for those that have one
    (off the GUI's thread: nothing in the project changes)."""
    neutral = project.textures.normal_neutral
    return {name: cavity_map(neutral, image) for name, image in images.items()
            if name in project.textures.cavity_maps}
