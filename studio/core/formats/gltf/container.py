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
import re
import struct
from pathlib import Path
from urllib.parse import unquote

import numpy as np

from studio.core.files.budgets import (
    FILE_BYTES,
    GLTF_IMAGE_BYTES,
    GLTF_VALUES,
    IMAGE_BYTES,
    MESH_VERTICES,
    check_json_depth,
)
from studio.core.files.errors import MeshError
from studio.core.files.images import decode_image, decoded_bytes
from studio.core.files.naming import shown, shown_list
from studio.core.files.safe_io import read_regular

Array = np.ndarray
MAGIC, JSON_CHUNK, BIN_CHUNK = b"glTF", 0x4E4F534A, 0x004E4942
COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
              5126: np.float32}
_COMPONENT_WORDS = {5120: "signed bytes", 5121: "unsigned bytes", 5122: "signed shorts",
                    5123: "unsigned shorts", 5125: "unsigned integers"}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
EXTRAS_KEY = "wrinkleStudio"
# Vertex attributes whose component types glTF restricts (as float, or these integer kinds when
# normalized) unless the file declares KHR_mesh_quantization, which allows integers for all.
FLOAT_ATTRIBUTES = {"POSITION": (), "NORMAL": (), "TANGENT": (),
                    "TEXCOORD": (5121, 5123)}  # TEXCOORD_n: unsigned bytes and shorts, normalized
QUANTIZATION = "KHR_mesh_quantization"
_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.-]+:")  # a URI scheme ("file:", "http:"), not "C:"

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
        self.values = 0  # numbers decoded from accessors so far (GLTF_VALUES)
        self.image_bytes = 0  # bytes of decoded images so far (GLTF_IMAGE_BYTES)
        self._decoded: dict[int, Array] = {}  # accessor -> its values, read-only, read once
        if data[:4] == MAGIC:
            self.doc, binary = self._parse_glb(data)
        else:
            self.doc = self._parse_json(data, "the glTF JSON", "not a glTF file")
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
                doc = self._parse_json(chunk, "the GLB's JSON", "the GLB's JSON is damaged")
            elif kind == BIN_CHUNK and binary is None:
                binary = chunk
            offset += 8 + size
        if doc is None:
            raise MeshError("the GLB file has no JSON chunk", self.path)
        return doc, binary

    def _parse_json(self, data: bytes, what: str, damaged: str) -> object:
        """The JSON document ``data``, its nesting checked first; ``damaged`` begins the
        message for text that is not JSON."""
        check_json_depth(data, what, self.path, MeshError)
        try:
            return json.loads(data.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise MeshError(f"{damaged} ({exc})", self.path) from None
        except ValueError:  # Python refuses to convert an integer of thousands of digits
            raise MeshError(f"{damaged}: it holds a number with thousands of digits, which no "
                            "glTF value can be", self.path) from None

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
            length = spec.get("byteLength", 0)
            if not _whole(length) or length > FILE_BYTES.value:
                raise MeshError(f"a compressed file's placeholder buffer declares "
                                f"{shown(length)} bytes", self.path)
            return bytes(length)  # never read: its views are refused
        if uri is None:
            if binary is None:
                raise MeshError("a buffer has no data", self.path)
            return binary
        return self._uri_data(uri, "a buffer", "buffer")

    def _uri_data(self, uri: object, what: str, kind: str) -> bytes:
        """The bytes a buffer's or image's ``uri`` names: a data URI, or a file in the glTF's
        own folder (``what``, "a buffer" or "image 3", and ``kind``, "buffer" or "image", name
        it in messages: a user looking for a missing texture is told it is an image)."""
        if not isinstance(uri, str):
            raise MeshError(f"{what}'s uri is not text: {shown(repr(uri))}", self.path)
        if uri.startswith("data:"):
            try:
                return base64.b64decode(uri.split(",", 1)[1])
            except (IndexError, ValueError) as exc:
                raise MeshError(f"{what}'s data URI is damaged ({exc})", self.path) from None
        if _SCHEME.match(uri):
            raise MeshError(f"{what}'s uri '{shown(uri)}' has the unsupported URI scheme "
                            f"'{shown(uri.split(':', 1)[0])}:' (a glTF names its files by paths "
                            "relative to itself, or embeds them as data: URIs)", self.path)
        target = (self.path.parent / unquote(uri)).resolve()  # a URI: "my%20face.bin"
        if self.path.parent.resolve() not in target.parents:
            raise MeshError(f"{what} refers outside the file's folder: '{shown(uri)}'",
                            self.path)
        return read_regular(target, FILE_BYTES.value, MeshError,
                            f"{kind} '{shown(uri)}' of the glTF", FILE_BYTES.setting)

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
        """An accessor's values as float64 rows (normalized integers scaled to −1…1), decoded
        once and kept read-only, so instanced meshes and morph targets sharing one accessor
        cost one decoding.

        Every *use* counts against GLTF_VALUES, checked before the values are returned: each
        use becomes a copy downstream (a mesh placed again, a key pose made of a shared
        target), so a thousand uses of one accessor are refused before the thousand copies are
        made, whichever reader asks. What an accessor declares is checked before any of it is
        allocated."""
        try:
            acc = _item(self, "accessors", index)
            if acc.get("componentType") not in COMPONENTS or acc.get("type") not in WIDTH:
                raise MeshError(f"accessor {index} has an unknown component type "
                                f"{shown(repr(acc.get('componentType')))} or type "
                                f"{shown(repr(acc.get('type')))}", self.path)
            dtype = np.dtype(COMPONENTS[acc["componentType"]])
            width, count = WIDTH[acc["type"]], acc.get("count")
            offset = acc.get("byteOffset", 0)
            if not (_whole(count) and count >= 1 and _whole(offset)):
                raise MeshError(f"accessor {index} has an invalid count or byteOffset",
                                self.path)
            MESH_VERTICES.check(count // 3 if acc["type"] == "SCALAR" else count,
                                f"accessor {index}", self.path, MeshError)
            self.values += count * width
            GLTF_VALUES.check(self.values, f"the numbers read, with accessor {index} "
                              f"({count:,} × {width}),", self.path, MeshError)
            if index in self._decoded:
                return self._decoded[index]
            if "bufferView" in acc:
                values = self._elements(acc["bufferView"], offset, dtype, width, count,
                                        f"accessor {index}").astype(np.float64)
            elif "sparse" in acc:  # a sparse accessor without a base: zeros
                values = np.zeros((count, width), np.float64)
            else:
                raise MeshError(f"accessor {index} has no bufferView (no data)", self.path)
            if "sparse" in acc:
                self._sparse(index, acc["sparse"], values, dtype)
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise MeshError(f"accessor {index} is malformed ({shown(exc)})", self.path) from None
        if acc.get("normalized") and dtype.kind in "iu":
            values /= float(np.iinfo(dtype).max)
            np.maximum(values, -1.0, out=values)  # glTF: the most negative integer is −1 too
        if not np.isfinite(values).all():
            raise MeshError(f"accessor {index} holds non-finite numbers (NaN or infinity)",
                            self.path)
        values.flags.writeable = False
        self._decoded[index] = values
        return values

    def declared_count(self, index: object) -> int:
        """The element count accessor ``index`` declares (0 when it declares none), read
        without decoding it: what budgets are checked against on paper."""
        items = _list(self, self.doc, "accessors")
        acc = items[index] if _whole(index) and index < len(items) else None
        count = acc.get("count") if isinstance(acc, dict) else None
        return count if _whole(count) else 0

    def _sparse(self, index: int, sparse: dict, values: Array, dtype: np.dtype) -> None:
        """Write the sparse block's values into ``values`` (float64) at its indices."""
        what = f"accessor {index}'s sparse block"
        try:
            count, indices, new = sparse["count"], sparse["indices"], sparse["values"]
            kind = indices["componentType"]
            if not (_whole(count) and 1 <= count <= len(values)) or kind not in (
                    5121, 5123, 5125):
                raise MeshError(f"{what} has an invalid count (more than the accessor's "
                                f"{len(values):,} elements?) or index type", self.path)
            where = self._elements(indices["bufferView"], indices.get("byteOffset", 0),
                                   np.dtype(COMPONENTS[kind]), 1, count,
                                   f"{what}'s indices")[:, 0].astype(np.int64)
            rows = self._elements(new["bufferView"], new.get("byteOffset", 0),
                                  dtype, values.shape[1], count, f"{what}'s values")
        except (KeyError, TypeError) as exc:
            raise MeshError(f"{what} is malformed (missing {shown(exc)})", self.path) from None
        if where.max() >= len(values) or (len(where) > 1 and (np.diff(where) <= 0).any()):
            raise MeshError(f"{what}'s indices are not increasing element numbers below "
                            f"{len(values)}", self.path)
        values[where] = rows

    def typed(self, index: int, kinds: tuple[str, ...], what: str,
              integer: bool = False) -> Array:
        """An accessor that must have one of ``kinds`` (and integer components): a position
        stored as a SCALAR, or indices as floats, is refused naming ``what``."""
        acc = _item(self, "accessors", index)
        if acc.get("type") not in kinds or (integer and acc.get("componentType") not in (
                5121, 5123, 5125)):
            raise MeshError(f"{what} (accessor {index}) is {shown(repr(acc.get('type')))} of "
                            f"component type {shown(repr(acc.get('componentType')))}, expected "
                            f"{' or '.join(kinds)}{' of unsigned integers' if integer else ''}",
                            self.path)
        return self.accessor(index)

    def attribute(self, index: int, semantic: str, kinds: tuple[str, ...],
                  what: str | None = None) -> Array:
        """A vertex attribute (POSITION, TEXCOORD_n, a morph target's POSITION …; ``what``
        names it in messages, by default ``semantic``), refusing component types glTF does not
        allow for it: integer positions, or integer UVs that are not normalized, are only valid
        in a file that declares KHR_mesh_quantization (a reader that took them would place a
        face of unsigned bytes 0–255 units wide)."""
        what = what or semantic
        base = semantic.split("_")[0] if semantic.startswith("TEXCOORD_") else semantic
        allowed = FLOAT_ATTRIBUTES.get(base)
        acc = _item(self, "accessors", index)
        kind = acc.get("componentType")
        if (allowed is not None and kind != 5126 and QUANTIZATION not in self.extensions_used
                and not (kind in allowed and acc.get("normalized"))):
            raise MeshError(f"{what} (accessor {index}) is stored as "
                            f"{_COMPONENT_WORDS.get(kind, shown(repr(kind)))}"
                            f"{' (normalized)' if acc.get('normalized') else ''}, which glTF "
                            f"allows only in a file that declares {QUANTIZATION}", self.path)
        return self.typed(index, kinds, what)

    @property
    def extensions_used(self) -> list:
        used = self.doc.get("extensionsUsed", [])
        return used if isinstance(used, list) else []

    def image(self, index: int) -> Array:
        spec = _item(self, "images", index)  # a negative index would read from the end
        try:
            if "bufferView" in spec:
                buffer, start, _ = self._view(spec["bufferView"])
                length = _item(self, "bufferViews", spec["bufferView"])["byteLength"]
                data = bytes(buffer[start:start + length])
            else:
                data = self._uri_data(spec["uri"], f"image {index}", "image")
        except (KeyError, IndexError, TypeError) as exc:
            raise MeshError(f"image {index} is malformed ({shown(exc)})", self.path) from None
        size = decoded_bytes(data)  # from its header, before it is decoded
        IMAGE_BYTES.check(size, f"image {index} decoded", self.path, MeshError)
        self.image_bytes += size
        GLTF_IMAGE_BYTES.check(self.image_bytes, f"the images decoded, with image {index},",
                               self.path, MeshError)
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
        if isinstance(name, str) and name in DECOMPRESS:
            raise MeshError(_compressed_message(name), path)
    unknown = [n for n in required if not isinstance(n, str) or n not in KNOWN_REQUIRED]
    if unknown:
        raise MeshError(f"the file requires the glTF extension{'s' * (len(unknown) > 1)} "
                        f"{shown_list(unknown)}, which this reader does not know", path)
