"""The studio's set-up carried where other tools keep it: a re-export by Blender (its default glTF
options) drops every ``extras`` and custom vertex attribute, but keeps each UV map and copies
each PNG image byte for byte.

So an export also carries, for such a round trip:

- ``TEXCOORD_1`` = (welded vertex number, UDIM tile or 0) on every render vertex: the studio's
  own welding and tiles come back exactly, whatever order or split the other tool writes its
  vertices in;
- a private ancillary PNG chunk ``wrSt`` in the skin's neutral normal map (the image every
  tool exports with the skin's material, and one rarely painted over): the studio's extras
  (which name images, never index them: other tools renumber images and textures) and the
  per-welded-vertex data the custom attributes held (not-face, each technique-2 area's
  directions, lengths and painted cones), zlib-compressed.

PNG readers skip an ancillary chunk they do not know (the studio's own included), so the image
is unchanged for them. A tool that re-encodes the image (the map painted over) loses the chunk;
the reader then says what it could not bring back.
"""

from __future__ import annotations

import json
import struct
import zlib

import numpy as np

from studio.core.files.budgets import IMAGE_BYTES

Array = np.ndarray
CHUNK = b"wrSt"  # ancillary (w), private (r), reserved bit clear (S), safe to copy (t)
STUDIO_UV = "TEXCOORD_1"
_DTYPES = {"<f4": np.dtype("<f4"), "|u1": np.dtype("|u1")}


def studio_uvs(weld: Array, tiles: Array | None) -> Array:
    """(render vertices, 2) float32: the welded vertex number (exact below 2**24), and the
    vertex's UDIM tile (0 for a face on one tile)."""
    uv = np.zeros((len(weld), 2), np.float32)
    uv[:, 0] = weld
    if tiles is not None:
        uv[:, 1] = tiles
    return uv


def with_setup(png: bytes, extras: dict, arrays: dict[str, Array]) -> bytes:
    """``png`` with the set-up in a ``wrSt`` chunk before its IEND (the last 12 bytes)."""
    header = json.dumps({"extras": extras, "arrays": [
        {"name": name, "dtype": _dtype(a).str, "shape": list(a.shape)}
        for name, a in arrays.items()]}, separators=(",", ":")).encode("utf-8")
    blob = b"".join(np.ascontiguousarray(a, _dtype(a)).tobytes() for a in arrays.values())
    data = zlib.compress(header + b"\n" + blob, 6)
    chunk = struct.pack(">I", len(data)) + CHUNK + data + struct.pack(
        ">I", zlib.crc32(CHUNK + data))
    return png[:-12] + chunk + png[-12:]


def _dtype(array: Array) -> np.dtype:
    return np.dtype("|u1") if array.dtype == bool else np.dtype("<f4")


def find_setup(png: bytes) -> tuple[dict, dict[str, Array]] | None:
    """The set-up a PNG carries (extras, arrays), None when it carries none. A damaged chunk
    raises ValueError (its caller names the file)."""
    pos = 8
    while pos + 12 <= len(png):
        length, kind = struct.unpack(">I4s", png[pos:pos + 8])
        end = pos + 8 + length
        if end + 4 > len(png):
            return None
        if kind == CHUNK:
            body = png[pos + 8:end]
            if zlib.crc32(kind + body) != struct.unpack(">I", png[end:end + 4])[0]:
                raise ValueError("the set-up chunk is damaged (checksum mismatch)")
            return _unpack(body)
        if kind == b"IEND":
            return None
        pos = end + 4
    return None


def _unpack(body: bytes) -> tuple[dict, dict[str, Array]]:
    """The chunk's extras and arrays; inflated no further than one image's budget (a set-up
    is a few bytes a vertex: the sample's is 9 MB), so a crafted chunk cannot fill memory."""
    limit = IMAGE_BYTES.value
    inflate = zlib.decompressobj()
    data = inflate.decompress(body, limit + 1)
    if len(data) > limit or inflate.unconsumed_tail:
        raise ValueError(f"the set-up chunk inflates past {limit:,} bytes "
                         f"(set {IMAGE_BYTES.setting} to allow more)")
    text, _, blob = data.partition(b"\n")
    header = json.loads(text)
    extras, specs = header["extras"], header["arrays"]
    if not isinstance(extras, dict) or not isinstance(specs, list):
        raise ValueError("the set-up chunk's header is not the studio's")
    arrays, offset = {}, 0
    for spec in specs:
        dtype = _DTYPES[spec["dtype"]]
        shape = tuple(int(n) for n in spec["shape"])
        size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        if min(shape, default=0) < 0 or offset + size > len(blob):
            raise ValueError(f"the set-up chunk's array '{spec['name']}' is cut short")
        arrays[str(spec["name"])] = np.frombuffer(blob, dtype, size // dtype.itemsize,
                                                  offset).reshape(shape)
        offset += size
    return extras, arrays
