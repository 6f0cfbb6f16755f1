"""What the viewport's gestures mean and what it says on the picture, with no Qt in it.

Why apart from the viewport: which mouse button and keys orbit, pan or zoom (Blender's
navigation), how far a drag turns the camera, where the split view's panes are and what the
picture says while it is drawn reduced are rules a person relies on; here they are plain values,
tested in milliseconds, and ``viewport.py`` only draws and forwards (napari's model and view).
"""

from __future__ import annotations

import itertools

from studio.core.wrinkles.techniques import SPLIT

ORBIT_DEGREES = 0.4  # per pixel of a drag
ZOOM_PER_PIXEL = 1.01  # a drag's zoom factor per pixel
WHEEL_ZOOM = 0.85  # the zoom factor of one wheel step
# numpad views: front (1), side (3; Ctrl: the other side) and top (7), as (yaw, pitch) degrees
NUMPAD_VIEWS = {"1": (0.0, 0.0), "3": (90.0, 0.0), "7": (0.0, 89.0)}


def split_columns(width: int) -> list[tuple[int, int]]:
    """x and width of each split-view pane."""
    edges = [round(width * i / len(SPLIT)) for i in range(len(SPLIT) + 1)]
    return [(a, b - a) for a, b in itertools.pairwise(edges)]


def navigation(button: str, shift: bool, ctrl: bool, alt: bool) -> str | None:
    """What a press starts: middle orbits, Shift+middle pans, Ctrl+middle zooms; on a laptop
    Alt+left orbits and Alt+Shift+left pans. None: the press is a tool's."""
    if button == "middle":
        if ctrl:
            return "zoom"
        return "pan" if shift else "orbit"
    if button == "left" and alt:
        return "pan" if shift else "orbit"
    return None


def camera_move(mode: str, dx: int, dy: int, height: int) -> tuple[str, tuple[float, ...]]:
    """The camera call and its arguments for a drag of ``dx, dy`` pixels in a view ``height``
    pixels tall (a pan moves the face with the pointer at any size)."""
    if mode == "orbit":
        return "orbit", (-dx * ORBIT_DEGREES, dy * ORBIT_DEGREES)
    if mode == "pan":
        return "pan", (-dx / max(height, 1), dy / max(height, 1))
    return "zoom", (ZOOM_PER_PIXEL ** dy,)


def numpad_view(key: str, ctrl: bool) -> tuple[float, float] | None:
    """The (yaw, pitch) a numpad key turns to (Ctrl+3: the other side); None for other keys."""
    view = NUMPAD_VIEWS.get(key)
    if view is not None and ctrl and key == "3":
        return -90.0, view[1]
    return view


def reduced_note(scale: object | None, full_size: bool, samples: int) -> str | None:
    """What the picture says while a moving frame is drawn at ``scale`` (None: a still
    frame; ``full_size``: the scale is 1), with ``samples`` the anti-aliasing a still frame
    uses. None: nothing a person would see is reduced."""
    if scale is not None and not full_size:
        return f"drawing at {scale} resolution while you move (software OpenGL)"
    if scale is not None and samples >= 2:
        return "drawing without anti-aliasing while you move (software OpenGL)"
    return None
