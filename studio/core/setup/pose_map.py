"""Which wrinkled map belongs to a pose: the map a new area for that pose should reveal.

Why: a face set up from its poses has several wrinkled maps (the sample: forehead lines for the
brow raise, glabellar lines for the frown, crow's feet for the squint, …). An area made for a
frown that reveals the first map shows forehead furrows between the brows. What the set-up
already decided says which map is the pose's; failing that, the map whose relief is strongest
under the area is the one whose furrows are there.
"""

from __future__ import annotations

import numpy as np

from studio.core.project.model import Project
from studio.core.wrinkles.flat_reveal import reveal_maps
from studio.core.wrinkles.influence import InfluenceArea


def wrinkle_map_for_pose(project: Project, pose: str, mask: np.ndarray) -> str:
    """The name of the wrinkled map for an area that ``pose`` drives, with ``mask``."""
    names = project.textures.wrinkle_map_names
    if len(names) <= 1:
        return names[0] if names else ""
    for area in project.wdv.areas:  # technique 2's area made for this pose
        if area.pose == pose and area.wrinkle_map in names:
            return area.wrinkle_map
    driven = project.influence.links.get(pose, {})
    for area in project.influence.areas:  # a mask this pose already drives
        if driven.get(area.name) and area.wrinkle_map in names:
            return area.wrinkle_map
    maps = reveal_maps(project.textures)

    def flat_share(name: str) -> float:
        reveal = maps.share(mask, name)
        return 1.0 if reveal is None else reveal.share

    return min(names, key=flat_share)  # (ties: the first, as before)


def map_on_link(project: Project, area: InfluenceArea, pose: str) -> str | None:
    """The map ``area`` should reveal once ``pose`` drives it, or None to keep its own: an
    area whose map nobody chose ("" = the first, the default of a new area) and that no pose
    drives yet reveals the pose's map, as Auto mask's areas do; a chosen map stays chosen."""
    if area.wrinkle_map or any(gains.get(area.name) for gains in
                               project.influence.links.values()):
        return None
    name = wrinkle_map_for_pose(project, pose, area.mask)
    return name or None
