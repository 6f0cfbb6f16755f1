"""What the Wrinkle vectors panel says, with no Qt in it: the poses an area may follow, each
area's summary, the selection count, and what Create, Suggest and the flat-map check report.

Why apart from the panel: these are the words a person reads to know what happened (how many
vectors were made, why some vertices got none); here they are plain strings, tested in
milliseconds, and ``panel.py`` only shows them (napari's model and view). The list's Solo and
Up/Down are ``studio/widgets/layer_list_model.py``'s.
"""

from __future__ import annotations

import numpy as np

from studio.core.animation.poses import NEUTRAL


def pose_choices(pose_names: list[str]) -> list[str]:
    """The poses an area may follow: every key pose but the neutral."""
    return [name for name in pose_names if name != NEUTRAL]


def area_tooltip(name: str, pose: str, authored: np.ndarray, cone_deg: float,
                 cone_angles: np.ndarray | None) -> str:
    """An area's row in the list: its pose, vectors and cone (and how many vertices have a
    painted cone of their own)."""
    painted = 0 if cone_angles is None else int((cone_angles > 0).sum())
    return (f"{name}: pose “{pose}”, {int(authored.sum())} vectors, cone {cone_deg:g}° "
            f"({painted} vertices painted). Double-click to rename; the check box mutes it")


def colour_text(colour: tuple[int, int, int]) -> str:
    return " #{:02x}{:02x}{:02x}".format(*colour)


def selection_text(selection: np.ndarray) -> str:
    return f"{int(selection.sum())} of {len(selection)} vertices selected"


def flat_text(name: str, reason: str | None, pose: str) -> str:
    """Why the current area shows nothing where its weight lands ("" when it does)."""
    if not reason:
        return ""
    return (f"“{name}” {reason} at “{pose}”: select where the map has wrinkles, or choose "
            "another map.")


def create_refused(area: str | None, selected: int) -> str:
    """Why Create cannot run ("" when it can)."""
    if area is None:
        return "Add an area first."
    if selected == 0:
        return "Select the vertices first (S, then drag over the face)."
    return ""


def created_text(selected: int, still: int, name: str, pose: str) -> tuple[str, bool]:
    """What Create did: how many vectors, and how many selected vertices the pose does not
    move (they get none: a warning)."""
    made = selected - still
    if still:
        return (f"{still} of the {selected} selected vertices do not move in “{pose}”, so they "
                f"got no direction; {made} vectors created."), True
    return f"{made} wrinkle direction vectors created for “{name}”.", False


def suggested_text(hits: np.ndarray, pose: str) -> str:
    return f"Suggested {int(hits.sum())} vertices that “{pose}” moves"
