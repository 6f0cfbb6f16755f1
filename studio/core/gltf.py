"""glTF 2.0 in and out: faces with morph targets become projects, projects become GLB files an
engine can use.

Import: the first triangle primitive with UVs; its morph targets become key poses (named from
``extras.targetNames``); the material's base-colour and normal textures become the diffuse and
neutral normal maps. Export: render vertices with UVs, one morph target per key pose, the
textures, and each technique-2 area as custom vertex attributes ``_WRINKLE_DIR_<n>`` (VEC3) and
``_WRINKLE_LEN_<n>`` (SCALAR), plus ``_WRINKLE_CONE_<n>`` (painted cone angles, degrees) where
painted and ``_NOT_FACE`` (1 on vertices never wrinkled) where marked. Everything else the
studio authored (masks as 16-bit PNG images, further wrinkled maps, which map each area reveals,
links, cone angles, the timeline) rides in ``extras.wrinkleStudio``, so a file exported here
imports back with nothing lost.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

from studio.core.errors import MeshError
from studio.core.images import decode_image
from studio.core.influence import InfluenceArea, InfluenceSetup
from studio.core.mesh import FaceMesh
from studio.core.meshio import mesh_from_render_vertices
from studio.core.png import encode_png
from studio.core.poses import KeyPose
from studio.core.project import Project
from studio.core.textures import FaceTextures, flat_normal_map
from studio.core.timeline import Timeline
from studio.core.wdv import WdvArea, WdvSetup

Array = np.ndarray
MAGIC, JSON_CHUNK, BIN_CHUNK = b"glTF", 0x4E4F534A, 0x004E4942
COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
              5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
EXTRAS_KEY = "wrinkleStudio"


# --- reading ---------------------------------------------------------------------------------
class _Gltf:
    """A parsed glTF document and its buffers, with typed accessors."""

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise MeshError(f"cannot read the file: {exc.strerror or exc}", path) from None
        if data[:4] == MAGIC:
            self.doc, binary = self._parse_glb(data)
        else:
            try:
                self.doc = json.loads(data.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise MeshError(f"not a glTF file ({exc})", path) from None
            binary = None
        if not isinstance(self.doc, dict) or not str(self.doc.get("asset", {}).get("version",
                                                                                    "")).startswith("2"):
            raise MeshError("not a glTF 2.0 file (asset.version is not 2.x)", path)
        self.buffers = [self._buffer(b, binary) for b in self.doc.get("buffers", [])]

    def _parse_glb(self, data: bytes) -> tuple[dict, bytes | None]:
        if len(data) < 20:
            raise MeshError("the GLB file is truncated", self.path)
        _, version, length = struct.unpack_from("<4sII", data)
        if version != 2:
            raise MeshError(f"the GLB header is damaged or not version 2 ({version})", self.path)
        if length > len(data):
            raise MeshError(f"the GLB file is truncated ({len(data)} of {length} bytes)",
                            self.path)
        doc, binary, offset = None, None, 12
        while offset + 8 <= length:
            size, kind = struct.unpack_from("<II", data, offset)
            chunk = data[offset + 8: offset + 8 + size]
            if len(chunk) != size:
                raise MeshError("a GLB chunk is truncated", self.path)
            if kind == JSON_CHUNK and doc is None:
                try:
                    doc = json.loads(chunk.decode("utf-8"))
                except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                    raise MeshError(f"the GLB's JSON is damaged ({exc})", self.path) from None
            elif kind == BIN_CHUNK and binary is None:
                binary = chunk
            offset += 8 + size
        if doc is None:
            raise MeshError("the GLB file has no JSON chunk", self.path)
        return doc, binary

    def _buffer(self, spec: dict, binary: bytes | None) -> bytes:
        uri = spec.get("uri")
        if uri is None:
            if binary is None:
                raise MeshError("a buffer has no data", self.path)
            return binary
        if uri.startswith("data:"):
            try:
                return base64.b64decode(uri.split(",", 1)[1])
            except (IndexError, ValueError) as exc:
                raise MeshError(f"a buffer's data URI is damaged ({exc})", self.path) from None
        target = (self.path.parent / uri).resolve()
        if self.path.parent.resolve() not in target.parents:
            raise MeshError(f"a buffer refers outside the file's folder: '{uri}'", self.path)
        try:
            return target.read_bytes()
        except OSError as exc:
            raise MeshError(f"cannot read the buffer '{uri}': {exc.strerror}", self.path) from None

    def _view(self, index: int) -> tuple[bytes, int, int | None]:
        view = self.doc["bufferViews"][index]
        buffer = self.buffers[view["buffer"]]
        start = view.get("byteOffset", 0)
        end = start + view["byteLength"]
        if end > len(buffer):
            raise MeshError("a buffer view reaches past its buffer's end", self.path)
        return buffer, start, view.get("byteStride")

    def accessor(self, index: int) -> Array:
        try:
            acc = self.doc["accessors"][index]
            if "sparse" in acc:
                raise MeshError("sparse accessors are not supported; re-export without them",
                                self.path)
            dtype = np.dtype(COMPONENTS[acc["componentType"]])
            width, count = WIDTH[acc["type"]], acc["count"]
            buffer, start, stride = self._view(acc["bufferView"])
            start += acc.get("byteOffset", 0)
            item = dtype.itemsize * width
            stride = stride or item
            if start + stride * (count - 1) + item > len(buffer):
                raise MeshError(f"accessor {index} reaches past its buffer's end", self.path)
            raw = np.ndarray((count, width), dtype, buffer, start, (stride, dtype.itemsize))
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise MeshError(f"accessor {index} is malformed ({exc})", self.path) from None
        values = raw.astype(np.float64)
        if acc.get("normalized") and dtype.kind in "iu":
            values /= float(np.iinfo(dtype).max)
        return values

    def image(self, index: int) -> Array:
        try:
            spec = self.doc["images"][index]
            if "bufferView" in spec:
                buffer, start, _ = self._view(spec["bufferView"])
                length = self.doc["bufferViews"][spec["bufferView"]]["byteLength"]
                data = buffer[start:start + length]
            else:
                data = self._buffer({"uri": spec["uri"]}, None)
        except (KeyError, IndexError, TypeError) as exc:
            raise MeshError(f"image {index} is malformed ({exc})", self.path) from None
        return decode_image(data, f"{self.path} (image {index})")

    def texture_image(self, info: dict | None) -> Array | None:
        if not info:
            return None
        try:
            source = self.doc["textures"][info["index"]]["source"]
        except (KeyError, IndexError, TypeError):
            raise MeshError("a material refers to a texture that does not exist",
                            self.path) from None
        return self.image(source)


def _rgb(image: Array | None, fallback: Array) -> Array:
    if image is None:
        return fallback
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    return np.ascontiguousarray(image[:, :, :3])


def _first_occurrence(weld: Array, n_welded: int) -> Array:
    first = np.empty(n_welded, np.int64)
    first[weld[::-1]] = np.arange(len(weld))[::-1]
    return first


def load_gltf(path: str | Path) -> Project:
    """A project from a glTF 2.0 file (.glb or .gltf)."""
    path = Path(path)
    g = _Gltf(path)
    mesh_spec, prim = _triangle_primitive(g)
    attrs = prim["attributes"]
    positions = g.accessor(attrs["POSITION"])
    uvs = g.accessor(attrs["TEXCOORD_0"])[:, :2] * [1.0, -1.0] + [0.0, 1.0]  # glTF v points down
    if "indices" in prim:
        triangles = g.accessor(prim["indices"]).astype(np.int64).reshape(-1, 3)
    else:
        triangles = np.arange(len(positions)).reshape(-1, 3)
    if "_WELD" in attrs:  # written by the studio: keep its welded numbering exactly
        mesh = _mesh_with_weld(g, positions, triangles, uvs, g.accessor(attrs["_WELD"])[:, 0])
    else:
        mesh = mesh_from_render_vertices(path, positions, triangles, uvs)
    first = _first_occurrence(mesh.weld, mesh.n_welded)
    names = (mesh_spec.get("extras", {}).get("targetNames")
             or prim.get("extras", {}).get("targetNames") or [])
    poses = []
    for i, target in enumerate(prim.get("targets", [])):
        if "POSITION" not in target:
            continue
        moved = positions + g.accessor(target["POSITION"])
        name = str(names[i]) if i < len(names) else f"target_{i}"
        poses.append(KeyPose(name, moved[first]))
    material = _material(g, prim)
    pbr = material.get("pbrMetallicRoughness", {})
    extras = g.doc.get("extras", {}).get(EXTRAS_KEY, {})
    textures = FaceTextures(
        diffuse=_rgb(g.texture_image(pbr.get("baseColorTexture")), _plain_skin()),
        normal_neutral=_rgb(g.texture_image(material.get("normalTexture")), flat_normal_map()),
        normal_wrinkled=_rgb(g.texture_image(material.get("extras", {}).get(
            "wrinkleNormalTexture")), flat_normal_map()))
    project = Project(str(extras.get("name", path.stem)), mesh, poses, textures)
    try:
        _read_studio_extras(g, project, extras, attrs, first)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise MeshError(f"the studio data in extras.{EXTRAS_KEY} is malformed ({exc})",
                        path) from None
    return project


def _mesh_with_weld(g: _Gltf, positions: Array, triangles: Array, uvs: Array,
                    weld_values: Array) -> FaceMesh:
    weld = weld_values.astype(np.int64)
    if (weld != weld_values).any() or weld.min() < 0 or weld.max() >= len(weld):
        raise MeshError("the _WELD attribute does not hold vertex numbers", g.path)
    n = int(weld.max()) + 1
    first = _first_occurrence(weld, n)
    if not np.array_equal(positions[first][weld], positions):
        raise MeshError("vertices welded by _WELD are not at one position", g.path)
    return FaceMesh(positions[first], triangles, uvs, weld, str(g.path))


def _plain_skin() -> Array:
    from studio.core.assemble import plain_diffuse

    return plain_diffuse()


def _triangle_primitive(g: _Gltf) -> tuple[dict, dict]:
    for mesh in g.doc.get("meshes", []):
        for prim in mesh.get("primitives", []):
            attrs = prim.get("attributes", {})
            if prim.get("mode", 4) == 4 and "POSITION" in attrs and "TEXCOORD_0" in attrs:
                return mesh, prim
    if any("POSITION" in p.get("attributes", {}) for m in g.doc.get("meshes", [])
           for p in m.get("primitives", [])):
        raise MeshError("the mesh has no texture coordinates (TEXCOORD_0)", g.path)
    raise MeshError("the file holds no triangle mesh", g.path)


def _material(g: _Gltf, prim: dict) -> dict:
    try:
        return g.doc["materials"][prim["material"]] if "material" in prim else {}
    except (KeyError, IndexError, TypeError):
        raise MeshError("the mesh refers to a material that does not exist", g.path) from None


def _read_studio_extras(g: _Gltf, project: Project, extras: dict, attrs: dict,
                        first: Array) -> None:
    areas = []
    for spec in extras.get("influence", {}).get("areas", []):
        mask = g.image(spec["image"]).astype(np.float32) / 65535.0
        areas.append(InfluenceArea(spec["name"], mask, tuple(spec.get("colour", (255, 128, 0))),
                                   float(spec.get("activation", 0.0)),
                                   bool(spec.get("visible", True)),
                                   str(spec.get("wrinkle_map", ""))))
    project.influence = InfluenceSetup(areas, extras.get("influence", {}).get("links", {}))
    if extras.get("wrinkle_maps"):
        tex = project.textures
        maps = {str(m["name"]): _rgb(g.image(m["image"]), tex.normal_wrinkled)
                for m in extras["wrinkle_maps"]}
        project.textures = FaceTextures(tex.diffuse, tex.normal_neutral, wrinkle_maps=maps)
    if "_NOT_FACE" in attrs:
        project.not_face = g.accessor(attrs["_NOT_FACE"])[first].ravel() > 0.5
    wdv = extras.get("wdv", {})
    wdv_areas = []
    for n, spec in enumerate(wdv.get("areas", [])):
        dirs = g.accessor(attrs[f"_WRINKLE_DIR_{n}"])[first]
        lengths = g.accessor(attrs[f"_WRINKLE_LEN_{n}"])[first, 0]
        cones = (g.accessor(attrs[f"_WRINKLE_CONE_{n}"])[first, 0]
                 if f"_WRINKLE_CONE_{n}" in attrs else None)
        wdv_areas.append(WdvArea(spec["name"], spec["pose"], dirs, lengths,
                                 tuple(spec.get("colour", (0, 170, 255))),
                                 float(spec.get("cone_angle_deg", 20.0)),
                                 bool(spec.get("enabled", True)),
                                 str(spec.get("wrinkle_map", "")), cones))
    project.wdv = WdvSetup(wdv_areas, float(wdv.get("expression_factor", 1.0)),
                           bool(wdv.get("scale_free", True)))
    if "timeline" in extras:
        project.timeline = Timeline.from_dict(extras["timeline"])


# --- writing ---------------------------------------------------------------------------------
class _Builder:
    """Accumulates buffer views and accessors for one GLB binary chunk."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def view(self, data: bytes, target: int | None = None) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.blob += data
        self.views.append(view)
        return len(self.views) - 1

    def accessor(self, array: Array, kind: str, bounds: bool = False,
                 indices: bool = False) -> int:
        array = np.ascontiguousarray(array, np.uint32 if indices else np.float32)
        acc = {"bufferView": self.view(array.tobytes(), 34963 if indices else 34962),
               "componentType": 5125 if indices else 5126, "count": len(array), "type": kind}
        if bounds:
            flat = array.reshape(len(array), -1)
            acc["min"] = flat.min(axis=0).tolist()
            acc["max"] = flat.max(axis=0).tolist()
        self.accessors.append(acc)
        return len(self.accessors) - 1


def save_gltf(project: Project, path: str | Path) -> None:
    """Write the project as a binary glTF (.glb)."""
    path = Path(path)
    mesh, weld = project.mesh, project.mesh.weld
    b = _Builder()
    rest = mesh.rest[weld]
    attributes = {
        "POSITION": b.accessor(rest, "VEC3", bounds=True),
        "TEXCOORD_0": b.accessor(mesh.uvs * [1.0, -1.0] + [0.0, 1.0], "VEC2"),
        "_WELD": b.accessor(weld, "SCALAR"),  # exact in float32 below 2**24 vertices
    }
    for n, area in enumerate(project.wdv.areas):
        attributes[f"_WRINKLE_DIR_{n}"] = b.accessor(area.directions[weld], "VEC3")
        attributes[f"_WRINKLE_LEN_{n}"] = b.accessor(area.lengths[weld], "SCALAR")
        if area.cone_angles_deg is not None:  # painted per-vertex cone angles, degrees
            attributes[f"_WRINKLE_CONE_{n}"] = b.accessor(area.cone_angles_deg[weld], "SCALAR")
    if project.not_face is not None:
        attributes["_NOT_FACE"] = b.accessor(project.not_face[weld], "SCALAR")
    targets = [{"POSITION": b.accessor(pose.positions[weld] - rest, "VEC3", bounds=True)}
               for pose in project.poses]
    images: list[dict] = []

    def image(array: Array, name: str) -> int:
        images.append({"bufferView": b.view(encode_png(array)), "mimeType": "image/png",
                       "name": name})
        return len(images) - 1

    tex = project.textures
    textures = [{"source": image(tex.diffuse, "diffuse")},
                {"source": image(tex.normal_neutral, "normal_neutral")},
                {"source": image(tex.normal_wrinkled, "normal_wrinkled")}]
    wrinkle_maps = [{"name": name, "image": 2 if i == 0 else image(im, f"wrinkled: {name}")}
                    for i, (name, im) in enumerate(tex.wrinkle_maps.items())]
    influence = {"links": project.influence.links, "areas": [
        {"name": a.name, "colour": list(a.colour), "activation": a.activation,
         "visible": a.visible, "wrinkle_map": a.wrinkle_map,
         "image": image(np.round(a.mask * 65535.0).astype(np.uint16), f"mask: {a.name}")}
        for a in project.influence.areas]}
    primitive = {"attributes": attributes, "indices": b.accessor(mesh.triangles.ravel(),
                                                                  "SCALAR", indices=True),
                 "material": 0, "mode": 4}
    if targets:
        primitive["targets"] = targets
    doc = {
        "asset": {"version": "2.0", "generator": "Wrinkle Studio"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": project.name}],
        "meshes": [{"name": project.name, "primitives": [primitive],
                    "weights": [0.0] * len(targets),
                    "extras": {"targetNames": [p.name for p in project.poses]}}],
        "materials": [{"name": "skin", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.7},
            "normalTexture": {"index": 1}, "extras": {"wrinkleNormalTexture": {"index": 2}}}],
        "textures": textures, "images": images,
        "accessors": b.accessors, "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.blob)}],
        "extras": {EXTRAS_KEY: {
            "name": project.name, "influence": influence, "timeline": project.timeline.to_dict(),
            "wrinkle_maps": wrinkle_maps,
            "wdv": {"expression_factor": project.wdv.expression_factor,
                    "scale_free": project.wdv.scale_free,
                    "areas": [{"name": a.name, "pose": a.pose, "colour": list(a.colour),
                               "cone_angle_deg": a.cone_angle_deg, "enabled": a.enabled,
                               "wrinkle_map": a.wrinkle_map}
                              for a in project.wdv.areas]}}},
    }
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    blob = bytes(b.blob) + b"\0" * (-len(b.blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    data = (struct.pack("<4sII", MAGIC, 2, total) + struct.pack("<II", len(text), JSON_CHUNK)
            + text + struct.pack("<II", len(blob), BIN_CHUNK) + blob)
    from studio.core.safe_io import write_atomic

    write_atomic(path, data, MeshError, what="file")
