"""What the Areas panel shows and what its fields mean, with no Qt in it.

Why apart from the panel: which poses drive the selected area, which can still be added, why an
area is flagged as showing nothing and the brush values kept between sessions are the panel's
rules; here they are plain values, tested in milliseconds, and ``areas_panel.py`` only shows
them and turns clicks into document edits (napari's model and view). The list's own rules
(Solo, Up/Down, the row kept selected) are ``studio/widgets/layer_list_model.py``'s.
"""

from __future__ import annotations

from studio.core.project.model import Project
from studio.core.wrinkles.influence import InfluenceArea

RADIUS_RANGE = (1.0, 1000.0)  # mask pixels
UNIT_RANGE = (0.0, 1.0)  # hardness, opacity, flow


def brush_setting(key: str, value: object, default: float) -> float:
    """A remembered brush value within its range (the radius in pixels, the rest 0..1); an
    unreadable one is ``default``."""
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return default
    if number != number:  # NaN
        return default
    lo, hi = RADIUS_RANGE if key == "radius" else UNIT_RANGE
    return min(max(number, lo), hi)


def scaled_radius(radius: float, factor: float) -> float:
    """The brush radius after ``[`` or ``]`` (a factor), within its range."""
    return float(min(max(radius * factor, RADIUS_RANGE[0]), RADIUS_RANGE[1]))


def linked_poses(project: Project, area: InfluenceArea | None) -> list[str]:
    """The poses that drive ``area`` (a non-zero link), in the project's pose order."""
    if area is None:
        return []
    links = project.influence.links
    return [p for p in project.pose_names if links.get(p, {}).get(area.name)]


def addable_poses(project: Project, linked: list[str]) -> list[str]:
    """What Add pose… offers: every key pose but the neutral (the first) and those linked."""
    return [p for p in project.pose_names[1:] if p not in linked]


def links_shown(project: Project, active: int, area: InfluenceArea | None) -> tuple | None:
    """What the links form shows; while it is the same, the form is updated in place (the
    field a person types in keeps its focus)."""
    if area is None:
        return None
    return (active, area.name, tuple(linked_poses(project, area)), tuple(project.pose_names),
            tuple(project.textures.wrinkle_map_names))


def flat_tooltip(name: str, reason: str) -> str:
    """The ⚠ beside an area whose weight lands on a flat part of its map ("" when not)."""
    if not reason:
        return ""
    return (f"{name} {reason}: its heat of the weight is hot, the picture does not change. "
            "Paint where the map has wrinkles, or choose another map")


def map_chosen_text(area: str, chosen: str | None, pose: str) -> str:
    """What linking a pose said about the map the area now reveals ("" when unchanged)."""
    if chosen is None:
        return ""
    return f"“{area}” reveals “{chosen}”, the map of {pose} (choose another under Wrinkled map)."
