"""The ``.wrinkle`` project file: one zip archive holding everything the user made.

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
    mesh/not_face.npy            (W,)   bool     vertices never wrinkled (eyes, teeth); optional
    mesh/vertex_tile.npy         (V,)   int16    UDIM tile (index into uv_tiles.tiles); optional
    masks/NN_<area>.png          16-bit greyscale PNG, value / 65535 = influence (all one size)
                                 (an 8-bit greyscale PNG from an editor reads as value / 255)
    wdv/NN_directions.npy        (W, 3) float32  WDV area NN's directions
    wdv/NN_lengths.npy           (W,)   float32  WDV area NN's authored lengths
    wdv/NN_cones.npy             (W,)   float32  painted cone angles (degrees, 0 = area's); optional

``project.json``::

    {"format": "wrinkle-studio-project", "version": 2, "name": "...",
     "mesh": {"source": "...", "welded_vertices": W, "render_vertices": V, "triangles": F},
     "poses": ["smile", ...],
     "wrinkle_maps": ["wrinkles", "smile lines"],   (names of the wrinkled maps, in order)
     "not_face": "mesh/not_face.npy",               (optional)
     "uv_tiles": {"tiles": [1001, 1002], "cells": [[x, y, side], ...],
                  "vertex_tile": "mesh/vertex_tile.npy"},  (optional: UDIM tiles in the atlas)
     "influence": {"areas": [{"name", "colour": [r, g, b], "activation", "visible",
                              "wrinkle_map", "mask": "masks/00_forehead.png"}, ...],
                   "links": {"pose": {"area": gain}}},
     "wdv": {"expression_factor", "scale_free",
             "areas": [{"name", "pose", "colour", "cone_angle_deg", "enabled", "wrinkle_map",
                        "cones": "wdv/00_cones.npy" (optional),
                        "directions": "wdv/00_directions.npy",
                        "lengths": "wdv/00_lengths.npy"}, ...]},
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
mode/size is checked, ``np.load`` runs with ``allow_pickle=False``, and each problem raises
:class:`ProjectError` with the file's path and one sentence. Saving is atomic: a temporary file
in the target's folder, fsync, then ``os.replace``; on failure the old file is untouched. The
previous version is kept as ``NAME.wrinkle.bak`` (``save_project(..., backup=False)`` skips it).
"""

from __future__ import annotations

import contextlib
import errno
import io
import json
import math
import os
import re
import shutil
import stat
import struct
import tempfile
import time
import warnings
import zipfile
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, NoReturn

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

import numpy as np

from studio.core.budgets import check_json_depth
from studio.core.errors import ProjectError, StudioError
from studio.core.influence import InfluenceArea, InfluenceSetup
from studio.core.input_checks import MAX_FPS, MIN_FPS, check_camera
from studio.core.mask_store import ImageBudget, mask_members
from studio.core.mesh import FaceMesh
from studio.core.png import PngError, encode_png, read_png
from studio.core.poses import NEUTRAL, KeyPose
from studio.core.project import Project
from studio.core.textures import DEFAULT_WRINKLE_MAP, MAX_WRINKLE_MAPS, FaceTextures
from studio.core.timeline import INTERPOLATIONS, Timeline
from studio.core.uv_tiles import TileLayout, UvTiles
from studio.core.wdv import WdvArea, WdvSetup

Array = np.ndarray

FORMAT = "wrinkle-studio-project"
FORMAT_VERSION = 2
SUFFIX = ".wrinkle"

# MIGRATIONS[v] turns the project.json of a version-v file into version v + 1 (pure JSON in,
# JSON out: a migration that moves members points the new JSON at the old member names).
# load_project applies them in turn, so a file of any older version reaches FORMAT_VERSION.
MIGRATIONS: dict[int, Callable[[dict[str, Any]], dict[str, Any]]] = {
    1: lambda doc: doc,  # 2 adds optional keys only: several wrinkled maps, not-face, cones
}

# Limits that stop a damaged or hostile archive before anything large is read or allocated.
MAX_TOTAL_BYTES = 4 << 30  # sum of the members' declared uncompressed sizes
MAX_MEMBER_BYTES = 2 << 30  # one member's declared uncompressed size
MAX_JSON_BYTES = 64 << 20
MAX_MEMBERS = 100_000
MAX_PIXEL_BYTES = 2 << 30  # one image's decoded pixels

KNOWN_KEYS = frozenset({"format", "version", "name", "mesh", "poses", "influence", "wdv", "view",
                        "timeline", "wrinkle_maps", "not_face", "uv_tiles"})
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
# covers zipfile's error for a compression method it does not know.)
_DAMAGE = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, struct.error, EOFError,
           OSError, ValueError, KeyError, IndexError, TypeError, ArithmeticError, RuntimeError,
           SyntaxError, MemoryError, AttributeError)


# --------------------------------------------------------------------------- saving


def save_project(project: Project, path: str | Path, backup: bool = True) -> None:
    """Write ``project`` to ``path`` atomically: the old file survives any failure.

    With ``backup`` the file being replaced is kept as ``NAME.wrinkle.bak`` (a hard link where
    the disk allows, so keeping it costs neither time nor space), one step of "undo the save".
    Temporary files left by an earlier save that was killed are removed on the way.

    Raises ProjectError naming ``path`` when the project cannot be saved as it is (so that
    nothing is written that load_project would refuse) or when the disk refuses the write.
    """
    path = Path(path)
    check_project(project, path)
    document = _document(project, path)
    target = Path(os.path.realpath(path))  # save through a symlink into the file it points at
    folder = target.parent
    _remove_stale_temps(folder, target.name)
    try:
        handle = _locked_temp(folder, target.name)
    except OSError as exc:
        reason = _os_reason(exc, f"the folder {folder}")
        raise ProjectError(f"cannot save the project: {reason}", path) from exc
    try:
        with handle:
            _write_archive(handle, project, document)
            handle.flush()
            os.fsync(handle.fileno())
            _copy_mode(handle.name, target)
        if backup:
            _keep_backup(target)
        os.replace(handle.name, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(handle.name)
        if isinstance(exc, OSError):
            reason = _os_reason(exc, str(target))
            raise ProjectError(f"cannot save the project: {reason}", path) from exc
        raise
    _fsync_folder(folder)


def backup_path(path: str | Path) -> Path:
    """Where save_project keeps the previous version of ``path``."""
    path = Path(path)
    return path.with_name(path.name + ".bak")


def _temp_prefix(name: str) -> str:
    return f".{name}."


def _locked_temp(folder: Path, name: str) -> Any:
    """A new temporary file beside the target, locked while it is written.

    Why the lock: a save killed half-way leaves its temporary file behind; the next save removes
    the ones nobody holds a lock on (the kernel drops a dead process's locks), never a file that
    another save is writing right now.
    """
    for _ in range(5):
        handle = tempfile.NamedTemporaryFile(  # noqa: SIM115 - the caller closes it
            dir=folder, prefix=_temp_prefix(name), suffix=".tmp", delete=False)
        if fcntl is None:
            return handle
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX)
        if os.fstat(handle.fileno()).st_nlink > 0:  # not swept away before it was locked
            return handle
        handle.close()
    return handle


def _remove_stale_temps(folder: Path, name: str) -> None:
    """Delete temporary files of earlier saves of ``name`` that died before renaming them."""
    if fcntl is None:  # no advisory locks (Windows): leave them, they are only hidden litter
        return
    prefix = _temp_prefix(name)
    try:
        entries = [e for e in os.scandir(folder)
                   if e.name.startswith(prefix) and e.name.endswith(".tmp")]
    except OSError:
        return
    for entry in _stale_backup_staging(folder, name):
        with contextlib.suppress(OSError):
            os.unlink(entry)
    for entry in entries:
        try:
            fd = os.open(entry.path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            continue
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                continue
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # held: a save is writing it
            os.unlink(entry.path)
        except OSError:
            pass
        finally:
            os.close(fd)


def _stale_backup_staging(folder: Path, name: str) -> list[str]:
    """Half-made backups (``_keep_backup``'s staging links) of processes that have died."""
    prefix = f".{name}.bak."
    stale = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if not (entry.name.startswith(prefix) and entry.name.endswith(".staging")):
                continue
            pid = entry.name[len(prefix):-len(".staging")]
            if pid.isdigit() and int(pid) != os.getpid() and not _process_alive(
                    int(pid), entry.stat().st_ctime):
                stale.append(entry.path)
    return stale


def _process_alive(pid: int, since: float | None = None) -> bool:
    """Whether process ``pid`` (the one that made a file at ``since``) still runs. Process ids
    are reused, and on Linux a thread's id answers ``kill`` too: there a live id counts only if
    it leads a process that started before the file was made."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, but someone else's
        return True
    if since is None or not os.path.exists("/proc/stat"):
        return True
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        tgid = next(int(line.split()[1]) for line in status.splitlines()
                    if line.startswith("Tgid:"))
        if tgid != pid:
            return False  # a thread of another process that got the same number
        boot = next(float(line.split()[1]) for line in Path("/proc/stat").read_text()
                    .splitlines() if line.startswith("btime"))
        ticks = float(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
        return boot + ticks / os.sysconf("SC_CLK_TCK") <= since + 1.0
    except (OSError, ValueError, IndexError, StopIteration):
        return True


def _keep_backup(target: Path) -> None:
    """Keep the file about to be replaced as ``NAME.bak``, replacing an older backup atomically.

    A backup that cannot be made (no room, no hard links and no space to copy) does not stop the
    save: the new version matters more than the previous one.
    """
    if not target.is_file():
        return
    bak = backup_path(target)
    staging = bak.with_name(f".{bak.name}.{os.getpid()}.staging")
    with contextlib.suppress(OSError):
        os.unlink(staging)
    try:
        try:
            os.link(target, staging)
        except OSError:
            shutil.copy2(target, staging)
        os.replace(staging, bak)
    except OSError:
        with contextlib.suppress(OSError):
            os.unlink(staging)


def _write_archive(handle: Any, project: Project, document: bytes) -> None:
    stamp = time.localtime()[:6]
    with zipfile.ZipFile(handle, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, encode, value in _members(project, document):
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.compress_type = zipfile.ZIP_STORED if name.endswith(".png") else \
                zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, encode(value))


def _members(project: Project,
             document: bytes) -> Iterator[tuple[str, Callable[[Any], bytes], Any]]:
    """(name, encoder, value) for every member, so bytes exist one member at a time."""
    yield "project.json", bytes, document
    for key in MESH_ARRAYS:
        yield f"mesh/{key}.npy", _npy, getattr(project.mesh, key)
    for i, pose in enumerate(project.poses):
        yield _pose_member(i), _npy, pose.positions
    if project.not_face is not None:
        yield NOT_FACE_MEMBER, _npy, project.not_face
    if project.uv_tiles is not None:
        yield VERTEX_TILE_MEMBER, _npy, project.uv_tiles.vertex_tile
    for key in TEXTURES:
        yield f"textures/{key}.png", encode_png, getattr(project.textures, key)
    for i, image in enumerate(list(project.textures.wrinkle_maps.values())[1:], start=1):
        yield _wrinkled_member(i), encode_png, image
    written = set()  # masks shared by several areas are stored once
    for area, member in zip(project.influence.areas,
                            mask_members(project.influence.areas, _mask_member), strict=True):
        if member not in written:
            written.add(member)
            yield member, _mask_png, area.mask
    for i, wdv in enumerate(project.wdv.areas):
        yield f"wdv/{i:02d}_directions.npy", _npy, wdv.directions
        yield f"wdv/{i:02d}_lengths.npy", _npy, wdv.lengths
        if wdv.cone_angles_deg is not None:
            yield _cones_member(i), _npy, wdv.cone_angles_deg


def _document(project: Project, path: Path) -> bytes:
    """project.json as UTF-8 bytes (strict JSON: no NaN or Infinity)."""
    doc: dict[str, Any] = {}
    for key, value in project.extra.items():
        if key not in KNOWN_KEYS:
            doc[key] = value
    influence = project.influence
    doc.update({
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "name": project.name,
        "mesh": {"source": project.mesh.source, "welded_vertices": project.mesh.n_welded,
                 "render_vertices": project.mesh.n_vertices,
                 "triangles": project.mesh.n_triangles},
        "poses": [pose.name for pose in project.poses],
        "wrinkle_maps": project.textures.wrinkle_map_names,
        **({"not_face": NOT_FACE_MEMBER} if project.not_face is not None else {}),
        **({"uv_tiles": {**project.uv_tiles.layout.to_dict(), "vertex_tile": VERTEX_TILE_MEMBER}}
           if project.uv_tiles is not None else {}),
        "influence": {
            "areas": [{"name": a.name, "colour": [int(c) for c in a.colour],
                       "activation": float(a.activation), "visible": bool(a.visible),
                       "wrinkle_map": a.wrinkle_map, "mask": member}
                      for a, member in zip(influence.areas, mask_members(
                          influence.areas, _mask_member), strict=True)],
            "links": {pose: {area: float(gain) for area, gain in gains.items()}
                      for pose, gains in influence.links.items()},
        },
        "wdv": {
            "expression_factor": float(project.wdv.expression_factor),
            "scale_free": bool(project.wdv.scale_free),
            "areas": [{"name": a.name, "pose": a.pose, "colour": [int(c) for c in a.colour],
                       "cone_angle_deg": float(a.cone_angle_deg), "enabled": bool(a.enabled),
                       "wrinkle_map": a.wrinkle_map,
                       **({"cones": _cones_member(i)} if a.cone_angles_deg is not None else {}),
                       "directions": f"wdv/{i:02d}_directions.npy",
                       "lengths": f"wdv/{i:02d}_lengths.npy"}
                      for i, a in enumerate(project.wdv.areas)],
        },
        "timeline": project.timeline.to_dict(),
        "view": project.view,
    })
    try:
        text = json.dumps(doc, indent=1, ensure_ascii=False, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as exc:
        raise ProjectError(f"cannot save the project: its view or timeline settings cannot be "
                           f"written as JSON ({exc})", path) from None
    return text.encode("utf-8")


def _npy(array: Array) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def _mask_png(mask: Array) -> bytes:
    """Float mask in [0, 1] -> 16-bit greyscale PNG, the nearest of 65536 levels."""
    return encode_png(np.rint(np.clip(mask, 0.0, 1.0) * 65535.0).astype(np.uint16))


def _wrinkled_member(index: int) -> str:
    return f"textures/wrinkled_{index:02d}.png"


def _cones_member(index: int) -> str:
    return f"wdv/{index:02d}_cones.npy"


def _pose_member(index: int) -> str:
    return f"poses/{index:02d}.npy"


def _mask_member(index: int, name: str) -> str:
    slug = re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_")[:40]
    return f"masks/{index:02d}_{slug}.png" if slug else f"masks/{index:02d}.png"


def _copy_mode(temp: str, target: Path) -> None:
    """Give the new file the old one's permissions (or the umask's), not mkstemp's 0600."""
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    with contextlib.suppress(OSError):  # a file system without modes still gets the file
        os.chmod(temp, mode)


def _fsync_folder(folder: Path) -> None:
    """Make the rename itself durable where the platform allows opening a folder."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _os_reason(exc: OSError, where: str) -> str:
    """One plain phrase for what the operating system refused."""
    reasons = {
        errno.ENOSPC: "the disk is full",
        errno.EDQUOT: "the disk quota is exceeded",
        errno.EACCES: f"permission denied for {where}",
        errno.EPERM: f"permission denied for {where}",
        errno.EROFS: f"{where} is on a read-only disk",
        errno.ENOENT: f"{where} does not exist",
        errno.EISDIR: f"{where} is a folder",
        errno.ENOTDIR: f"a part of {where} is not a folder",
        errno.EIO: "the disk reported an input/output error",
    }
    return reasons.get(exc.errno, exc.strerror or str(exc) or type(exc).__name__)


# --------------------------------------------------------------------------- checks shared


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
        fail(f"the influence masks differ in size ({', '.join(_size(s) for s in shapes)}); "
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


def _size(shape: tuple[int, ...]) -> str:
    return "×".join(str(s) for s in shape[1::-1])  # width×height, as image editors say it


# --------------------------------------------------------------------------- loading


def load_project(path: str | Path) -> Project:
    """Read a ``.wrinkle`` file, checking every part; ProjectError(one sentence, path) if bad."""
    path = Path(path)
    try:
        with _open_archive(path) as archive:
            return _Loader(archive, path).project()
    except ProjectError:
        raise
    except StudioError as exc:
        raise ProjectError(exc.problem, path) from exc
    except PngError as exc:
        raise ProjectError(f"an image in the project is damaged: {exc}", path) from exc
    except RecursionError:
        raise ProjectError("the project file is damaged (data nested too deeply)", path) from None
    except FileNotFoundError:
        raise ProjectError("the project file does not exist", path) from None
    except OSError as exc:
        if exc.errno not in _CANNOT_READ:  # e.g. EINVAL from a seek to a damaged offset
            raise ProjectError(f"the project file is damaged ({exc})", path) from exc
        reason = _os_reason(exc, str(path))
        raise ProjectError(f"cannot read the project file: {reason}", path) from exc
    except _DAMAGE as exc:
        detail = str(exc) or type(exc).__name__
        raise ProjectError(f"the project file is damaged ({detail})", path) from exc


_CANNOT_READ = {errno.EACCES, errno.EPERM, errno.EIO, errno.ENOTDIR, errno.EISDIR, errno.ELOOP,
                errno.ENAMETOOLONG}


def _open_archive(path: Path) -> zipfile.ZipFile:
    from studio.core.safe_io import require_regular

    require_regular(path, ProjectError, "project file")  # a FIFO or /dev/zero would hang
    try:
        return zipfile.ZipFile(path)
    except zipfile.BadZipFile:
        with open(path, "rb") as f:
            head = f.read(4)
        if head == b"PK\x03\x04":
            raise ProjectError("the project file is truncated or damaged (its zip directory is "
                               "missing or broken)", path) from None
        raise ProjectError("this is not a Wrinkle Studio project (it is not a zip archive)",
                           path) from None


def _unsafe_name(name: str) -> bool:
    """Absolute, drive-qualified, backslashed or escaping member names (never extracted, but a
    file that has them was not written by the studio and must not be trusted)."""
    parts = name.rstrip("/").split("/")
    return (not name or name.startswith("/") or "\\" in name or "\0" in name
            or re.match(r"^[A-Za-z]:", name) is not None
            or any(p in ("", ".", "..") for p in parts))


class _Loader:
    """Reads one open archive into a Project; every method fails with a ProjectError."""

    def __init__(self, archive: zipfile.ZipFile, path: Path) -> None:
        self.archive = archive
        self.path = path
        self.sizes = self._check_directory()
        self.images = ImageBudget(path)  # decoded pixels, and each mask member decoded once

    def fail(self, message: str) -> NoReturn:
        raise ProjectError(message, self.path)

    # -- the zip directory, before anything is decompressed
    def _check_directory(self) -> dict[str, int]:
        infos = self.archive.infolist()
        if len(infos) > MAX_MEMBERS:
            self.fail(f"the project file has {len(infos)} members, more than any project has")
        sizes: dict[str, int] = {}
        total = 0
        for info in infos:
            name = info.filename
            if _unsafe_name(name):
                self.fail(f"the project file contains a member with an unsafe name {name!r} "
                          "(an absolute path or one leading outside the archive)")
            if name in sizes:
                self.fail(f"the project file contains two members named '{name}'")
            if info.flag_bits & 0x1:
                self.fail(f"the member '{name}' is encrypted, which project files never are")
            if info.file_size > MAX_MEMBER_BYTES:
                self.fail(f"the member '{name}' claims {info.file_size} bytes, more than the "
                          f"{MAX_MEMBER_BYTES >> 20} MiB limit for one member (a damaged or "
                          "hostile file)")
            total += info.file_size
            sizes[name] = info.file_size
        if total > MAX_TOTAL_BYTES:
            self.fail(f"the project file unpacks to {total} bytes, more than the "
                      f"{MAX_TOTAL_BYTES >> 30} GiB limit (a damaged or hostile file)")
        return sizes

    def read(self, name: Any, what: str) -> bytes:
        if not isinstance(name, str) or _unsafe_name(name):
            self.fail(f"project.json names an invalid member {name!r} for {what}")
        if name not in self.sizes:
            self.fail(f"the project file is missing '{name}' ({what})")
        with self.archive.open(name) as member:
            data = member.read(self.sizes[name] + 1)
        if len(data) != self.sizes[name]:
            self.fail(f"the member '{name}' ({what}) is truncated or damaged")
        return data

    # -- project.json
    def document(self) -> dict[str, Any]:
        if "project.json" not in self.sizes:
            self.fail("this zip archive is not a Wrinkle Studio project (it has no project.json)")
        if self.sizes["project.json"] > MAX_JSON_BYTES:
            self.fail("project.json is far larger than any project description")
        data = self.read("project.json", "the project description")
        check_json_depth(data, "project.json", self.path, ProjectError)
        try:
            doc = json.loads(data.decode("utf-8"), parse_constant=_reject_constant,
                             parse_float=_finite_float)
        except UnicodeDecodeError:
            self.fail("project.json is not UTF-8 text")
        except RecursionError:
            self.fail("project.json is nested too deeply")
        except ValueError as exc:
            self.fail(f"project.json is not valid JSON ({exc})")
        if not isinstance(doc, dict):
            self.fail("project.json does not hold a JSON object")
        if doc.get("format") != FORMAT:
            self.fail("this zip archive is not a Wrinkle Studio project (project.json has no "
                      f"\"format\": \"{FORMAT}\")")
        version = doc.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or version < 1:
            self.fail(f"project.json has an invalid format version {version!r}")
        if version > FORMAT_VERSION:
            self.fail(f"this project was made by a newer Wrinkle Studio (file format version "
                      f"{version}; this one reads up to version {FORMAT_VERSION}); please update")
        while version < FORMAT_VERSION:
            step = MIGRATIONS.get(version)
            if step is None:
                self.fail(f"file format version {version} is no longer supported")
            doc = step(doc)
            version += 1
            if not isinstance(doc, dict):
                self.fail(f"the project could not be upgraded from format version {version - 1}")
            doc["version"] = version
        return doc

    # -- typed access to JSON fields, with the field's place in every message
    def field(self, obj: dict[str, Any], key: str, kind: str, where: str) -> Any:
        if key not in obj:
            self.fail(f"project.json lacks {where}{key}")
        return self.value(obj[key], kind, f"{where}{key}")

    def optional(self, obj: dict[str, Any], key: str, kind: str, where: str,
                 default: Any) -> Any:
        return self.field(obj, key, kind, where) if key in obj else default

    def value(self, value: Any, kind: str, where: str) -> Any:
        if kind == "number":
            ok = isinstance(value, int | float) and not isinstance(value, bool) \
                and math.isfinite(value)
            return float(value) if ok else self.fail(f"project.json: {where} must be a number")
        if kind == "count":
            ok = isinstance(value, int) and not isinstance(value, bool) and value >= 1
            return value if ok else self.fail(f"project.json: {where} must be a whole number "
                                              "of at least 1")
        if kind == "colour":
            ok = isinstance(value, list) and len(value) == 3 and all(
                isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255 for c in value)
            return tuple(value) if ok else self.fail(f"project.json: {where} must be three "
                                                     "whole numbers from 0 to 255")
        if kind == "name":
            ok = isinstance(value, str) and value != ""
            return value if ok else self.fail(f"project.json: {where} must be a non-empty name")
        types = {"text": str, "bool": bool, "object": dict, "list": list}[kind]
        if not isinstance(value, types):
            self.fail(f"project.json: {where} must be {_KIND_WORDS[kind]}")
        return value

    # -- members
    def array(self, name: Any, dtype: type, shape: tuple[int, ...], what: str) -> Array:
        data = self.read(name, what)
        expected = np.dtype(dtype)
        stream = io.BytesIO(data)
        try:
            with warnings.catch_warnings():  # a damaged header makes ast warn as well as fail
                warnings.simplefilter("ignore")
                major, _ = np.lib.format.read_magic(stream)
                if major not in (1, 2):
                    raise ValueError(f"unsupported .npy version {major}")
                header = (np.lib.format.read_array_header_1_0 if major == 1
                          else np.lib.format.read_array_header_2_0)(stream)
        except Exception as exc:  # numpy parses the header with tokenize and ast: their
            # errors (TokenError, SyntaxError, ValueError, …) vary by version, all mean "damaged"
            self.fail(f"'{name}' ({what}) is not a valid .npy array ({exc})")
        file_shape, _, file_dtype = header
        if file_dtype.kind != expected.kind or file_dtype.itemsize != expected.itemsize:
            self.fail(f"'{name}' ({what}) holds {file_dtype} values, expected {expected}")
        if tuple(file_shape) != shape:
            self.fail(f"'{name}' ({what}) has shape {tuple(file_shape)}, expected {shape}")
        if len(data) - stream.tell() != math.prod(shape) * expected.itemsize:
            self.fail(f"'{name}' ({what}) is truncated or has extra bytes")
        array = np.load(io.BytesIO(data), allow_pickle=False)
        array = np.ascontiguousarray(array, dtype=expected)  # native byte order, C order
        if expected.kind == "f" and not np.isfinite(array).all():
            self.fail(f"'{name}' ({what}) contains non-finite values (NaN or infinity)")
        return array

    def image(self, name: Any, what: str, grey: bool) -> Array:
        shared = self.images.shared(name, what, grey)
        if shared is not None:
            return shared
        data = self.read(name, what)
        try:
            self.images.claim(name, data, what, grey)
            image = read_png(data, MAX_PIXEL_BYTES)
        except PngError as exc:
            self.fail(f"'{name}' ({what}) cannot be read: {exc}")
        if grey and image.ndim != 2:
            self.fail(f"'{name}' ({what}) must be a greyscale image, it has "
                      f"{image.shape[2]} channels")
        if not grey and (image.ndim != 3 or image.shape[2] != 3):
            channels = 1 if image.ndim == 2 else image.shape[2]
            self.fail(f"'{name}' ({what}) must be an RGB image, it has {channels} channel"
                      f"{'s' if channels != 1 else ''}")
        self.images.keep(name, image)
        return image

    # -- the whole project
    def project(self) -> Project:
        doc = self.document()
        name = self.field(doc, "name", "text", "")
        mesh_doc = self.field(doc, "mesh", "object", "")
        source = self.field(mesh_doc, "source", "text", "mesh.") if "source" in mesh_doc else ""
        counts = {key: self.field(mesh_doc, key, "count", "mesh.")
                  for key in ("welded_vertices", "render_vertices", "triangles")}
        arrays = {key: self.array(f"mesh/{key}.npy", dtype,
                                  tuple(counts[d] if isinstance(d, str) else d for d in dims),
                                  f"the mesh's {key}")
                  for key, (dtype, dims) in MESH_ARRAYS.items()}
        mesh = FaceMesh(**arrays, source=source)
        n = mesh.n_welded

        pose_names = [self.value(p, "name", f"poses[{i}]")
                      for i, p in enumerate(self.field(doc, "poses", "list", ""))]
        if NEUTRAL in pose_names:
            self.fail(f"project.json: a key pose is called '{NEUTRAL}', a reserved name")
        if len(set(pose_names)) != len(pose_names):
            self.fail("project.json: two key poses have the same name")
        poses = [KeyPose(p, self.array(_pose_member(i), np.float32, (n, 3), f"key pose '{p}'"))
                 for i, p in enumerate(pose_names)]

        textures = self.textures(doc)
        not_face = None
        if "not_face" in doc:
            not_face = self.array(self.field(doc, "not_face", "text", ""), np.bool_, (n,),
                                  "the not-face vertex flags")
        uv_tiles = self.uv_tiles(doc, mesh.n_vertices) if "uv_tiles" in doc else None
        influence = self.influence(self.field(doc, "influence", "object", ""))
        wdv = self.wdv(self.field(doc, "wdv", "object", ""), n)
        view = self.field(doc, "view", "object", "") if "view" in doc else {}
        check_camera(view, self.path)
        timeline = self.timeline(doc["timeline"]) if "timeline" in doc else Timeline()
        project = Project(name, mesh, poses, textures, influence=influence, wdv=wdv,
                          timeline=timeline, view=view, not_face=not_face,
                          uv_tiles=uv_tiles)
        unknown = {k: v for k, v in doc.items() if k not in KNOWN_KEYS}
        project.extra.update(unknown)
        check_project(project, self.path)  # names, links, WDV and timeline poses together
        return project

    def uv_tiles(self, doc: dict[str, Any], n_vertices: int) -> UvTiles:
        tiles_doc = self.field(doc, "uv_tiles", "object", "")
        try:
            layout = TileLayout.from_dict(tiles_doc)
            vertex_tile = self.array(self.field(tiles_doc, "vertex_tile", "text", "uv_tiles."),
                                     np.int16, (n_vertices,), "the vertices' UV tiles")
            return UvTiles(layout, vertex_tile)
        except StudioError as exc:
            self.fail(f"project.json: {exc.problem}")

    def textures(self, doc: dict[str, Any]) -> FaceTextures:
        diffuse, neutral, first = (self.image(f"textures/{key}.png", f"the {key} texture", False)
                                   for key in TEXTURES)
        names = [DEFAULT_WRINKLE_MAP]
        if "wrinkle_maps" in doc:
            names = [self.value(m, "name", f"wrinkle_maps[{i}]")
                     for i, m in enumerate(self.field(doc, "wrinkle_maps", "list", ""))]
            if not 1 <= len(names) <= MAX_WRINKLE_MAPS or len(set(names)) != len(names):
                self.fail(f"project.json: wrinkle_maps must name 1 to {MAX_WRINKLE_MAPS} "
                          "different wrinkled maps")
        maps = {names[0]: first}
        for i, map_name in enumerate(names[1:], start=1):
            maps[map_name] = self.image(_wrinkled_member(i), f"wrinkled map '{map_name}'", False)
        return FaceTextures(diffuse, neutral, wrinkle_maps=maps)

    def timeline(self, doc: Any) -> Timeline:
        doc = self.value(doc, "object", "timeline")
        try:
            return Timeline.from_dict(doc)
        except (ValueError, TypeError, KeyError, AttributeError, OverflowError) as exc:
            self.fail(f"project.json: the timeline is malformed ({exc})")

    def influence(self, doc: dict[str, Any]) -> InfluenceSetup:
        areas = []
        entries = self.field(doc, "areas", "list", "influence.")
        self.images.plan_masks([e.get("mask") for e in entries if isinstance(e, dict)],
                               self.read)
        for i, entry in enumerate(entries):
            where = f"influence.areas[{i}]."
            entry = self.value(entry, "object", where[:-1])
            area_name = self.field(entry, "name", "name", where)
            mask = self.image(self.field(entry, "mask", "text", where),
                              f"the mask of influence area '{area_name}'", True)
            if areas and mask.shape != areas[0].mask.shape:
                self.fail(f"the mask of influence area '{area_name}' is {_size(mask.shape)} "
                          f"pixels, the others are {_size(areas[0].mask.shape)}; all masks "
                          "must share one size")
            scale = np.float32(65535.0 if mask.dtype == np.uint16 else 255.0)
            areas.append(InfluenceArea(
                area_name, mask.astype(np.float32) / scale,
                colour=self.field(entry, "colour", "colour", where),
                activation=self.field(entry, "activation", "number", where),
                visible=self.field(entry, "visible", "bool", where),
                wrinkle_map=self.optional(entry, "wrinkle_map", "text", where, "")))
        links: dict[str, dict[str, float]] = {}
        for pose, gains in self.field(doc, "links", "object", "influence.").items():
            gains = self.value(gains, "object", f"influence.links.{pose}")
            links[pose] = {area: self.value(g, "number", f"influence.links.{pose}.{area}")
                           for area, g in gains.items()}
        return InfluenceSetup(areas, links)

    def wdv(self, doc: dict[str, Any], n: int) -> WdvSetup:
        areas = []
        for i, entry in enumerate(self.field(doc, "areas", "list", "wdv.")):
            where = f"wdv.areas[{i}]."
            entry = self.value(entry, "object", where[:-1])
            area_name = self.field(entry, "name", "name", where)
            what = f"WDV area '{area_name}'"
            areas.append(WdvArea(
                area_name, self.field(entry, "pose", "name", where),
                self.array(self.field(entry, "directions", "text", where), np.float32, (n, 3),
                           f"the directions of {what}"),
                self.array(self.field(entry, "lengths", "text", where), np.float32, (n,),
                           f"the lengths of {what}"),
                colour=self.field(entry, "colour", "colour", where),
                cone_angle_deg=self.field(entry, "cone_angle_deg", "number", where),
                enabled=self.field(entry, "enabled", "bool", where),
                wrinkle_map=self.optional(entry, "wrinkle_map", "text", where, ""),
                cone_angles_deg=self.array(entry["cones"], np.float32, (n,),
                                           f"the painted cone angles of {what}")
                if "cones" in entry else None))
        return WdvSetup(areas, self.field(doc, "expression_factor", "number", "wdv."),
                        self.field(doc, "scale_free", "bool", "wdv."))


_KIND_WORDS = {"text": "text", "bool": "true or false", "object": "a JSON object",
               "list": "a JSON list"}


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"the number {text[:20]} is too large")
    return value
