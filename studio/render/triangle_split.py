"""The face's index buffer in draw order: the triangles that can show wrinkles this frame first,
drawn with the technique's program, then the rest, drawn with the technique-off program (the
identical picture where the wrinkle weight is 0, at a fraction of the cost), each group nearest
first for the current view (see studio/core/mesh/draw_split.py), or in the mesh's own order for a
frame drawn small while the user moves (see ``order``). The buffer is rewritten only when the
split or the order changes, or the view turns by more than ``RESORT_DEGREES``."""

from __future__ import annotations

from collections.abc import Callable

import moderngl
import numpy as np

from studio.core.mesh.draw_split import (
    any_corner,
    boxes_touch,
    nearest_first,
    triangle_texel_boxes,
    wrinkled_first,
)

Array = np.ndarray
RESORT_DEGREES = 10.0  # how far the view turns before the triangles are sorted again


class TriangleSplit:
    """Which triangles each technique may wrinkle, and the index buffer ordered to match."""

    def __init__(self, ibo: moderngl.Buffer, triangles: Array, uvs: Array,
                 positions: Array) -> None:
        """``positions``: per render vertex, the neutral pose (for the depth order)."""
        self.ibo = ibo
        self.triangles = np.ascontiguousarray(triangles, np.int32)
        self.uvs = uvs
        self._centroids = positions[self.triangles].mean(axis=1)
        self._depth_order: Array | None = None  # nearest first along ``_sorted_for``
        self._sorted_for = np.zeros(3)  # view direction (world) the depth order was made for
        self._order_key: bytes | None = None  # the split the buffer is in
        self._wrinkled_count = len(self.triangles)
        self._skin = np.ones(len(self.triangles), bool)  # some corner may wrinkle at all
        self._has_slot = np.ones(len(positions), bool)  # per render vertex: a slot in use
        self._touch = np.zeros((0, len(self.triangles)), bool)  # technique 1: area × triangle
        self._texel_boxes: Array | None = None
        self._texel_size: tuple[int, int] = (0, 0)
        self._memo: dict[str, tuple[object, Array]] = {}  # technique: (key, triangles)

    # --- what can wrinkle ---------------------------------------------------------------------
    def set_skin(self, render_skin: Array) -> None:
        """Per render vertex skin weight: triangles with no skin corner never wrinkle."""
        self._skin = any_corner(self.triangles, np.asarray(render_skin) > 0)
        self._memo.clear()

    def set_slots(self, render_has_slot: Array) -> None:
        """Per render vertex: whether any technique-2 slot is in use."""
        self._has_slot = np.asarray(render_has_slot, bool)
        self._memo.clear()

    def set_area_boxes(self, boxes: Array, width: int, height: int) -> None:
        """Technique 1: each area's mask box (texels, see ``mask_boxes``) on a texture of this
        size."""
        if self._texel_size != (width, height) or self._texel_boxes is None:
            self._texel_boxes = triangle_texel_boxes(self.uvs, self.triangles, width, height)
            self._texel_size = (width, height)
        self._touch = boxes_touch(self._texel_boxes, np.asarray(boxes))
        self._memo.clear()

    def set_area_box(self, area: int, box: Array) -> None:
        """One area's box grew (a dab)."""
        self._touch[area] = boxes_touch(self._texel_boxes, np.asarray(box)[None])[0]
        self._memo.clear()

    def for_areas(self, activations: Array) -> Array:
        """Technique 1: (T,) the triangles some active area's mask box reaches. The same areas
        stay active over many frames of an animation, so the answer is kept."""
        active = activations[: len(self._touch)] > 0
        return self._remember("t1", np.packbits(active).tobytes(),
                              lambda: self._touch[active].any(axis=0) & self._skin)

    def for_slots(self, key: object, moved: Callable[[], Array]) -> Array:
        """Technique 2: the triangles with a corner that has a slot and has left the neutral
        pose (|delta| = 0 gives weight 0); ``moved()`` gives per render vertex whether it has,
        asked only when ``key`` (the pose's version) changed."""
        return self._remember("t2", key, lambda: any_corner(
            self.triangles, moved() & self._has_slot) & self._skin)

    def for_weights(self, key: object, weights: Callable[[], Array]) -> Array:
        """Per-vertex weights (the strain mode): the triangles with a corner above 0."""
        return self._remember("strain", key, lambda: any_corner(
            self.triangles, weights() > 0) & self._skin)

    def _remember(self, name: str, key: object, compute: Callable[[], Array]) -> Array:
        hit = self._memo.get(name)
        if hit is None or hit[0] != key:
            hit = self._memo[name] = (key, compute())
        return hit[1]

    # --- the index buffer ---------------------------------------------------------------------
    def set_view(self, view: Array, nearest_first_order: bool = True) -> None:
        """The camera of the next draw (4 × 4 world-to-view): sort again if it turned (and
        the next draw is in depth order)."""
        if not nearest_first_order:
            return
        forward = view[2, :3]
        if (self._depth_order is None
                or forward @ self._sorted_for < np.cos(np.radians(RESORT_DEGREES))):
            self._depth_order = nearest_first(self._centroids, view)
            self._sorted_for = forward.copy()
            self._order_key = None

    def order(self, wrinkled: Array | None, nearest_first_order: bool = True) -> int:
        """Put the buffer in the order for ``wrinkled`` (None: every triangle with one program)
        and return how many triangles lead it. ``nearest_first_order`` False keeps each group
        in the mesh's order: a small frame has few pixels to save from overdraw, and a
        renderer that shades vertices on the CPU (llvmpipe) reuses a shaded vertex only among
        neighbouring triangles, so the mesh's order drew the ICT head at 16 × 16 in 5 ms
        against 8 ms in depth order. The picture is the same (the depth test decides)."""
        if wrinkled is None:
            wrinkled = np.ones(len(self.triangles), bool)
        key = np.packbits(wrinkled).tobytes() + bytes([nearest_first_order])
        if key != self._order_key:
            depth_order = self._depth_order if nearest_first_order else None
            ordered, self._wrinkled_count = wrinkled_first(self.triangles, wrinkled,
                                                           depth_order)
            self.ibo.write(ordered.tobytes())
            self._order_key = key
        return self._wrinkled_count
