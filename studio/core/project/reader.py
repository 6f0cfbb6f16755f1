"""Loading a project: every member name, size, JSON field, array and image checked before use."""
from __future__ import annotations

import errno
import json
import math
import re
import struct
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, NoReturn

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

import numpy as np

from studio.core.animation.poses import NEUTRAL, KeyPose
from studio.core.animation.timeline import Timeline
from studio.core.files.budgets import (
    MESH_TRIANGLES,
    MESH_VERTICES,
    POSES,
    Budget,
    check_json_depth,
)
from studio.core.files.errors import Cancelled, ProjectError, StudioError
from studio.core.files.input_checks import check_camera
from studio.core.files.npy import read_npy_header
from studio.core.files.png import HEADER_BYTES, PngError, max_file_bytes, png_header, read_png
from studio.core.files.safe_io import os_reason, require_regular
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import TileLayout, UvTiles
from studio.core.project.mask_store import ImageBudget
from studio.core.project.migrations import migrate
from studio.core.project.model import Project
from studio.core.project.schema import (
    FORMAT,
    KNOWN_KEYS,
    MAX_JSON_BYTES,
    MAX_MEMBER_BYTES,
    MAX_MEMBERS,
    MAX_PIXEL_BYTES,
    MAX_TOTAL_BYTES,
    MESH_ARRAYS,
    TEXTURES,
    check_project,
    image_size,
    pose_member,
    tone_member,
    wrinkled_member,
)
from studio.core.wrinkles.furrow_controls import FurrowSettings
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.response import curves_from_dict
from studio.core.wrinkles.textures import DEFAULT_WRINKLE_MAP, MAX_WRINKLE_MAPS, FaceTextures
from studio.core.wrinkles.wdv import WdvArea, WdvSetup

Array = np.ndarray

# What corrupt bytes can make the standard library, numpy or Pillow raise. load_project turns
# each into a ProjectError; anything else escaping is a bug in this module. (RuntimeError also
# covers zipfile's error for a compression method it does not know.)
_DAMAGE = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, struct.error, EOFError,
           OSError, ValueError, KeyError, IndexError, TypeError, ArithmeticError, RuntimeError,
           SyntaxError, MemoryError, AttributeError)


Progress = Callable[[int, int], bool]  # (bytes read, bytes in all) -> go on?
_PIECE = 1 << 20  # bytes inflated at a time into a member's buffer


def load_project(path: str | Path, progress: Progress | None = None) -> Project:
    """Read a ``.wrinkle`` file, checking every part; ProjectError(one sentence, path) if bad.

    ``progress(done, total)`` is called after each member is read (bytes unpacked so far and in
    all); returning False stops the load with ``Cancelled`` (the GUI's Cancel button, run on a
    worker thread)."""
    path = Path(path)
    try:
        with _open_archive(path) as archive:
            return _Loader(archive, path, progress).project()
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
        reason = os_reason(exc, str(path))
        raise ProjectError(f"cannot read the project file: {reason}", path) from exc
    except _DAMAGE as exc:
        detail = str(exc) or type(exc).__name__
        raise ProjectError(f"the project file is damaged ({detail})", path) from exc


_CANNOT_READ = {errno.EACCES, errno.EPERM, errno.EIO, errno.ENOTDIR, errno.EISDIR, errno.ELOOP,
                errno.ENAMETOOLONG}


def _open_archive(path: Path) -> zipfile.ZipFile:
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

    def __init__(self, archive: zipfile.ZipFile, path: Path,
                 progress: Progress | None = None) -> None:
        self.archive = archive
        self.path = path
        self.sizes = self._check_directory()
        self.progress = progress
        self.done, self.total = 0, sum(self.sizes.values())
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

    def open(self, name: Any, what: str) -> IO[bytes]:
        """The member ``name`` as a stream, nothing inflated yet (a header can be read first)."""
        if not isinstance(name, str) or _unsafe_name(name):
            self.fail(f"project.json names an invalid member {name!r} for {what}")
        if name not in self.sizes:
            self.fail(f"the project file is missing '{name}' ({what})")
        return self.archive.open(name)

    def rest(self, member: IO[bytes], name: str, what: str, done: int,
             head: bytes = b"") -> bytearray:
        """``head`` and the rest of ``member``, of which ``done`` bytes were read already.

        Read in pieces into one buffer, so that a member costs its own size once; callers
        check what its header declares against its size before calling this."""
        size = self.sizes[name]
        buffer = bytearray(size - done + len(head))
        buffer[:len(head)] = head
        view = memoryview(buffer)
        pos = len(head)
        while pos < len(buffer):
            count = member.readinto(view[pos:pos + _PIECE])
            if not count:
                self.fail(f"the member '{name}' ({what}) is truncated or damaged")
            pos += count
        view.release()
        self.done += size
        if self.progress is not None and not self.progress(self.done, self.total):
            raise Cancelled()
        return buffer

    def read(self, name: Any, what: str) -> bytes:
        """The whole member (project.json: its size is checked against MAX_JSON_BYTES)."""
        with self.open(name, what) as member:
            return bytes(self.rest(member, name, what, 0))

    def png_head(self, name: Any, what: str) -> bytes:
        """The signature and IHDR of a PNG member, the rest not inflated."""
        with self.open(name, what) as member:
            return member.read(HEADER_BYTES)

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
        except json.JSONDecodeError as exc:
            self.fail(f"project.json is not valid JSON ({exc})")
        except ValueError as exc:  # a constant, a float or an integer too large to be a value
            if "digits" in str(exc) and "sys.set_int_max_str_digits" in str(exc):
                self.fail("project.json holds a number with thousands of digits, which no "
                          "project value can be")
            self.fail(f"project.json is not valid JSON ({exc})")
        if not isinstance(doc, dict):
            self.fail("project.json does not hold a JSON object")
        if doc.get("format") != FORMAT:
            self.fail("this zip archive is not a Wrinkle Studio project (project.json has no "
                      f"\"format\": \"{FORMAT}\")")
        return migrate(doc, self.fail)

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
        """The ``.npy`` member ``name``, its header checked against ``dtype``, ``shape`` and
        the member's size before its data is inflated (a small hostile file cannot make the
        studio allocate gigabytes to refuse it)."""
        expected = np.dtype(dtype)
        with self.open(name, what) as member:
            try:
                header = read_npy_header(member)
            except ValueError as exc:
                self.fail(f"'{name}' ({what}) is not a valid .npy array ({exc})")
            if header.dtype.kind != expected.kind or header.dtype.itemsize != expected.itemsize:
                self.fail(f"'{name}' ({what}) holds {header.dtype} values, expected {expected}")
            if header.shape != shape:
                self.fail(f"'{name}' ({what}) has shape {header.shape}, expected {shape}")
            if self.sizes[name] != header.size + header.data_bytes:
                self.fail(f"'{name}' ({what}) is truncated or has extra bytes")
            data = self.rest(member, name, what, header.size)
        array = np.frombuffer(data, dtype=header.dtype).reshape(
            shape, order="F" if header.fortran_order else "C")
        array = np.ascontiguousarray(array, dtype=expected)  # native byte order, C order
        if expected.kind == "f" and not np.isfinite(array).all():
            self.fail(f"'{name}' ({what}) contains non-finite values (NaN or infinity)")
        return array

    def image(self, name: Any, what: str, grey: bool) -> Array:
        shared = self.images.shared(name, what, grey)
        if shared is not None:
            return shared
        with self.open(name, what) as member:
            head = member.read(HEADER_BYTES)
            try:  # the budgets and the member's size from the header, before inflating it
                self.images.claim(name, head, what, grey)
                limit = max_file_bytes(head)
            except PngError as exc:
                self.fail(f"'{name}' ({what}) cannot be read: {exc}")
            if self.sizes[name] > limit:
                width, height, *_ = png_header(head)
                self.fail(f"'{name}' ({what}) is {self.sizes[name]:,} bytes, more than a PNG "
                          f"of its {width}×{height} pixels can take ({limit:,}): a damaged or "
                          "hostile file")
            data = self.rest(member, name, what, len(head), head)
        try:
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
        for key, budget in _COUNT_BUDGETS.items():  # before any array is inflated
            budget.check(counts[key], f"project.json: mesh.{key}", self.path, ProjectError)
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
        POSES.check(len(pose_names), "project.json: the pose count", self.path,
                    ProjectError)
        if len(set(pose_names)) != len(pose_names):
            self.fail("project.json: two key poses have the same name")
        poses = [KeyPose(p, self.array(pose_member(i), np.float32, (n, 3), f"key pose '{p}'"))
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
                          uv_tiles=uv_tiles, furrows=self.furrows(doc.get("furrows", {})))
        unknown = {k: v for k, v in doc.items() if k not in KNOWN_KEYS}
        project.extra.update(unknown)
        check_project(project, self.path)  # names, links, WDV and timeline poses together
        return project

    def uv_tiles(self, doc: dict[str, Any], n_vertices: int) -> UvTiles:
        tiles_doc = self.field(doc, "uv_tiles", "object", "")
        member = self.field(tiles_doc, "vertex_tile", "text", "uv_tiles.")
        # the loader's own errors already name project.json or the member: only the layout's
        # and the tiles' checks need the prefix
        try:
            layout = TileLayout.from_dict(tiles_doc)
        except StudioError as exc:
            self.fail(f"project.json: {exc.problem}")
        vertex_tile = self.array(member, np.int16, (n_vertices,), "the vertices' UV tiles")
        try:
            return UvTiles(layout, vertex_tile)
        except StudioError as exc:
            self.fail(f"{member}: {exc.problem}")

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
            maps[map_name] = self.image(wrinkled_member(i), f"wrinkled map '{map_name}'", False)
        textures = FaceTextures(diffuse, neutral, wrinkle_maps=maps)
        for i, map_name in enumerate(names):
            cavity, colour = (self.image(member, f"the {kind} map of '{map_name}'",
                                         kind == "cavity") if member in self.sizes else None
                              for kind in ("cavity", "colour")
                              for member in [tone_member(kind, i)])
            try:
                textures.set_tone(map_name, cavity, colour)
            except StudioError as exc:
                self.fail(exc.problem)
        return textures

    def furrows(self, doc: Any) -> FurrowSettings:
        try:
            return FurrowSettings.from_dict(doc)
        except ValueError as exc:
            self.fail(f"project.json: the furrow settings are malformed ({exc})")

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
                               self.png_head)
        for i, entry in enumerate(entries):
            where = f"influence.areas[{i}]."
            entry = self.value(entry, "object", where[:-1])
            area_name = self.field(entry, "name", "name", where)
            mask = self.image(self.field(entry, "mask", "text", where),
                              f"the mask of influence area '{area_name}'", True)
            if areas and mask.shape != areas[0].mask.shape:
                self.fail(f"the mask of influence area '{area_name}' is {image_size(mask.shape)} "
                          f"pixels, the others are {image_size(areas[0].mask.shape)}; all masks "
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
        curves = self.optional(doc, "curves", "object", "influence.", {})
        try:
            return InfluenceSetup(areas, links, curves_from_dict(curves))
        except ValueError as exc:  # names the pose, area and field: "smile.cheek: kind …"
            self.fail(f"project.json: influence.curves.{exc}")

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


_COUNT_BUDGETS: dict[str, Budget] = {"welded_vertices": MESH_VERTICES,
                                     "render_vertices": MESH_VERTICES,
                                     "triangles": MESH_TRIANGLES}
_KIND_WORDS = {"text": "text", "bool": "true or false", "object": "a JSON object",
               "list": "a JSON list"}


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"the number {text[:20]} is too large")
    return value
