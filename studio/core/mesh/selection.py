"""Selecting welded vertices for technique-2 authoring (numpy only, no loops over vertices).

The viewport projects the (posed) vertices to pixels once per gesture; everything here works on
those arrays, so a box, lasso or brush over a 30 000-vertex face costs a few milliseconds.
Visibility has two parts: a vertex must face the camera (its normal against the view
direction), and nothing may cover it (its depth against the depth buffer the face was drawn
with, or a CPU ray cast when there is no depth buffer and only a few candidates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.mesh.picking import ray_triangles

Array = np.ndarray

REPLACE, ADD, REMOVE = "replace", "add", "remove"


# --- regions of the screen -----------------------------------------------------------------------

def in_box(pixels: Array, corner_a: tuple[float, float], corner_b: tuple[float, float]) -> Array:
    """Pixels inside the rectangle spanned by two corners (any order)."""
    (x0, y0), (x1, y1) = corner_a, corner_b
    lo_x, hi_x = min(x0, x1), max(x0, x1)
    lo_y, hi_y = min(y0, y1), max(y0, y1)
    x, y = pixels[:, 0], pixels[:, 1]
    return (x >= lo_x) & (x <= hi_x) & (y >= lo_y) & (y <= hi_y)


def in_lasso(pixels: Array, polygon: Array) -> Array:
    """Pixels inside a closed polygon (even–odd rule). Loops over the polygon's edges only,
    each vectorised over all pixels; pixels outside its bounding box are skipped."""
    poly = np.asarray(polygon, np.float64).reshape(-1, 2)
    inside = np.zeros(len(pixels), dtype=bool)
    if len(poly) < 3:
        return inside
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    cand = np.flatnonzero((pixels[:, 0] >= lo[0]) & (pixels[:, 0] <= hi[0])
                          & (pixels[:, 1] >= lo[1]) & (pixels[:, 1] <= hi[1]))
    x, y = pixels[cand, 0], pixels[cand, 1]
    odd = np.zeros(len(cand), dtype=bool)
    ax, ay = poly[:, 0], poly[:, 1]
    bx, by = np.roll(ax, -1), np.roll(ay, -1)
    for x0, y0, x1, y1 in zip(ax, ay, bx, by, strict=True):
        if y0 == y1:
            continue
        crosses = (y0 > y) != (y1 > y)
        x_at = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        odd ^= crosses & (x < x_at)
    inside[cand] = odd
    return inside


def in_circle(pixels: Array, centre: tuple[float, float], radius: float) -> Array:
    """Pixels within ``radius`` of ``centre`` (the brush)."""
    d = pixels - np.asarray(centre, np.float64)
    return np.einsum("ij,ij->i", d, d) <= radius * radius


# --- visibility ----------------------------------------------------------------------------------

def front_facing(positions: Array, normals: Array, eye: Array) -> Array:
    """Vertices whose normal points toward the eye (the back of the head is never picked)."""
    to_eye = np.asarray(eye, np.float64) - positions
    return np.einsum("ij,ij->i", normals, to_eye) > 0.0


def linear_depth(window_depth: Array, near: float, far: float) -> Array:
    """View-space distance from a [0, 1] depth-buffer value of a perspective projection."""
    z = 2.0 * np.asarray(window_depth, np.float64) - 1.0
    return 2.0 * near * far / (far + near - z * (far - near))


def unoccluded(pixels: Array, view_depth: Array, depth_buffer: Array, near: float, far: float,
               tolerance: float) -> Array:
    """Vertices not hidden behind other surface, judged by the depth buffer (H, W, rows from the
    bottom as OpenGL reads them). A vertex passes when its depth is within ``tolerance`` of the
    farthest surface in its 3×3 pixel neighbourhood, which forgives rasterisation at edges."""
    h, w = depth_buffer.shape
    xi = np.clip(np.floor(pixels[:, 0]).astype(np.int64), 0, w - 1)
    yi = np.clip(h - 1 - np.floor(pixels[:, 1]).astype(np.int64), 0, h - 1)
    farthest = np.zeros(len(pixels))
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            d = depth_buffer[np.clip(yi + dy, 0, h - 1), np.clip(xi + dx, 0, w - 1)]
            farthest = np.maximum(farthest, d)
    surface = linear_depth(farthest, near, far)
    on_screen = (pixels[:, 0] >= 0) & (pixels[:, 0] < w) & (pixels[:, 1] >= 0) & (pixels[:, 1] < h)
    return on_screen & (view_depth <= surface + tolerance)


def unoccluded_by_rays(positions: Array, triangles: Array, eye: Array, candidates: Array,
                       tolerance: float) -> Array:
    """CPU fallback for a few candidates (no depth buffer): a ray from the eye to each one must
    not hit a triangle clearly in front of it. Costs one all-triangle ray cast per candidate."""
    eye = np.asarray(eye, np.float64)
    ok = np.zeros(len(candidates), dtype=bool)
    for k, v in enumerate(np.asarray(candidates)):
        to = positions[v] - eye
        dist = float(np.linalg.norm(to))
        hit = ray_triangles(eye, to / dist, positions, triangles)
        ok[k] = hit is None or hit.distance >= dist - tolerance
    return ok


@dataclass
class ScreenView:
    """The posed vertices as one camera sees them: enough to answer every selection gesture."""

    pixels: Array  # (W, 2) x right, y down
    depth: Array  # (W,) view depth
    facing: Array  # (W,) bool, normal toward the eye
    visible: Array  # (W,) bool, facing and not covered (all True with "select through")

    def select(self, region: Array, through: bool = False) -> Array:
        """The vertices inside a screen region mask that may be picked."""
        return region & (self.depth > 0.0) & (True if through else self.visible)


def screen_view(pixels: Array, depth: Array, positions: Array, normals: Array, eye: Array,
                depth_buffer: Array | None = None, near: float = 0.0, far: float = 0.0,
                tolerance: float = 0.0) -> ScreenView:
    """Visibility of every vertex; without a depth buffer only the facing test applies."""
    facing = front_facing(positions, normals, eye)
    visible = facing.copy()
    if depth_buffer is not None:
        visible &= unoccluded(pixels, depth, depth_buffer, near, far, tolerance)
    return ScreenView(pixels, depth, facing, visible)


def nearest_in_radius(view: ScreenView, x: float, y: float, radius: float,
                      through: bool = False) -> int | None:
    """The pickable vertex closest to a pixel, within ``radius`` pixels (click selection)."""
    ok = view.select(in_circle(view.pixels, (x, y), radius), through)
    idx = np.flatnonzero(ok)
    if len(idx) == 0:
        return None
    d = np.linalg.norm(view.pixels[idx] - (x, y), axis=1)
    return int(idx[np.argmin(d)])


def combine(current: Array, hits: Array, mode: str) -> Array:
    """New selection from the old one and a gesture's hits: replace, add (Shift) or remove
    (Ctrl)."""
    if mode == ADD:
        return current | hits
    if mode == REMOVE:
        return current & ~hits
    if mode == REPLACE:
        return hits.copy()
    raise ValueError(f"unknown selection mode '{mode}' (use replace, add or remove)")


# --- topology ------------------------------------------------------------------------------------

def edges(welded_triangles: Array) -> Array:
    """Unique undirected edges (E, 2) of a triangle mesh, smaller index first."""
    t = np.asarray(welded_triangles, np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    e.sort(axis=1)
    e = e[e[:, 0] != e[:, 1]]
    n = int(t.max(initial=0)) + 1
    key = np.unique(e[:, 0] * n + e[:, 1])  # 1-D unique is much faster than unique(axis=0)
    return np.c_[key // n, key % n]


def grow(selection: Array, mesh_edges: Array, steps: int = 1) -> Array:
    """Add every vertex that shares an edge with a selected one."""
    sel = np.asarray(selection, bool).copy()
    a, b = mesh_edges[:, 0], mesh_edges[:, 1]
    for _ in range(steps):
        nxt = sel.copy()
        nxt[a[sel[b]]] = True
        nxt[b[sel[a]]] = True
        sel = nxt
    return sel


def shrink(selection: Array, mesh_edges: Array, steps: int = 1) -> Array:
    """Drop every selected vertex that shares an edge with an unselected one (the border)."""
    return ~grow(~np.asarray(selection, bool), mesh_edges, steps)


def invert(selection: Array) -> Array:
    return ~np.asarray(selection, bool)


# --- symmetry ------------------------------------------------------------------------------------

def nearest_neighbours(points: Array, queries: Array) -> tuple[Array, Array]:
    """Index of and distance to the nearest point for every query, on a uniform grid.

    Each round searches the 27 cells around each query; a query whose best distance exceeds the
    cell size might have a closer point further out, so it is searched again with cells twice
    as large. Vectorised over queries; the loops run over cell offsets and cell occupancy.
    """
    pts = np.asarray(points, np.float64)
    qs = np.asarray(queries, np.float64)
    n = len(pts)
    best_i = np.full(len(qs), -1, np.int64)
    best_d = np.full(len(qs), np.inf)
    lo = np.minimum(pts.min(axis=0), qs.min(axis=0)) if len(qs) else pts.min(axis=0)
    hi = np.maximum(pts.max(axis=0), qs.max(axis=0)) if len(qs) else pts.max(axis=0)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    cell = diag / max(np.sqrt(n), 1.0)  # a surface: about one point per cell
    todo = np.arange(len(qs))
    offsets = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    while len(todo):
        pc = np.floor((pts - lo) / cell).astype(np.int64) + 1
        dims = pc.max(axis=0) + 3
        key = (pc[:, 0] * dims[1] + pc[:, 1]) * dims[2] + pc[:, 2]
        order = np.argsort(key, kind="stable")
        skey = key[order]
        q = qs[todo]
        qc = np.clip(np.floor((q - lo) / cell).astype(np.int64) + 1, 1, dims - 2)
        bi, bd = best_i[todo], best_d[todo]
        for off in offsets:
            c = qc + off
            qk = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
            start = np.searchsorted(skey, qk, "left")
            count = np.searchsorted(skey, qk, "right") - start
            for j in range(int(count.max(initial=0))):
                m = np.flatnonzero(count > j)
                cand = order[start[m] + j]
                d = np.linalg.norm(pts[cand] - q[m], axis=1)
                better = d < bd[m]
                bi[m[better]], bd[m[better]] = cand[better], d[better]
        best_i[todo], best_d[todo] = bi, bd
        again = bd > cell
        if cell >= diag * 2.0:
            break
        todo = todo[again]
        cell *= 2.0
    return best_i, best_d


def mirror_map(positions: Array, axis: int = 0, plane: float = 0.0) -> Array:
    """For each vertex, the vertex nearest to its reflection across the plane ``axis = plane``
    (x = 0 by default: the face's left–right symmetry)."""
    pts = np.asarray(positions, np.float64)
    reflected = pts.copy()
    reflected[:, axis] = 2.0 * plane - reflected[:, axis]
    index, _ = nearest_neighbours(pts, reflected)
    return index


def mirror(selection: Array, mirror_index: Array, keep: bool = True) -> Array:
    """The selection reflected across the symmetry plane; with ``keep`` the original stays
    (a symmetric selection), otherwise only the reflection remains."""
    sel = np.asarray(selection, bool)
    reflected = np.zeros_like(sel)
    reflected[mirror_index[sel]] = True
    return sel | reflected if keep else reflected


# --- suggestions ---------------------------------------------------------------------------------

def suggest(rest: Array, target: Array, fraction: float) -> Array:
    """Vertices the pose moves by more than ``fraction`` of its largest motion: where its skin
    folds, and so a starting point for the area's selection."""
    moved = np.linalg.norm(np.asarray(target, np.float64) - rest, axis=1)
    top = float(moved.max(initial=0.0))
    if top <= 0.0:
        return np.zeros(len(rest), dtype=bool)
    return moved > fraction * top
