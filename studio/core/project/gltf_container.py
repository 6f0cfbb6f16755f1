"""The glTF 2.0 container: the JSON document, its buffers (GLB chunk, data URIs, files beside
it), typed accessors (strided, normalized, quantized, sparse) and images.

Before any buffer is read the document's ``extensionsRequired`` is checked: a file compressed
with meshopt or Draco is refused naming the extension and a command that decompresses it (the
compressed buffers would otherwise look damaged), and any other required extension this reader
does not know is refused by name. Neither decoder is a dependency yet: the ``meshoptimizer``
package on PyPI is an alpha source package that needs a compiler, and DracoPy's decoding of
files with morph targets (whose vertex order must match the uncompressed targets) is unverified;
the tools named decompress such files in one command.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

from studio.core.files.budgets import FILE_BYTES, MESH_VERTICES, check_json_depth
from studio.core.files.errors import MeshError
from studio.core.files.images import decode_image
from studio.core.files.safe_io import read_regular

Array = np.ndarray
MAGIC, JSON_CHUNK, BIN_CHUNK = b"glTF", 0x4E4F534A, 0x004E4942
COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
              5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
EXTRAS_KEY = "wrinkleStudio"

# Extensions a file may require that change nothing this reader uses, or that it implements
# (quantized attributes, texture transforms read by the scene, WebP images through Pillow).
KNOWN_REQUIRED = frozenset({
    "KHR_mesh_quantization", "KHR_texture_transform", "EXT_texture_webp",
    "KHR_materials_unlit", "KHR_materials_variants", "KHR_materials_emissive_strength",
    "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission",
    "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_volume",
    "KHR_materials_iridescence", "KHR_materials_anisotropy", "KHR_materials_dispersion",
    "KHR_lights_punctual", "KHR_materials_pbrSpecularGlossiness"})
# Compression: what undoes it (gltfpack 0.21+ reads meshopt input; without -c it writes none).
DECOMPRESS = {
    "EXT_meshopt_compression": "gltfpack -noq -i FILE -o OUT.glb",
    "KHR_meshopt_compression": "gltfpack -noq -i FILE -o OUT.glb",
    "KHR_draco_mesh_compression": "npx @gltf-transform/cli copy FILE OUT.glb",
}


# --- reading ---------------------------------------------------------------------------------
def _whole(value: object) -> bool:
    """A JSON whole number of 0 or more (not a bool, float or string)."""
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _list(g: _Gltf, obj: dict, key: str) -> list:
    value = obj.get(key, [])
    if not isinstance(value, list):
        raise MeshError(f"'{key}' is not a JSON list", g.path)
    return value


def _item(g: _Gltf, key: str, index: object, items: list | None = None) -> dict:
    """``doc[key][index]``, refusing an index that is not a whole number in range (Python
    would read a negative one from the end) and an entry that is not a JSON object."""
    items = _list(g, g.doc, key) if items is None else items
    if not _whole(index) or index >= len(items):
        raise MeshError(f"a reference to {key}[{index!r}], which does not exist (the file has "
                        f"{len(items)})", g.path)
    item = items[index]
    if items is not g.buffers and not isinstance(item, dict):
        raise MeshError(f"{key}[{index}] is not a JSON object", g.path)
    return item


class _Gltf:
    """A parsed glTF document and its buffers, with typed accessors."""

    def __init__(self, path: Path) -> None:
        self.path = path
        data = read_regular(path, FILE_BYTES.value, MeshError, "glTF file", FILE_BYTES.setting)
        if data[:4] == MAGIC:
            self.doc, binary = self._parse_glb(data)
        else:
            check_json_depth(data, "the glTF JSON", path, MeshError)
            try:
                self.doc = json.loads(data.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise MeshError(f"not a glTF file ({exc})", path) from None
            binary = None
        asset = self.doc.get("asset") if isinstance(self.doc, dict) else None
        if not isinstance(asset, dict) or not str(asset.get("version", "")).startswith("2"):
            raise MeshError("not a glTF 2.0 file (asset.version is not 2.x)", path)
        _check_required(self.doc, path)
        self.buffers = [self._buffer(b, binary) for b in _list(self, self.doc, "buffers")]

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
                check_json_depth(chunk, "the GLB's JSON", self.path, MeshError)
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
        data = self._buffer_data(spec, binary)
        length = spec.get("byteLength", len(data)) if isinstance(spec, dict) else 0
        if not _whole(length) or length > len(data):
            raise MeshError(f"a buffer declares {length!r} bytes but holds {len(data)}",
                            self.path)
        return data

    def _buffer_data(self, spec: dict, binary: bytes | None) -> bytes:
        if not isinstance(spec, dict):
            raise MeshError("a buffer is not a JSON object", self.path)
        uri = spec.get("uri")
        if uri is None and _compressed_fallback(spec):
            return b"\0" * spec.get("byteLength", 0)  # never read: its views are refused
        if uri is None:
            if binary is None:
                raise MeshError("a buffer has no data", self.path)
            return binary
        if not isinstance(uri, str):
            raise MeshError(f"a buffer's uri is not text: {uri!r}", self.path)
        if uri.startswith("data:"):
            try:
                return base64.b64decode(uri.split(",", 1)[1])
            except (IndexError, ValueError) as exc:
                raise MeshError(f"a buffer's data URI is damaged ({exc})", self.path) from None
        target = (self.path.parent / uri).resolve()
        if self.path.parent.resolve() not in target.parents:
            raise MeshError(f"a buffer refers outside the file's folder: '{uri}'", self.path)
        return read_regular(target, FILE_BYTES.value, MeshError, f"buffer '{uri}' of the glTF",
                            FILE_BYTES.setting)

    def _view(self, index: int) -> tuple[memoryview, int, int | None]:
        view = _item(self, "bufferViews", index)
        for name in DECOMPRESS:
            if name in (view.get("extensions") or {}):
                raise MeshError(_compressed_message(name), self.path)
        buffer = _item(self, "buffers", view.get("buffer"), self.buffers)
        start, length = view.get("byteOffset", 0), view.get("byteLength")
        stride = view.get("byteStride")
        if not (_whole(start) and _whole(length)) or (
                stride is not None and not (_whole(stride) and 4 <= stride <= 252)):
            raise MeshError(f"buffer view {index} has an invalid byteOffset, byteLength or "
                            "byteStride", self.path)
        end = start + length
        if end > len(buffer):
            raise MeshError(f"buffer view {index} reaches past its buffer's end", self.path)
        return memoryview(buffer)[:end], start, stride  # no copy of the buffer

    def _elements(self, view: int, offset: object, dtype: np.dtype, width: int, count: int,
                  what: str) -> Array:
        """``count`` elements of ``width`` components from a buffer view, without a copy."""
        if not _whole(offset):
            raise MeshError(f"{what} has an invalid byteOffset", self.path)
        buffer, start, stride = self._view(view)
        start += offset
        item = dtype.itemsize * width
        stride = stride or item
        if stride < item or start % dtype.itemsize or stride % dtype.itemsize:
            raise MeshError(f"{what}'s elements overlap or are misaligned", self.path)
        if start + stride * (count - 1) + item > len(buffer):
            raise MeshError(f"{what} reaches past its buffer view's end", self.path)
        return np.ndarray((count, width), dtype, buffer, start, (stride, dtype.itemsize))

    def accessor(self, index: int) -> Array:
        try:
            acc = _item(self, "accessors", index)
            if acc.get("componentType") not in COMPONENTS or acc.get("type") not in WIDTH:
                raise MeshError(f"accessor {index} has an unknown component type "
                                f"{acc.get('componentType')!r} or type {acc.get('type')!r}",
                                self.path)
            dtype = np.dtype(COMPONENTS[acc["componentType"]])
            width, count = WIDTH[acc["type"]], acc.get("count")
            offset = acc.get("byteOffset", 0)
            if not (_whole(count) and count >= 1 and _whole(offset)):
                raise MeshError(f"accessor {index} has an invalid count or byteOffset",
                                self.path)
            MESH_VERTICES.check(count // 3 if acc["type"] == "SCALAR" else count,
                                f"accessor {index}", self.path, MeshError)
            if "bufferView" in acc:
                raw = self._elements(acc["bufferView"], offset, dtype, width, count,
                                     f"accessor {index}")
            elif "sparse" in acc:  # a sparse accessor without a base: zeros
                raw = np.zeros((count, width), dtype)
            else:
                raise MeshError(f"accessor {index} has no bufferView (no data)", self.path)
            if "sparse" in acc:
                raw = self._sparse(index, acc["sparse"], raw)
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise MeshError(f"accessor {index} is malformed ({exc})", self.path) from None
        values = raw.astype(np.float64)
        if acc.get("normalized") and dtype.kind in "iu":
            values /= float(np.iinfo(dtype).max)
            np.maximum(values, -1.0, out=values)  # glTF: the most negative integer is −1 too
        if not np.isfinite(values).all():
            raise MeshError(f"accessor {index} holds non-finite numbers (NaN or infinity)",
                            self.path)
        return values

    def _sparse(self, index: int, sparse: dict, base: Array) -> Array:
        """``base`` with the sparse block's values written at its indices (a copy)."""
        what = f"accessor {index}'s sparse block"
        try:
            count, indices, values = sparse["count"], sparse["indices"], sparse["values"]
            kind = indices["componentType"]
            if not (_whole(count) and count >= 1) or kind not in (5121, 5123, 5125):
                raise MeshError(f"{what} has an invalid count or index type", self.path)
            where = self._elements(indices["bufferView"], indices.get("byteOffset", 0),
                                   np.dtype(COMPONENTS[kind]), 1, count,
                                   f"{what}'s indices")[:, 0].astype(np.int64)
            new = self._elements(values["bufferView"], values.get("byteOffset", 0),
                                 base.dtype, base.shape[1], count, f"{what}'s values")
        except (KeyError, TypeError) as exc:
            raise MeshError(f"{what} is malformed (missing {exc})", self.path) from None
        if where.max() >= len(base) or (len(where) > 1 and (np.diff(where) <= 0).any()):
            raise MeshError(f"{what}'s indices are not increasing element numbers below "
                            f"{len(base)}", self.path)
        out = np.array(base)
        out[where] = new
        return out

    def typed(self, index: int, kinds: tuple[str, ...], what: str,
              integer: bool = False) -> Array:
        """An accessor that must have one of ``kinds`` (and integer components): a position
        stored as a SCALAR, or indices as floats, is refused naming ``what``."""
        acc = _item(self, "accessors", index)
        if acc.get("type") not in kinds or (integer and acc.get("componentType") not in (
                5121, 5123, 5125)):
            raise MeshError(f"{what} (accessor {index}) is {acc.get('type')!r} of component "
                            f"type {acc.get('componentType')!r}, expected "
                            f"{' or '.join(kinds)}{' of unsigned integers' if integer else ''}",
                            self.path)
        return self.accessor(index)

    def image(self, index: int) -> Array:
        spec = _item(self, "images", index)  # a negative index would read from the end
        try:
            if "bufferView" in spec:
                buffer, start, _ = self._view(spec["bufferView"])
                length = _item(self, "bufferViews", spec["bufferView"])["byteLength"]
                data = bytes(buffer[start:start + length])
            else:
                data = self._buffer({"uri": spec["uri"]}, None)
        except (KeyError, IndexError, TypeError) as exc:
            raise MeshError(f"image {index} is malformed ({exc})", self.path) from None
        return decode_image(data, f"{self.path} (image {index})")

    def texture_image(self, info: dict | None) -> Array | None:
        if not info:
            return None
        try:
            texture = _item(self, "textures", info["index"])
            webp = (texture.get("extensions") or {}).get("EXT_texture_webp") or {}
            source = webp["source"] if "source" in webp else texture["source"]
        except (MeshError, KeyError, TypeError):
            raise MeshError("a material refers to a texture that does not exist",
                            self.path) from None
        return self.image(source)




def _compressed_message(name: str) -> str:
    return (f"the file is compressed with {name}, which this reader does not decode; "
            f"decompress it first: {DECOMPRESS[name]}")


def _compressed_fallback(spec: dict) -> bool:
    """A meshopt file's placeholder buffer: declared, with no data of its own."""
    ext = spec.get("extensions") or {}
    return any(isinstance(ext.get(n), dict) and ext[n].get("fallback") for n in DECOMPRESS)


def _check_required(doc: dict, path: Path) -> None:
    """Refuse a file that requires an extension this reader cannot honour, by name."""
    required = doc.get("extensionsRequired", [])
    if not isinstance(required, list):
        raise MeshError("'extensionsRequired' is not a JSON list", path)
    for name in required:
        if name in DECOMPRESS:
            raise MeshError(_compressed_message(name), path)
    unknown = [str(n) for n in required if n not in KNOWN_REQUIRED]
    if unknown:
        raise MeshError(f"the file requires the glTF extension{'s' * (len(unknown) > 1)} "
                        f"{', '.join(unknown)}, which this reader does not know", path)
