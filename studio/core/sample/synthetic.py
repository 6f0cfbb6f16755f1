"""The procedural test face: a head with key poses, maps and both techniques' presets, built
from formulas. (The studio opens on a real head, studio.core.setup.sample_setup; this face was
its sample before.)

Why procedural: the tests need a face whose wrinkle regions are known exactly, in
milliseconds, and the benchmark reproduces the thesis's study at its resolutions. Geometry
(``sample_mesh``) and maps (``sample_maps``) come from one analytic surface, so any vertex count
(the thesis benchmarks 561 … 5151 and 2172) shares the same UVs, maps and landmarks.

``make_test_face`` caches the expensive build and hands every caller its own copy of the arrays,
so a caller may edit the project it gets without disturbing the next one.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from functools import lru_cache

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import sequence_all_poses
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.sample.maps import (
    BROW_MAP,
    EYE_MAP,
    Texels,
    bake_normal_maps,
    paint_diffuse,
    paint_masks,
)
from studio.core.sample.mesh import (
    BROW_Y,
    CORNER_X,
    CORNER_Y,
    EYE_X,
    EYE_Y,
    MIN_VERTICES,
    MOUTH_X,
    MOUTH_Y,
    SampleGeometry,
    blob,
    build_geometry,
    face_to_uv,
    vertex_normals,
)
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.textures import FaceTextures
from studio.core.wrinkles.wdv import WdvArea, WdvSetup, wrinkle_directions

Array = np.ndarray

NAME = "Sample face"
POSES = ("brow_raise_right", "brow_raise_left", "surprise", "squeeze", "frown")

# Named points in face coordinates (x toward the character's left, y up); "right" = −X.
LANDMARKS: dict[str, tuple[float, float]] = {
    "forehead": (0.0, 0.47),
    "forehead right": (-0.2, 0.47),
    "forehead left": (0.2, 0.47),
    "between brows": (0.0, 0.22),
    "eye corner right": (-(CORNER_X - 0.02), CORNER_Y),
    "eye corner left": (CORNER_X - 0.02, CORNER_Y),
    "under eye right": (-(EYE_X + 0.01), EYE_Y - 0.075),
    "under eye left": (EYE_X + 0.01, EYE_Y - 0.075),
    "cheek right": (-0.22, -0.30),
    "cheek left": (0.22, -0.30),
    "nose tip": (0.0, -0.175),
    "chin": (0.0, -0.70),
    "mouth": (0.0, MOUTH_Y),
}

MASK_COLOURS: dict[str, tuple[int, int, int]] = {
    "forehead right": (230, 75, 60),
    "forehead left": (70, 200, 80),
    "between brows": (70, 110, 240),
    "eye corner right": (240, 210, 40),
    "eye corner left": (220, 60, 220),
    "under eye right": (40, 210, 220),
    "under eye left": (250, 140, 30),
    "cheeks": (150, 90, 250),
}

LINKS: dict[str, dict[str, float]] = {
    "brow_raise_right": {"forehead right": 1.0},
    "brow_raise_left": {"forehead left": 1.0},
    "surprise": {"forehead right": 1.0, "forehead left": 1.0},
    "squeeze": {"eye corner right": 1.0, "eye corner left": 1.0, "under eye right": 1.0,
                "under eye left": 1.0, "cheeks": 1.0},
    "frown": {"between brows": 1.0},
}


# --- key poses: smooth displacement fields over face coordinates --------------------------------

def _brow_lift(x: Array, y: Array, centre_x: float, spread: float, flat: bool) -> Array:
    """Upward motion of a raised brow: full at the brow, fading toward the hairline.

    Stronger near the brow than higher up, so the forehead is squeezed vertically — where the
    horizontal forehead lines form.
    """
    above = np.exp(-0.5 * ((y - BROW_Y) / 0.22) ** 2)
    below = np.exp(-0.5 * ((y - BROW_Y) / 0.075) ** 2)
    vertical = np.where(y >= BROW_Y, above, below)
    if flat:
        lateral = np.exp(-0.5 * (x / spread) ** 4)
    else:
        lateral = np.exp(-0.5 * ((x - centre_x) / spread) ** 2)
    return 0.075 * vertical * lateral


def _pose_motion(name: str, x: Array, y: Array) -> tuple[Array, Array]:
    """In-surface (x, y) motion and outward bulge (along the normal) of a pose."""
    ax, side = np.abs(x), np.sign(x)
    move = np.zeros((len(x), 3))
    bulge = np.zeros(len(x))
    if name == "brow_raise_right":
        move[:, 1] = _brow_lift(x, y, -0.24, 0.2, flat=False)
    elif name == "brow_raise_left":
        move[:, 1] = _brow_lift(x, y, 0.24, 0.2, flat=False)
    elif name == "surprise":
        move[:, 1] = (_brow_lift(x, y, 0.0, 0.42, flat=True)
                      + 0.022 * blob(ax, y, EYE_X, EYE_Y + 0.05, 0.09, 0.03)  # upper lids up
                      - 0.012 * blob(ax, y, EYE_X, EYE_Y - 0.04, 0.09, 0.03))  # lower lids down
    elif name == "squeeze":
        # crow's feet: skin around the outer eye corners contracts toward them
        # (plus a small lift, so the corner's centre moves too and gets a wrinkle direction)
        cx = side * CORNER_X
        ring = blob(x, y, cx, CORNER_Y, 0.09, 0.09)
        lift = blob(x, y, cx, CORNER_Y, 0.14, 0.12)
        move[:, 0] = -0.5 * (x - cx) * ring - side * 0.012 * lift
        move[:, 1] = (-0.5 * (y - CORNER_Y) * ring + 0.018 * lift
                      - 0.04 * blob(ax, y, EYE_X, EYE_Y + 0.045, 0.1, 0.035)  # upper lids down
                      + 0.022 * blob(ax, y, EYE_X, EYE_Y - 0.035, 0.11, 0.035)  # lower lids up
                      + 0.05 * blob(ax, y, 0.30, -0.17, 0.14, 0.09)  # cheeks up
                      + 0.035 * blob(ax, y, MOUTH_X, MOUTH_Y, 0.07, 0.06)  # mouth corners up
                      - 0.015 * blob(ax, y, 0.22, BROW_Y, 0.15, 0.06))  # brows a little down
        move[:, 0] += side * 0.02 * blob(ax, y, MOUTH_X, MOUTH_Y, 0.07, 0.06)
        bulge = 0.02 * blob(ax, y, 0.30, -0.14, 0.12, 0.09)
    elif name == "frown":
        brows = blob(x, y, 0.0, BROW_Y - 0.02, 0.2, 0.08)
        move[:, 0] = -0.3 * x * brows  # pulled toward the centre: squeezes between the brows
        move[:, 1] = -0.045 * blob(ax, y, 0.12, BROW_Y, 0.17, 0.08)
        bulge = 0.012 * blob(x, y, 0.0, BROW_Y - 0.03, 0.06, 0.06)
    else:
        raise KeyError(name)
    return move, bulge


def pose_positions(geo: SampleGeometry, name: str, normals: Array) -> Array:
    """Welded positions of a key pose: motions slide along the skin, bulges push it out."""
    x, y = geo.face_xy[:, 0], geo.face_xy[:, 1]
    move, bulge = _pose_motion(name, x, y)
    move *= geo.front[:, None]
    bulge = bulge * geo.front
    tangential = move - np.sum(move * normals, axis=1, keepdims=True) * normals
    return (geo.rest + tangential + bulge[:, None] * normals).astype(np.float32)


# --- technique presets ---------------------------------------------------------------------------

def _influence(masks: dict[str, Array]) -> InfluenceSetup:
    areas = [InfluenceArea(name, mask, colour=MASK_COLOURS[name],
                           wrinkle_map=BROW_MAP if name in BROW_AREAS else EYE_MAP)
             for name, mask in masks.items()]
    return InfluenceSetup(areas=areas, links={p: dict(v) for p, v in LINKS.items()})


BROW_AREAS = ("forehead right", "forehead left", "between brows", "forehead")

WDV_AREAS: dict[str, tuple[str, Callable[[Array, Array], Array], tuple[int, int, int]]] = {
    # area: (pose, which face points belong to it, colour)
    # the forehead above the brows, leaving the frown lines' strip between them out
    "forehead": ("surprise", lambda x, y: (np.abs(x) < 0.5) & (y > BROW_Y + 0.01) & (y < 0.8)
                 & ((np.abs(x) > 0.12) | (y > 0.34)), (255, 150, 40)),
    "eye corners": ("squeeze", lambda x, y: np.hypot(np.abs(x) - CORNER_X, y - CORNER_Y) < 0.16,
                    (60, 220, 120)),
    "between brows": ("frown", lambda x, y: (np.abs(x) < 0.12) & (y > 0.12) & (y < 0.33),
                      (90, 140, 255)),
}


def _wdv(geo: SampleGeometry, poses: dict[str, Array]) -> WdvSetup:
    x, y = geo.face_xy[:, 0], geo.face_xy[:, 1]
    areas = []
    for name, (pose, region, colour) in WDV_AREAS.items():
        target = poses[pose]
        moved = np.linalg.norm(target - geo.rest, axis=1)
        inside = region(x, y) & (geo.front > 0.5)
        # only the vertices the pose really moves: those are the ones whose skin folds
        selected = np.flatnonzero(inside & (moved > 0.05 * moved[inside].max()))
        result = wrinkle_directions(geo.rest, target, selected)
        areas.append(WdvArea(name, pose, result.directions, result.lengths, colour=colour,
                             cone_angle_deg=20.0,
                             wrinkle_map=BROW_MAP if name in BROW_AREAS else EYE_MAP))
    return WdvSetup(areas=areas, expression_factor=1.0, scale_free=True)


# --- the project ---------------------------------------------------------------------------------

@lru_cache(maxsize=8)
def _build(vertices: int, texture_size: int, mask_size: int) -> Project:
    geo = build_geometry(vertices)
    mesh = FaceMesh(geo.rest, geo.triangles, geo.uvs, geo.weld)
    normals = vertex_normals(geo.rest.astype(np.float64), mesh.welded_triangles)
    poses = {name: pose_positions(geo, name, normals) for name in POSES}
    texels = Texels.of(texture_size)
    neutral, wrinkled = bake_normal_maps(texels)
    textures = FaceTextures(paint_diffuse(texels), neutral, wrinkle_maps=wrinkled)
    mask_texels = texels if mask_size == texture_size else Texels.of(mask_size)
    return Project(
        name=NAME,
        mesh=mesh,
        poses=[KeyPose(name, positions) for name, positions in poses.items()],
        textures=textures,
        influence=_influence(paint_masks(mask_texels)),
        wdv=_wdv(geo, poses),
        # neutral → pose → neutral for each pose: the sample moves the moment it plays
        timeline=sequence_all_poses(POSES, fps=24.0),
    )


def make_test_face(vertices: int = 2172, texture_size: int = 1024, mask_size: int = 512) -> Project:
    """The test face with exactly ``vertices`` welded vertices (at least 64).

    Built once per argument set and cached; each call returns a deep copy, so callers may
    modify what they get.
    """
    if vertices < MIN_VERTICES:
        raise ValueError(f"the sample face needs at least {MIN_VERTICES} vertices, not {vertices}")
    if texture_size < 16 or mask_size < 16:
        raise ValueError("texture and mask sizes must be at least 16 texels")
    return copy.deepcopy(_build(int(vertices), int(texture_size), int(mask_size)))


def landmark_uvs() -> dict[str, Array]:
    """UV (u, v) of each named landmark; the same for every vertex count and map size."""
    names = list(LANDMARKS)
    uv = face_to_uv(np.array([LANDMARKS[n] for n in names]))
    return {n: uv[i].astype(np.float32) for i, n in enumerate(names)}


def _points_at_uvs(mesh: FaceMesh, uvs: Array) -> Array:
    """Points on the mesh's surface at the given UVs (barycentric lookup in UV space)."""
    tri = mesh.triangles
    t0, t1, t2 = (mesh.uvs[tri[:, k]].astype(np.float64) for k in range(3))
    e1, e2 = t1 - t0, t2 - t0
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    ok = np.abs(det) > 1e-14
    det = np.where(ok, det, 1.0)
    out = np.empty((len(uvs), 3))
    for i, uv in enumerate(uvs):  # a handful of landmarks, each vectorised over all triangles
        d = uv - t0
        b1 = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / det
        b2 = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / det
        b0 = 1.0 - b1 - b2
        worst = np.where(ok, np.minimum(np.minimum(b0, b1), b2), -np.inf)
        f = int(np.argmax(worst))  # the containing triangle (or the nearest to containing it)
        corners = mesh.rest[mesh.weld[tri[f]]].astype(np.float64)
        out[i] = b0[f] * corners[0] + b1[f] * corners[1] + b2[f] * corners[2]
    return out


def sample_landmarks(project: Project) -> dict[str, Array]:
    """3-D points (model units) on the neutral surface of a sample project, by region name.

    Names: forehead, forehead right/left, between brows, eye corner right/left, under eye
    right/left, cheek right/left, nose tip, chin, mouth ("right" is the character's own, −X).
    """
    uvs = landmark_uvs()
    names = list(uvs)
    points = _points_at_uvs(project.mesh, np.array([uvs[n] for n in names]))
    return {n: points[i].astype(np.float32) for i, n in enumerate(names)}


__all__ = [
    "LANDMARKS",
    "NAME",
    "POSES",
    "landmark_uvs",
    "make_test_face",
    "sample_landmarks",
]

