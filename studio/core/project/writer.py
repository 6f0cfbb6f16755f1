"""Saving a project: the archive written all or nothing, the previous version kept as a backup."""
from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import time
import zipfile
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

import numpy as np

from studio.core.files.atomic_write import atomic_output
from studio.core.files.budgets import check_json_depth
from studio.core.files.cores import usable_cores
from studio.core.files.errors import ProjectError
from studio.core.files.png import encode_png
from studio.core.files.processes import process_tag
from studio.core.project.mask_store import mask_members
from studio.core.project.model import Project
from studio.core.project.schema import (
    FORMAT,
    FORMAT_VERSION,
    KNOWN_KEYS,
    MAX_JSON_BYTES,
    MESH_ARRAYS,
    NOT_FACE_MEMBER,
    TEXTURES,
    VERTEX_TILE_MEMBER,
    check_project,
    cones_member,
    mask_member,
    pose_member,
    tone_member,
    wrinkled_member,
)
from studio.core.wrinkles.response import curves_to_dict

Array = np.ndarray

ENCODE_THREADS = 4  # images compressed at once (each holds one image's blocks)
# zlib's level for the arrays (mesh, poses, vectors): float data barely compresses further at
# the default 6 — on the sample 12.97 MB at 1 against 12.70 MB at 6 (2 % more), in two thirds
# of the CPU time (0.60 s against 0.89 s). The images keep 6: at 1 they grew by 37 %.
ARRAY_LEVEL = 1


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
    _check_document(document, path)
    with atomic_output(path, ProjectError, what="project", verb="save",
                       before_replace=keep_backup if backup else None) as handle:
        _write_archive(handle, project, document)


def backup_path(path: str | Path) -> Path:
    """Where save_project keeps the previous version of ``path``."""
    path = Path(path)
    return path.with_name(path.name + ".bak")


def keep_backup(target: Path) -> None:
    """Keep the file about to be replaced as ``NAME.bak``, replacing an older backup atomically.

    A backup that cannot be made (no room, no hard links and no space to copy) does not stop the
    save: the new version matters more than the previous one.
    """
    if not target.is_file():
        return
    bak = backup_path(target)
    staging = bak.with_name(f".{bak.name}.{process_tag()}.staging")
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
    members = list(_members(project, document))
    with zipfile.ZipFile(handle, "w", zipfile.ZIP_DEFLATED, compresslevel=ARRAY_LEVEL) as archive:
        for (name, _, _), data in zip(members, _encoded(members), strict=True):
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.compress_type = zipfile.ZIP_STORED if name.endswith(".png") else \
                zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, data)


def _encoded(members: list[tuple[str, Callable[[Any], bytes], Any]]) -> Iterator[bytes]:
    """Each member's bytes, in order. The images are compressed side by side on threads (zlib
    lets go of the interpreter); once the interpreter is shutting down no pool may start a
    thread, so a save that runs then — the sample kept in the cache by a thread that outlives
    a studio closed at once, an autosave finishing its write — encodes one member after
    another instead of losing the file."""
    pool = ThreadPoolExecutor(usable_cores(ENCODE_THREADS))
    try:
        try:
            futures = [pool.submit(_encode, member) for member in members]
        except RuntimeError:  # "cannot schedule new futures after interpreter shutdown"
            futures = None
        if futures is None:
            for member in members:
                yield _encode(member)
        else:
            for future in futures:
                yield future.result()
    finally:
        pool.shutdown(cancel_futures=True)


def _encode(member: tuple[str, Callable[[Any], bytes], Any]) -> bytes:
    _, encoder, value = member
    return encoder(value)


def _members(project: Project,
             document: bytes) -> Iterator[tuple[str, Callable[[Any], bytes], Any]]:
    """(name, encoder, value) for every member, so bytes exist one member at a time."""
    yield "project.json", bytes, document
    for key in MESH_ARRAYS:
        yield f"mesh/{key}.npy", _npy, getattr(project.mesh, key)
    for i, pose in enumerate(project.poses):
        yield pose_member(i), _npy, pose.positions
    if project.not_face is not None:
        yield NOT_FACE_MEMBER, _npy, project.not_face
    if project.uv_tiles is not None:
        yield VERTEX_TILE_MEMBER, _npy, project.uv_tiles.vertex_tile
    for key in TEXTURES:
        yield f"textures/{key}.png", encode_png, getattr(project.textures, key)
    for i, image in enumerate(list(project.textures.wrinkle_maps.values())[1:], start=1):
        yield wrinkled_member(i), encode_png, image
    for i, name in enumerate(project.textures.wrinkle_map_names):
        for kind, maps in (("cavity", project.textures.cavity_maps),
                           ("colour", project.textures.colour_maps)):
            if name in maps:
                yield tone_member(kind, i), encode_png, maps[name]
    written = set()  # masks shared by several areas are stored once
    for area, member in zip(project.influence.areas,
                            mask_members(project.influence.areas, mask_member), strict=True):
        if member not in written:
            written.add(member)
            yield member, _mask_png, area.mask
    for i, wdv in enumerate(project.wdv.areas):
        yield f"wdv/{i:02d}_directions.npy", _npy, wdv.directions
        yield f"wdv/{i:02d}_lengths.npy", _npy, wdv.lengths
        if wdv.cone_angles_deg is not None:
            yield cones_member(i), _npy, wdv.cone_angles_deg


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
                          influence.areas, mask_member), strict=True)],
            "links": {pose: {area: float(gain) for area, gain in gains.items()}
                      for pose, gains in influence.links.items()},
            **({"curves": curves} if (curves := curves_to_dict(influence.curves)) else {}),
        },
        "wdv": {
            "expression_factor": float(project.wdv.expression_factor),
            "scale_free": bool(project.wdv.scale_free),
            "areas": [{"name": a.name, "pose": a.pose, "colour": [int(c) for c in a.colour],
                       "cone_angle_deg": float(a.cone_angle_deg), "enabled": bool(a.enabled),
                       "wrinkle_map": a.wrinkle_map,
                       **({"cones": cones_member(i)} if a.cone_angles_deg is not None else {}),
                       "directions": f"wdv/{i:02d}_directions.npy",
                       "lengths": f"wdv/{i:02d}_lengths.npy"}
                      for i, a in enumerate(project.wdv.areas)],
        },
        **({"furrows": furrows} if (furrows := project.furrows.pruned(
            project.pose_names, project.textures.wrinkle_map_names).to_dict()) else {}),
        "timeline": project.timeline.to_dict(),
        "view": project.view,
    })
    try:
        text = json.dumps(doc, indent=1, ensure_ascii=False, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as exc:
        raise ProjectError(f"cannot save the project: its view or timeline settings cannot be "
                           f"written as JSON ({exc})", path) from None
    return text.encode("utf-8")



def _check_document(document: bytes, path: Path) -> None:
    """Refuse to write a project.json the reader would refuse: over its size, nesting or
    container budgets (a timeline of millions of keys imported from an animation would make a
    file that cannot be opened again)."""
    if len(document) > MAX_JSON_BYTES:
        raise ProjectError(f"cannot save the project: its description would be "
                           f"{len(document) >> 20} MB, more than the {MAX_JSON_BYTES >> 20} MB "
                           "a project can hold (a timeline with too many keys?)", path)
    check_json_depth(document, "the project description", path, ProjectError)


def _npy(array: Array) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def _mask_png(mask: Array) -> bytes:
    """Float mask in [0, 1] -> 16-bit greyscale PNG, the nearest of 65536 levels."""
    return encode_png(np.rint(np.clip(mask, 0.0, 1.0) * 65535.0).astype(np.uint16))

