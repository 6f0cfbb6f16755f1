"""The eyes and the tip of the nose: which way a head looks, from its anatomy alone.

Pose names can be missing or misleading, a head's extents mislead when a neck, a ponytail or
a wide hairdo outgrows it, and a file's normals may point inward. A face's layout does not
depend on any of these: the eyes are a mirror-image pair on either side of the left–right
plane, the tip of the nose lies on that plane below them and in front of them, and it is the
skin's most protruding point there. So, with no assumption about the axes:

- **the left–right plane**: of the three model axes, the one across which the skin is most
  nearly its own mirror image (a head is symmetric left to right, never top to bottom or
  front to back);
- **the nose tip**: of the skin vertices near that plane, those that stand out furthest from
  the skin around them (the offset from the area-weighted mean of the surface within a
  radius, along the outward normal), away from open edges (a neck's cut rim stands out the
  same way); the most protruding that makes a face with a pair of eyes is the tip (where a
  coarse neck closes can stand out more);
- **the eyes**, from the first of these that gives a pair: parts the rig marks as not skin
  (eyeballs, with the lashes and shells around them; a row of teeth, tooth by tooth, merges
  into one arch across the middle), holes in the skin (the eye openings of a face whose eyes
  are separate meshes), or pits in a closed skin (the sockets: its most concave points). A
  pair mirrors itself across the plane, lies a face's proportions from the nose tip (0.4 to
  1.4 times its own width away: a jaw's or a neck's hollows are further), spans well under
  the head's width (not the hollows behind the ears) and, of several, is the widest (not the
  hollows beside the nostrils);
- **up** is the in-plane axis the eyes lie along from the nose, **front** the one the nose
  stands out toward and lies ahead of the eyes along; no skin near the nose tip lies ahead
  of it. Where any of this is unclear, nothing is claimed.

Every length is a share of the face's own size (the region the poses deform, else the skin).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

SYMMETRY_SAMPLE = 600  # points of the skin compared with their mirror image …
SYMMETRY_OTHERS = 20000  # … and the most points they are compared with (a dense head thinned)
NEAR_OTHERS = 8000  # the most points of an open edge that nearness to it is measured against
MIRROR_CLEAR = 0.6  # the left–right axis is this much more symmetric than the next axis …
SURFACE_SAMPLE = 10000  # surface points (area-weighted) the neighbourhood means are taken over
CANDIDATES = 3000  # skin vertices measured for pits, at most
MIDLINE = 800  # midline vertices measured for the nose tip, at most (evenly spread)
SPARE = 4  # of a dense head, this many times those spread evenly are looked at first
NOSE_TRIES = 5  # the most protruding midline points tried as the nose tip
LEADS = 0.1  # no skin near the nose tip is ahead of it by over this share of the eyes' distance
RADIUS = 0.05  # the neighbourhood a point stands out from: a share of the face's size
BAND = 0.02  # the midline: within this share of the face's size of the plane …
BAND_EDGES = 0.75  # … or of this many typical edge lengths (a coarse mesh's midline)
REACH = 1.2  # the features lie within this many face sizes of the face's centre
PART_SIZE = 0.5  # an eye (part, hole or pit) is under half the distance between the eyes
PAIR_TOLERANCE = 0.2  # one eye mirrored lies within this share of their distance of the other
EYES_TO_NOSE = (0.4, 1.4)  # the nose tip lies this many eye distances from their midpoint
ABOVE = 0.15  # the eyes are above the nose tip by this share of their distance at least …
AHEAD = 0.05  # … and the nose tip ahead of them by this share
FACING = 0.3  # the nose tip stands out toward the front: cosine with the front at least
SPAN = 0.65  # the eyes span at most this share of the skin's width around them
PAIRS_TRIED = 8  # eye pairs tried with each nose tip, nearest first
MERGE_MOST = 2000  # parts whose overlaps are found (hair cards beyond this stay apart)
CHUNK = 256  # points measured at once (memory: CHUNK × SURFACE_SAMPLE distances)


@dataclass(frozen=True)
class FaceFeatures:
    """The eyes and nose tip found, and the orientation they give (unit model axes)."""

    nose: Array  # (3,) the nose tip
    eyes: Array  # (2, 3) the eyes' centres, the +mirror-axis side first
    left_axis: int  # the model axis across the left–right plane
    plane: float  # where the plane lies along it
    up: Array  # (3,) the in-plane axis from the nose tip toward the eyes
    front: Array  # (3,) the in-plane axis the nose stands out toward, ahead of the eyes
    eyes_from: str  # "eye parts", "eye holes in the skin" or "eye sockets"


def asymmetry(points: Array, axis: Array) -> float:
    """How far the points are from mirror-symmetric across the plane at right angles to
    ``axis`` through their middle: the mean distance from a sample of them (at most
    ``SYMMETRY_SAMPLE``), mirrored, to the nearest of all of them — near nothing for a head
    across its left–right plane, whatever the mesh's resolution."""
    sample = points
    if len(points) > SYMMETRY_SAMPLE:
        sample = points[np.linspace(0, len(points) - 1, SYMMETRY_SAMPLE).astype(int)]
    along = sample @ axis
    mirrored = sample - 2.0 * np.outer(along - np.median(points @ axis), axis)
    return float(np.sqrt(_nearest2(mirrored, thinned(points, SYMMETRY_OTHERS))).mean())


def _nearest2(points: Array, others: Array) -> Array:
    """(N,) each point's squared distance to the nearest of the others (chunked)."""
    out = np.empty(len(points))
    norm2 = np.sum(others ** 2, axis=1)
    for start in range(0, len(points), CHUNK):
        p = points[start:start + CHUNK]
        d2 = np.sum(p ** 2, axis=1)[:, None] + norm2[None, :] - 2.0 * p @ others.T
        out[start:start + CHUNK] = np.maximum(d2.min(axis=1), 0.0)
    return out


def mirror_plane(points: Array) -> tuple[int, float] | None:
    """The model axis across which the points are their own mirror image, and where the plane
    lies along it (the median: a head's middle); None when no axis is clearly the one (the
    best must be under ``MIRROR_CLEAR`` of the next: a ball is symmetric every way)."""
    if len(points) < 8:
        return None
    scores = np.array([asymmetry(points, axis) for axis in np.eye(3)])
    order = np.argsort(scores)
    if scores[order[0]] > MIRROR_CLEAR * scores[order[1]]:
        return None
    axis = int(order[0])
    return axis, float(np.median(points[:, axis]))


def _components(count: int, edges: Array) -> Array:
    """(count,) a label per vertex, equal for vertices the edges connect: union by the
    smaller label, then pointer jumping, until every edge joins equal labels (a few passes,
    each over all edges at once)."""
    parent = np.arange(count)
    if not len(edges):
        return parent
    while True:
        a, b = parent[edges[:, 0]], parent[edges[:, 1]]
        if np.array_equal(a, b):
            return parent
        np.minimum.at(parent, np.maximum(a, b), np.minimum(a, b))
        while True:
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped


def unique_edges(triangles: Array) -> tuple[Array, Array]:
    """The unique edges of the triangles (E, 2), smaller index first, and how many triangles
    use each. Each edge is one integer key while they are sorted (a row-wise unique sorts
    rows as records: seconds on a 250,000-vertex head, against a tenth of one)."""
    t = np.asarray(triangles, np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    e.sort(axis=1)
    stride = int(e.max(initial=0)) + 1
    keys, counts = np.unique(e[:, 0] * stride + e[:, 1], return_counts=True)
    return np.stack([keys // stride, keys % stride], axis=1), counts


def thinned(points: Array, most: int) -> Array:
    """At most ``most`` of the points, spread evenly over where they lie: the first in each
    cell of a grid coarsened until few enough cells are occupied (all of them when they
    are few already). Nearest-point questions about a dense head's surface then cost what
    they cost on a coarse one, and the answer does not move by more than a cell."""
    if len(points) <= most:
        return points
    lo = points.min(axis=0)
    diagonal = float(np.linalg.norm(np.ptp(points, axis=0))) or 1.0
    cell = diagonal / np.sqrt(most)  # a surface fills about (diagonal / cell)² cells
    while True:
        grid = np.floor((points - lo) / cell).astype(np.int64)
        span = grid.max(axis=0) + 1
        keys = (grid[:, 0] * span[1] + grid[:, 1]) * span[2] + grid[:, 2]
        _, first = np.unique(keys, return_index=True)
        if len(first) <= most:
            return points[np.sort(first)]
        cell *= 1.5


def _blobs(points: Array, members: Array, labels: Array) -> tuple[Array, Array]:
    """Centres (bounding-box middles) and radii (half the box diagonal) of the groups of the
    ``members`` vertices by label, groups whose boxes overlap merged: an eye is an eyeball, a
    cornea, lashes and an occlusion shell around one place, and a row of teeth, each tooth
    its own shell, one arch across the middle (so not a pair)."""
    index = members[np.argsort(labels[members], kind="stable")]
    _, starts = np.unique(labels[index], return_index=True)
    lo = np.minimum.reduceat(points[index], starts, axis=0)
    hi = np.maximum.reduceat(points[index], starts, axis=0)
    if len(lo) <= MERGE_MOST:
        overlap = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]),
                         axis=2)
        merged = _components(len(lo), np.argwhere(np.triu(overlap, 1)))
        order = np.argsort(merged, kind="stable")
        _, starts = np.unique(merged[order], return_index=True)
        lo = np.minimum.reduceat(lo[order], starts, axis=0)
        hi = np.maximum.reduceat(hi[order], starts, axis=0)
    return (lo + hi) / 2.0, np.linalg.norm(hi - lo, axis=1) / 2.0


def _vertex_normals(rest: Array, triangles: Array) -> Array:
    """Area-weighted vertex normals turned outward as a whole: a closed or cupped skin's
    normals point away from its middle on the whole, so a file wound inside out is
    corrected."""
    p = rest[triangles]
    face_normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals = np.zeros_like(rest)
    for corner in range(3):
        np.add.at(normals, triangles[:, corner], face_normals)
    used = np.unique(triangles)
    if np.sum(normals[used] * (rest[used] - rest[used].mean(axis=0))) < 0:
        normals = -normals
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)


def _surface(rest: Array, triangles: Array) -> tuple[Array, Array]:
    """Points spread evenly over the surface with their weights: the triangles' centres
    weighted by area, or an area-weighted draw of ``SURFACE_SAMPLE`` of them (fixed seed) for
    a dense mesh, so that a fine nose does not outweigh a coarse cheek."""
    p = rest[triangles]
    centres = p.mean(axis=1)
    areas = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    if len(centres) <= SURFACE_SAMPLE or areas.sum() <= 0:
        return centres, areas
    pick = np.random.default_rng(0).choice(len(centres), SURFACE_SAMPLE, p=areas / areas.sum())
    return centres[pick], np.ones(SURFACE_SAMPLE)


def _protrusion(points: Array, normals: Array, surface: Array, weights: Array,
                radius: float) -> tuple[Array, Array]:
    """How far each point stands out of the surface around it, as a share of ``radius``:
    its offset from the surface's smoothly weighted mean within ``radius``, along its outward
    normal (positive on a bump such as the nose, negative in a pit such as a socket); and the
    offsets' directions. Chunked, so that memory stays bounded."""
    height = np.zeros(len(points))
    direction = np.zeros_like(points)
    norm2 = np.sum(surface ** 2, axis=1)
    for start in range(0, len(points), CHUNK):
        p = points[start:start + CHUNK]
        d2 = np.sum(p ** 2, axis=1)[:, None] + norm2[None, :] - 2.0 * p @ surface.T
        w = np.clip(1.0 - d2 / radius ** 2, 0.0, None) ** 2 * weights[None, :]
        total = w.sum(axis=1)
        ok = total > 0
        mean = (w @ surface) / np.where(ok, total, 1.0)[:, None]
        offset = np.where(ok[:, None], p - mean, 0.0)
        height[start:start + CHUNK] = np.sum(offset * normals[start:start + CHUNK], axis=1)
        direction[start:start + CHUNK] = offset
    length = np.linalg.norm(direction, axis=1, keepdims=True)
    return height / radius, direction / np.maximum(length, 1e-300)


def _spread(indices: Array, most: int) -> Array:
    """At most ``most`` of the indices, evenly spread (all of them when they are fewer)."""
    if len(indices) <= most:
        return indices
    return indices[np.linspace(0, len(indices) - 1, most).astype(int)]


def _near(points: Array, others: Array, distance: float) -> Array:
    """(N,) bool: points within ``distance`` of any of the others."""
    if not len(others):
        return np.zeros(len(points), bool)
    return _nearest2(points, thinned(others, NEAR_OTHERS)) < distance ** 2


def _eye_pairs(centres: Array, radii: Array, axis: int, plane: float, band: float,
               nose: Array) -> list[Array]:
    """(2, 3) each, the +axis side first: the mirror pairs of the blobs that could be eyes
    for this nose tip — on either side of the plane, each mirroring the other, each smaller
    than half their distance, at a face's proportions from the nose — nearest first (at most
    ``PAIRS_TRIED``)."""
    side = centres[:, axis] - plane
    plus, minus = np.flatnonzero(side > band), np.flatnonzero(side < -band)
    if not len(plus) or not len(minus):
        return []
    mirrored = centres[plus].copy()
    mirrored[:, axis] = 2.0 * plane - mirrored[:, axis]
    a, b = centres[plus][:, None, :], centres[minus][None, :, :]
    apart = np.linalg.norm(a - b, axis=2)
    miss = np.linalg.norm(mirrored[:, None, :] - b, axis=2)
    to_nose = np.linalg.norm((a + b) / 2.0 - nose, axis=2)
    small = np.maximum(radii[plus][:, None], radii[minus][None, :]) < PART_SIZE * apart
    ok = (small & (miss < PAIR_TOLERANCE * apart) & (to_nose > EYES_TO_NOSE[0] * apart)
          & (to_nose < EYES_TO_NOSE[1] * apart))
    order = np.argsort(np.where(ok, to_nose, np.inf), axis=None)[:min(int(ok.sum()),
                                                                     PAIRS_TRIED)]
    rows, cols = np.unravel_index(order, ok.shape)
    return [np.stack([centres[plus[i]], centres[minus[j]]]) for i, j in zip(rows, cols,
                                                                            strict=True)]


def _peaks(points: Array, score: Array, apart: float, most: int) -> Array:
    """Indices of up to ``most`` highest-scoring points (positive scores only), each at least
    ``apart`` from those before it: the tops of separate bumps (or pits), not one bump's
    neighbouring vertices."""
    order = np.argsort(-score)
    order = order[score[order] > 0]
    chosen: list[int] = []
    while len(order) and len(chosen) < most:
        chosen.append(int(order[0]))
        order = order[np.linalg.norm(points[order] - points[order[0]], axis=1) >= apart]
    return np.array(chosen, int)


def _pits(points: Array, depth: Array, axis: int, plane: float, band: float, radius: float,
          most: int = 6) -> list[tuple[Array, Array]]:
    """Eye-socket candidates in a closed skin: mirror pairs of concave points, deepest first
    (a pair is as deep as its shallower side), each side given as the depth-weighted centre
    of the pit around its deepest point (a socket is a bowl), with a radius of 0 (a pit's
    size is no test of it)."""
    side = points[:, axis] - plane
    plus, minus = np.flatnonzero((side > band) & (depth > 0)), np.flatnonzero(
        (side < -band) & (depth > 0))
    if not len(plus) or not len(minus):
        return []
    mirrored = points[plus].copy()
    mirrored[:, axis] = 2.0 * plane - mirrored[:, axis]
    gap2, match = _nearest(mirrored, points[minus])
    paired = np.where(gap2 < radius ** 2, np.minimum(depth[plus], depth[minus[match]]), 0.0)
    out = []
    for peak in _peaks(points[plus], paired, 2.0 * radius, most):
        ends, sizes = [], []
        for chosen, pool in ((plus[peak], plus), (minus[match[peak]], minus)):
            around = pool[np.linalg.norm(points[pool] - points[chosen], axis=1) < 2.0 * radius]
            weight = depth[around] - 0.5 * depth[chosen]
            keep = around[weight > 0]
            ends.append(np.average(points[keep], axis=0, weights=weight[weight > 0]))
            sizes.append(0.0)
        out.append((np.array(ends), np.array(sizes)))
    return out


def _nearest(points: Array, others: Array) -> tuple[Array, Array]:
    """(N,) each point's squared distance to the nearest of the others, and its index."""
    gap2 = np.empty(len(points))
    index = np.empty(len(points), int)
    norm2 = np.sum(others ** 2, axis=1)
    for start in range(0, len(points), CHUNK):
        p = points[start:start + CHUNK]
        d2 = np.sum(p ** 2, axis=1)[:, None] + norm2[None, :] - 2.0 * p @ others.T
        index[start:start + CHUNK] = d2.argmin(axis=1)
        gap2[start:start + CHUNK] = np.maximum(d2.min(axis=1), 0.0)
    return gap2, index


def find_face_features(rest: Array, triangles: Array, skin: Array | None = None,
                       region: Array | None = None, sockets: bool = True
                       ) -> FaceFeatures | None:
    """The nose tip and eyes of a head, and the up and front they give; None when they are
    not found clearly (no mirror plane, no pair of eyes at a face's proportions from a
    protruding point of the midline, or the eyes not clearly above and behind it along some
    axis).

    ``rest`` (W, 3), ``triangles`` (F, 3) welded; ``skin`` (W,) flags (parts such as eyes and
    teeth excluded; None: all skin); ``region`` (W,) the face as far as known (the skin the
    poses deform), which sets the face's size and where to look (None: the skin);
    ``sockets``: whether pits in a closed skin may stand for eyes (the weakest evidence).

    The most protruding midline points are tried in turn (a coarse neck's closing point can
    stand out more than the nose): the nose tip is the first with eyes where a face has
    them."""
    rest = np.asarray(rest, np.float64)
    triangles = np.asarray(triangles)
    skin = np.ones(len(rest), bool) if skin is None else np.asarray(skin) > 0
    if len(triangles) == 0 or skin.sum() < 16:
        return None
    skin_tris = triangles[skin[triangles].all(axis=1)]
    if len(skin_tris) < 16:
        return None
    face = skin if region is None or np.asarray(region).sum() < 16 else np.asarray(region) > 0
    lo, hi = rest[face].min(axis=0), rest[face].max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    if size <= 0:
        return None
    middle = (lo + hi) / 2.0
    on_skin = np.zeros(len(rest), bool)
    on_skin[skin_tris] = True
    within = on_skin & (np.linalg.norm(rest - middle, axis=1) < REACH * size)
    symmetry = mirror_plane(rest[within])
    if symmetry is None:
        return None
    axis, plane = symmetry

    edges, uses = unique_edges(skin_tris)
    spacing = float(np.median(np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)))
    band = max(BAND * size, BAND_EDGES * spacing)
    radius = max(RADIUS * size, 2.0 * spacing)
    near_tris = skin_tris[within[skin_tris].all(axis=1)]
    if not len(near_tris):
        return None
    surface, weights = _surface(rest, near_tris)
    normals = _vertex_normals(rest, skin_tris)
    rim = edges[uses == 1]
    rim_points = rest[np.unique(rim)]

    # nose tips to try: the midline's most protruding points, clear of open edges
    midline = _spread(np.flatnonzero(within & (np.abs(rest[:, axis] - plane) < band)),
                      SPARE * MIDLINE)
    midline = midline[~_near(rest[midline], rim_points, radius)]
    if len(midline) < 3:
        return None
    midline = _spread(midline, MIDLINE)
    height, outward = _protrusion(rest[midline], normals[midline], surface, weights, radius)
    noses = _peaks(rest[midline], height, 2.0 * radius, NOSE_TRIES)

    # eyes: parts that are not skin, holes in the skin, or pits in it
    blobs = []
    others = triangles[~skin[triangles].all(axis=1)]
    if len(others):
        part_edges, _ = unique_edges(others)
        members = np.unique(others)
        members = members[~skin[members]
                          & (np.linalg.norm(rest[members] - middle, axis=1) < REACH * size)]
        if len(members):
            blobs.append((*_blobs(rest, members, _components(len(rest), part_edges)),
                          "eye parts"))
    members = np.unique(rim)
    members = members[within[members]]
    if len(members):
        blobs.append((*_blobs(rest, members, _components(len(rest), rim)),
                      "eye holes in the skin"))
    def widest(sets: list[tuple[Array, Array]], source: str) -> FaceFeatures | None:
        """With the most protruding nose tip that makes a face with any of the pairs, the
        widest pair apart (a nostril's hollows make one too, nearer the nose)."""
        found = []
        for rank, tip in enumerate(noses):
            for centres, radii in sets:
                for eyes in _eye_pairs(centres, radii, axis, plane, band, rest[midline[tip]]):
                    result = _orientation(rest[midline[tip]], outward[tip], eyes, axis, plane,
                                          source, rest[within])
                    if result is not None:
                        apart = float(np.linalg.norm(eyes[0] - eyes[1]))
                        found.append((rank, -apart, len(found), result))
        return min(found, key=lambda item: item[:3])[3] if found else None

    for centres, radii, source in blobs:
        result = widest([(centres, radii)], source)
        if result is not None:
            return result
    if not sockets:
        return None
    candidates = _spread(np.flatnonzero(within), SPARE * CANDIDATES)
    candidates = candidates[~_near(rest[candidates], rim_points, radius)]
    candidates = _spread(candidates, CANDIDATES)
    if not len(candidates) or not len(noses):
        return None
    depth, _ = _protrusion(rest[candidates], normals[candidates], surface, weights, radius)
    return widest(_pits(rest[candidates], -depth, axis, plane, band, radius), "eye sockets")


def _orientation(nose: Array, nose_out: Array, eyes: Array, axis: int, plane: float,
                 source: str, skin: Array) -> FaceFeatures | None:
    """Up and front from the nose tip and the eyes: of the four axis directions in the
    left–right plane, front is the one the nose stands out toward and lies ahead of the eyes
    along (both count: the eyes are about as far behind the nose tip as above it), up the one
    at right angles to it toward the eyes. None unless the eyes are clearly above and behind,
    the nose clearly faces the front, and no skin near the nose tip lies ahead of it (a
    nose tip leads the face; a bump elsewhere, such as where a coarse neck closes, has skin
    ahead of it on one side), and the eyes lie well inside the head's width around them (a
    pair of hollows behind the ears spans all of it)."""
    middle = eyes.mean(axis=0)
    apart = float(np.linalg.norm(eyes[0] - eyes[1]))
    ahead = nose - middle
    in_plane = [i for i in range(3) if i != axis]
    directions = np.array([sign * np.eye(3)[i] for i in in_plane for sign in (1.0, -1.0)])
    scores = directions @ (ahead / max(np.linalg.norm(ahead), 1e-300)) + directions @ nose_out
    front = directions[int(np.argmax(scores))]
    up = next((d for d in directions if abs(d @ front) < 0.5 and d @ (middle - nose) > 0),
              None)
    if (up is None or up @ (middle - nose) < ABOVE * apart or front @ ahead < AHEAD * apart
            or front @ nose_out < FACING):
        return None
    near = skin[np.linalg.norm(skin - nose, axis=1) < apart]
    if len(near) and float(np.max((near - nose) @ front)) > LEADS * apart:
        return None
    around = skin[np.linalg.norm(skin - middle, axis=1) < apart, axis]
    if not len(around) or apart > SPAN * float(np.ptp(around)):
        return None
    return FaceFeatures(nose, eyes, axis, plane, up, front, source)
