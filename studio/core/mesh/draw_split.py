"""Which triangles can show wrinkles this frame, so that the others are drawn with the plain
(technique-off) shading.

A renderer runs the whole wrinkle shading on every pixel the wrinkle program draws, whatever the
weight there (a software renderer runs both sides of every branch); where the weight is 0 the
technique-off program draws the identical picture for a fraction of the cost. A triangle can show
wrinkles only if its weight can be non-zero somewhere inside it: technique 2 and the strain mode
interpolate per-vertex weights, so a triangle whose corners all have weight 0 has none; technique
1 reads the composed weight texture, so a triangle whose UV footprint misses every active area's
mask has none. Image rows run top first (texture y = 1 - v), like the masks.

Either way the triangles are drawn nearest first for the current view: a renderer skips the
shading of a pixel already covered by something nearer (early depth test), so the draw order
matters as much as the split (13 % of a frame of the sample on llvmpipe).
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray


def triangle_texel_boxes(uvs: Array, triangles: Array, width: int, height: int,
                         pad: int = 1) -> Array:
    """(T, 4) int64 texel box x0, y0, x1, y1 (end exclusive, top row first) each triangle's UV
    footprint reads from a ``width`` × ``height`` texture, grown by ``pad`` texels for bilinear
    filtering."""
    corners = uvs[triangles]  # (T, 3, 2)
    x = corners[..., 0] * width
    y = (1.0 - corners[..., 1]) * height
    boxes = np.stack([np.floor(x.min(axis=1)) - pad, np.floor(y.min(axis=1)) - pad,
                      np.floor(x.max(axis=1)) + 1 + pad, np.floor(y.max(axis=1)) + 1 + pad],
                     axis=1)
    return boxes.astype(np.int64)


def boxes_touch(triangle_boxes: Array, area_boxes: Array) -> Array:
    """(A, T) bool: whether triangle t's texel box overlaps area a's box (end exclusive; an empty
    area box, x1 <= x0, touches nothing)."""
    t = triangle_boxes[None]
    a = area_boxes[:, None]
    return ((t[..., 0] < a[..., 2]) & (a[..., 0] < t[..., 2])
            & (t[..., 1] < a[..., 3]) & (a[..., 1] < t[..., 3])
            & (a[..., 2] > a[..., 0]))


def any_corner(triangles: Array, vertex_flags: Array) -> Array:
    """(T,) bool: triangles with at least one flagged corner (three column gathers: a quarter
    of the time of ``.any(axis=1)`` over a (T, 3) gather, for the frames where a pose moves)."""
    return (vertex_flags[triangles[:, 0]] | vertex_flags[triangles[:, 1]]
            | vertex_flags[triangles[:, 2]])


def moved(positions: Array, rest: Array) -> Array:
    """(V,) bool: vertices not exactly at their neutral position."""
    differs = positions != rest
    return differs[:, 0] | differs[:, 1] | differs[:, 2]


def nearest_first(centroids: Array, view: Array) -> Array:
    """Triangle order by distance along the view direction, nearest first (``view``: the 4 × 4
    world-to-view matrix; the camera looks down view-space -z)."""
    depth = -(centroids @ view[2, :3])
    return np.argsort(depth, kind="stable")


def wrinkled_first(triangles: Array, wrinkled: Array,
                   order: Array | None = None) -> tuple[Array, int]:
    """The triangles reordered with the wrinkled ones first, each group in ``order`` (default:
    mesh order), and how many are wrinkled."""
    if order is None:
        order = np.arange(len(triangles))
    in_order = wrinkled[order]
    order = np.concatenate([order[in_order], order[~in_order]])
    # whole rows as one opaque item each: a third of the time of a (T, 3) fancy index
    triangles = np.ascontiguousarray(triangles)
    rows = triangles.view(np.dtype((np.void, 3 * triangles.itemsize))).reshape(-1)
    reordered = np.take(rows, order).view(triangles.dtype).reshape(-1, 3)
    return reordered, int(np.count_nonzero(wrinkled))
