"""The ``.wrinkle`` project file's schema: its members, their limits, and what a valid project is.

The file is one zip archive holding everything the user made; writer.py writes it, reader.py
reads it, migrations.py upgrades older versions.

Layout (every name relative to the archive root)::

    project.json                 what ties it together (below); written first
    mesh/rest.npy                (W, 3) float32  welded neutral positions
    mesh/triangles.npy           (F, 3) int32    triangles over render vertices
    mesh/uvs.npy                 (V, 2) float32  one UV per render vertex
    mesh/weld.npy                (V,)   int32    render vertex -> welded position
    poses/NN.npy                 (W, 3) float32  key pose NN (order of project.json "poses")
    textures/diffuse.png         RGB PNG, 8 or 16 bits as imported
    textures/normal_neutral.png  RGB PNG, 8 or 16 bits
    textures/normal_wrinkled.png RGB PNG, 8 or 16 bits: the first wrinkled map
    textures/wrinkled_NN.png     RGB PNG: wrinkled map NN (1, 2, 3) when there are several
    textures/cavity_NN.png       8-bit greyscale PNG: wrinkled map NN's cavity (0, 1, 2, 3;
                                 255 open skin, darker deeper in a crease); optional
    textures/colour_NN.png       8-bit RGB PNG: wrinkled map NN's colour (value / 128 tints the
                                 albedo); optional. Both found by name, so a file without them
                                 (an older one) reads as before (core/wrinkles/skin_tone.py)
    mesh/not_face.npy            (W,)   bool     vertices never wrinkled (eyes, teeth); optional
    mesh/vertex_tile.npy         (V,)   int16    UDIM tile (index into uv_tiles.tiles); optional
    masks/NN_<area>.png          16-bit greyscale PNG, value / 65535 = influence (all one size)
                                 (an 8-bit greyscale PNG from an editor reads as value / 255)
    wdv/NN_directions.npy        (W, 3) float32  WDV area NN's directions
    wdv/NN_lengths.npy           (W,)   float32  WDV area NN's authored lengths
    wdv/NN_cones.npy             (W,)   float32  painted cone angles (degrees, 0 = area's); optional

``project.json``::

    {"format": "wrinkle-studio-project", "version": 4, "name": "...",
     "mesh": {"source": "...", "welded_vertices": W, "render_vertices": V, "triangles": F},
     "poses": ["smile", ...],
     "wrinkle_maps": ["wrinkles", "smile lines"],   (names of the wrinkled maps, in order)
     "not_face": "mesh/not_face.npy",               (optional)
     "uv_tiles": {"tiles": [1001, 1002], "cells": [[x, y, side], ...],
                  "vertex_tile": "mesh/vertex_tile.npy"},  (optional: UDIM tiles in the atlas)
     "influence": {"areas": [{"name", "colour": [r, g, b], "activation", "visible",
                              "wrinkle_map", "mask": "masks/00_forehead.png"}, ...],
                   "links": {"pose": {"area": gain}},
                   "curves": {"pose": {"area": {"kind", "start", "end", "points"}}}},
                                (optional: each link's response curve, ResponseCurve.to_dict;
                                 a link without one is linear, as in files made before curves)
     "wdv": {"expression_factor", "scale_free",
             "areas": [{"name", "pose", "colour", "cone_angle_deg", "enabled", "wrinkle_map",
                        "cones": "wdv/00_cones.npy" (optional),
                        "directions": "wdv/00_directions.npy",
                        "lengths": "wdv/00_lengths.npy"}, ...]},
     "furrows": {"all": {"depth", "spacing", "sharpness",      (optional: factors, 1 = as
                         "onset"},                          synthesised; the onset a pose
                 "poses": {"pose": {"depth", ...}},         weight, 0 = lines from the start
                                                            (version 4); a pose's own on top
                 "maps": {"map": {"poses", "spacing",       of all poses'; each synthesised
                                  "depth", "anatomy",       map's record, to make it again:
                                  "digest",                 FurrowSettings.to_dict;
                                  "over_neutral"}}},        over_neutral: version 4, absent
                                                            = true)
     "view": {...}, "timeline": {...}}

Why this shape: images are ordinary PNGs, so a mask can be opened in any image editor straight
from the archive; arrays are ``.npy`` so they keep their exact dtype and need no parsing code;
``.npy`` members are deflated, PNG members are stored (they are compressed already).

``timeline`` is ``Timeline.to_dict()``; its tracks must name existing poses. ``view`` is kept
verbatim (any JSON: tuples come back as lists). Top-level keys this version does not know (a
later writer's additions) are not dropped: ``Project`` has no field for them, so a loaded project
carries them as a plain ``project.extra`` dict attribute (only when there are any), and
:func:`save_project` writes them back.

Loading trusts nothing: every member name, size, JSON field, array dtype/shape/value and image
mode/size is checked, each member's header (a ``.npy``'s dtype and shape, a PNG's IHDR) against
project.json, the budgets and the member's size *before* the member is inflated (a 600 kB file
cannot make the loader allocate 600 MB to refuse it), arrays are read as raw bytes of their
checked dtype (never pickles), and each problem raises :class:`ProjectError` with the file's
path and one sentence. Saving is atomic: a temporary file in the target's folder, fsync, then
``os.replace``; on failure the old file is untouched. The previous version is kept as
``NAME.wrinkle.bak`` (``save_project(..., backup=False)`` skips it).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

import numpy as np

from studio.core.animation.poses import NEUTRAL
from studio.core.animation.timeline import INTERPOLATIONS, Timeline
from studio.core.files.errors import ProjectError, StudioError
from studio.core.files.input_checks import MAX_FPS, MIN_FPS
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.wrinkles.furrow_controls import FurrowSettings
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.textures import FaceTextures

Array = np.ndarray

FORMAT = "wrinkle-studio-project"
FORMAT_VERSION = 4
SUFFIX = ".wrinkle"

# Limits that stop a damaged or hostile archive before anything large is read or allocated.
MAX_TOTAL_BYTES = 4 << 30  # sum of the members' declared uncompressed sizes
MAX_MEMBER_BYTES = 2 << 30  # one member's declared uncompressed size
MAX_JSON_BYTES = 64 << 20
MAX_MEMBERS = 100_000
MAX_PIXEL_BYTES = 2 << 30  # one image's decoded pixels

KNOWN_KEYS = frozenset({"format", "version", "name", "mesh", "poses", "influence", "wdv", "view",
                        "timeline", "wrinkle_maps", "not_face", "uv_tiles", "furrows"})
TEXTURES = ("diffuse", "normal_neutral", "normal_wrinkled")
NOT_FACE_MEMBER = "mesh/not_face.npy"
VERTEX_TILE_MEMBER = "mesh/vertex_tile.npy"
MESH_ARRAYS = {  # member -> dtype, shape in terms of the counts in project.json "mesh"
    "rest": (np.float32, ("welded_vertices", 3)),
    "triangles": (np.int32, ("triangles", 3)),
    "uvs": (np.float32, ("render_vertices", 2)),
    "weld": (np.int32, ("render_vertices",)),
}

# What corrupt bytes can make the standard library, numpy or Pillow raise. load_project turns
# each into a ProjectError; anything else escaping is a bug in this module. (RuntimeError also


def wrinkled_member(index: int) -> str:
    return f"textures/wrinkled_{index:02d}.png"


def tone_member(kind: str, index: int) -> str:
    """``kind``: "cavity" or "colour" of wrinkled map ``index`` (from 0)."""
    return f"textures/{kind}_{index:02d}.png"


def cones_member(index: int) -> str:
    return f"wdv/{index:02d}_cones.npy"


def pose_member(index: int) -> str:
    return f"poses/{index:02d}.npy"


def mask_member(index: int, name: str) -> str:
    slug = re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_")[:40]
    return f"masks/{index:02d}_{slug}.png" if slug else f"masks/{index:02d}.png"


def check_project(project: Project, path: str | Path | None = None) -> None:
    """Raise ProjectError for anything load_project would refuse, so a save never writes it.

    Names are the keys that links and WDV areas refer by, hence unique and non-empty.
    """
    def fail(message: str) -> NoReturn:
        raise ProjectError(message, path)

    if not isinstance(project.name, str):
        fail("the project name must be text")
    names = [p.name for p in project.poses]
    for name in names:
        if not isinstance(name, str) or not name or name == NEUTRAL:
            fail(f"a key pose cannot be called {name!r}")
    if len(set(names)) != len(names):
        fail("two key poses have the same name")
    try:  # re-run the model's own checks: arrays may have been replaced since construction
        m, t = project.mesh, project.textures
        mesh = FaceMesh(m.rest, m.triangles, m.uvs, m.weld)
        Project(project.name, mesh, project.poses,
                FaceTextures(t.diffuse, t.normal_neutral, wrinkle_maps=dict(t.wrinkle_maps)),
                not_face=project.not_face, uv_tiles=project.uv_tiles)
    except StudioError as exc:
        fail(exc.problem)
    map_names = set(project.textures.wrinkle_map_names) | {""}
    for kind, group in (("influence", project.influence.areas), ("WDV", project.wdv.areas)):
        for a in group:
            if a.wrinkle_map not in map_names:
                fail(f"{kind} area '{a.name}' reveals wrinkled map '{a.wrinkle_map}', which "
                     "does not exist")
    areas = project.influence.areas
    _check_names([a.name for a in areas], "influence area", fail)
    shapes = {a.mask.shape for a in areas}
    if any(len(s) != 2 or min(s) < 1 for s in shapes):
        fail("every influence mask must be a two-dimensional image")
    if len(shapes) > 1:
        fail(f"the influence masks differ in size ({', '.join(image_size(s) for s in shapes)}); "
             "they must all share one size")
    for a in areas:
        if not np.isfinite(a.mask).all():
            fail(f"the mask of influence area '{a.name}' has non-finite values")
        _check_colour(a.colour, f"influence area '{a.name}'", fail)
        _check_number(a.activation, f"the activation of influence area '{a.name}'", fail)
    poses = set(project.pose_names)
    area_names = {a.name for a in areas}
    for pose, gains in project.influence.links.items():
        if pose not in poses:
            fail(f"a link comes from key pose '{pose}', which does not exist")
        for area, gain in gains.items():
            if area not in area_names:
                fail(f"the link from key pose '{pose}' names influence area '{area}', "
                     "which does not exist")
            _check_number(gain, f"the gain of the link from '{pose}' to '{area}'", fail)
    for pose, by_area in project.influence.curves.items():
        for area, curve in by_area.items():
            if pose not in poses or area not in area_names:
                fail(f"the response curve of the link from '{pose}' to '{area}' names a key "
                     "pose or influence area that does not exist")
            if not isinstance(curve, ResponseCurve):
                fail(f"the response curve of the link from '{pose}' to '{area}' is not a curve")
    wdv = project.wdv
    _check_number(wdv.expression_factor, "the WDV expression factor", fail)
    _check_names([a.name for a in wdv.areas], "WDV area", fail)
    n = project.mesh.n_welded
    for a in wdv.areas:
        what = f"WDV area '{a.name}'"
        if a.pose not in poses:
            fail(f"{what} uses key pose '{a.pose}', which does not exist")
        if a.directions.shape != (n, 3) or a.lengths.shape != (n,):
            fail(f"{what} has directions for {len(a.directions)} vertices, the mesh has {n}")
        if not (np.isfinite(a.directions).all() and np.isfinite(a.lengths).all()):
            fail(f"{what} has non-finite directions or lengths")
        if (a.lengths < 0).any():
            fail(f"{what} has negative lengths")
        _check_colour(a.colour, what, fail)
        _check_number(a.cone_angle_deg, f"the cone angle of {what}", fail)
        if not 0.0 <= a.cone_angle_deg <= 180.0:
            fail(f"the cone angle of {what} must be between 0 and 180 degrees")
        cones = a.cone_angles_deg
        if cones is not None and (cones.shape != (n,) or not np.isfinite(cones).all()
                                  or cones.min() < 0.0 or cones.max() > 180.0):
            fail(f"the painted cone angles of {what} must be {n} values from 0 to 180 degrees")
    if not isinstance(project.view, dict):
        fail("the view settings must be a dictionary")
    _check_furrows(project.furrows, fail)
    _check_timeline(project.timeline, poses, fail)


def _check_timeline(timeline: Timeline, poses: set[str], fail: Callable[[str], NoReturn]) -> None:
    if not isinstance(timeline, Timeline):
        fail("the project's timeline is not a timeline")
    _check_number(timeline.fps, "the timeline's frame rate", fail)
    if not (timeline.fps > 0 and timeline.end > timeline.start):
        fail("the timeline needs a positive frame rate and an end after its start")
    if not MIN_FPS <= timeline.fps <= MAX_FPS:
        fail(f"the timeline's frame rate {timeline.fps:g} is outside {MIN_FPS:g} to "
             f"{MAX_FPS:g} frames per second")
    for track in timeline.tracks:
        if track.pose not in poses:
            fail(f"the timeline animates key pose '{track.pose}', which does not exist")
        for key in track.keys:
            _check_number(key.frame, f"a key frame of the '{track.pose}' track", fail)
            _check_number(key.value, f"a key value of the '{track.pose}' track", fail)
            if key.interpolation not in INTERPOLATIONS:
                fail(f"the '{track.pose}' track has an unknown interpolation "
                     f"'{key.interpolation}'")


def _check_furrows(furrows: FurrowSettings, fail: Callable[[str], NoReturn]) -> None:
    """Only the type: controls of a pose renamed or deleted since are dropped on saving
    (``FurrowSettings.pruned``), and a record's missing pose is skipped when the map is made
    again — neither is worth refusing a file for."""
    if not isinstance(furrows, FurrowSettings):
        fail("the furrow settings are not furrow settings")


def _check_names(names: list[Any], what: str, fail: Callable[[str], NoReturn]) -> None:
    for name in names:
        if not isinstance(name, str) or not name:
            fail(f"an {what} needs a name" if what[0] in "aeiou" else f"a {what} needs a name")
    seen = set()
    for name in names:
        if name in seen:
            fail(f"two {what}s are called '{name}'")
        seen.add(name)


def _check_colour(colour: Any, what: str, fail: Callable[[str], NoReturn]) -> None:
    ok = isinstance(colour, tuple | list) and len(colour) == 3 and all(
        isinstance(c, int | np.integer) and not isinstance(c, bool) and 0 <= c <= 255
        for c in colour)
    if not ok:
        fail(f"the colour of {what} must be three whole numbers from 0 to 255")


def _check_number(value: Any, what: str, fail: Callable[[str], NoReturn]) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float | np.number) \
            or not math.isfinite(value):
        fail(f"{what} must be a finite number")


def image_size(shape: tuple[int, ...]) -> str:
    """An image's size as width×height, the way image editors say it."""
    return "×".join(str(s) for s in shape[1::-1])  # width×height, as image editors say it


# --------------------------------------------------------------------------- loading
