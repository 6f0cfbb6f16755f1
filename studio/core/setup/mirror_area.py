"""A technique-1 area made for the other side of the face: its mask mirrored through the mesh,
its name and its poses swapped to their paired side (``browDown_L`` → ``browDown_R``), so a mask
painted or generated on one side serves both."""

from __future__ import annotations

from dataclasses import dataclass

from studio.core.animation.pose_names import mirror_name, swapped_sides
from studio.core.files.naming import unique_name
from studio.core.project.model import Project
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.surface_mirror import SurfaceMirror, mirror_mask


@dataclass
class MirroredArea:
    area: InfluenceArea  # the new area, or the paired one with its new mask
    replaces: int | None  # index of the paired area it replaces; None: added after the source
    links: dict[str, float]  # pose -> gain, for the new area
    curves: dict[str, ResponseCurve]  # pose -> the response curve of that link (if not linear)


def mirrored_area(project: Project, index: int, mirror: SurfaceMirror) -> MirroredArea:
    """The area at ``index`` mirrored to the other side. An area named for one side becomes
    its pair (replacing an area of that name, if there is one); poses it follows become their
    pairs (a pose without one, such as ``browInnerUp``, keeps driving the copy)."""
    source = project.influence.areas[index]
    names = [a.name for a in project.influence.areas]
    paired = next(iter(swapped_sides(source.name)), None)
    replaces = names.index(paired) if paired in names else None
    name = paired if paired is not None else unique_name(f"{source.name} mirrored", names)
    mask = mirror_mask(source.mask, mirror)
    if replaces is not None:
        old = project.influence.areas[replaces]
        area = InfluenceArea(old.name, mask, old.colour, old.activation, old.visible,
                             old.wrinkle_map)
    else:
        area = InfluenceArea(name, mask, source.colour, source.activation, source.visible,
                             source.wrinkle_map)
    poses = project.pose_names
    links, curves = {}, {}
    for pose, gains in project.influence.links.items():
        if source.name in gains:
            paired_pose = mirror_name(pose, poses) or pose
            links[paired_pose] = gains[source.name]
            curve = project.influence.curves.get(pose, {}).get(source.name)
            if curve is not None:
                curves[paired_pose] = curve
    return MirroredArea(area, replaces, links, curves)
