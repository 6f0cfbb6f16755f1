"""What the UV paint canvas shows, as numpy arrays and words, with no Qt in it.

Why apart from the canvas: how masks are tinted over the map, where the overlap view turns red
or dark, which wireframe edges are drawn and what the hint line says are the canvas's rules;
here they are plain arrays and strings, tested in milliseconds, and ``uv_canvas.py`` only puts
them into graphics items (napari's model and view).

Scene units are mask pixels: x right, y down (v = 1 is the top row, as in every image editor).
"""

from __future__ import annotations

import numpy as np

OVERLAY_ALPHA = 0.7
OVER_RGBA = (255, 40, 40, 170)
NONE_RGBA = (0, 0, 0, 120)  # a dark veil where no area reaches
DEFAULT_SIZE = (1024, 1024)  # the canvas of a project without areas (width, height)


def mask_size(resolution: tuple[int, int] | None) -> tuple[int, int]:
    """The canvas's (width, height) in mask pixels, from the masks' (rows, columns)."""
    return (resolution[1], resolution[0]) if resolution else DEFAULT_SIZE


def rgb8(rgb: np.ndarray) -> np.ndarray:
    """A texture as contiguous 8-bit RGB for display (16-bit maps are shown at 8 bits)."""
    if rgb.dtype == np.uint16:
        rgb = (rgb >> 8).astype(np.uint8)
    return np.ascontiguousarray(rgb[:, :, :3])


def masks_rgba(masks: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """Premultiplied RGBA of (n, h, w) masks tinted by their (n, 3) colours: each pixel the
    masks' colours weighted by their values, as opaque as the strongest mask allows."""
    n, h, w = masks.shape
    out = np.zeros((h, w, 4), np.uint8)
    if not n:
        return out
    total = masks.sum(axis=0)
    alpha = np.clip(masks.max(axis=0), 0.0, 1.0) * OVERLAY_ALPHA
    rgb = np.tensordot(masks, colours.astype(np.float32), axes=(0, 0)) \
        / np.maximum(total, 1e-6)[..., None]
    out[..., :3] = np.rint(rgb * alpha[..., None]).astype(np.uint8)
    out[..., 3] = np.rint(alpha * 255.0).astype(np.uint8)
    return out


def overlap_rgba(over: np.ndarray, none: np.ndarray) -> np.ndarray:
    """Premultiplied RGBA of the overlap view: red where the weighted masks pass 1, a dark veil
    where no area reaches (red wins where both)."""
    out = np.zeros((*over.shape, 4), np.uint8)
    for where, (r, g, b, a) in ((none, NONE_RGBA), (over, OVER_RGBA)):
        out[where] = (r * a // 255, g * a // 255, b * a // 255, a)
    return out


def overlap_activations(activations: np.ndarray, visible: list[bool]) -> np.ndarray:
    """The current activations, or every shown area at 1 while the face is neutral (so a
    conflict shows before any pose is set)."""
    if activations.any():
        return activations
    return np.array([1.0 if v else 0.0 for v in visible], np.float32)


def uv_points(uvs: np.ndarray, width: int, height: int) -> np.ndarray:
    """UVs as scene pixels (v up in the file, y down on the canvas)."""
    return np.c_[uvs[:, 0] * width, (1.0 - uvs[:, 1]) * height].astype(float)


def outline_edges(triangles: np.ndarray) -> np.ndarray:
    """(E, 2) the edges of a set of triangles that only one of them uses: the outline of
    each piece they make, without the edges inside it."""
    e = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                triangles[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    return edges[counts == 1]


def brush_hint(area: str | None, erase: bool, radius: float, mirror: str | None,
               overlap: bool) -> str:
    """The line under the canvas: what a drag paints, and how to move around. ``mirror`` is
    the mirror mode's label (None when off)."""
    if area is None:
        return "No area selected: add or select one in the Areas panel."
    text = f"{'Eraser' if erase else 'Brush'} on “{area}” · radius {radius:.0f} px · "
    if mirror is not None:
        text += f"mirror {mirror.lower()} · "
    text += "wheel zoom, middle/Space-drag pan, [ ] size, X eraser, F fit"
    if overlap:
        text += " · red: Σ mask·activation > 1, dark: no area"
    return text
