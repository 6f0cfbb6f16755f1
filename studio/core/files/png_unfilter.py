"""Undoing PNG row filters in Pillow's C decoder, for the filters numpy cannot vectorise.

Why: the Average and Paeth filters make each byte depend on the byte ``bpp`` places to its left
and the row above, so ``studio.core.files.png`` undoes them one anti-diagonal at a time — about a
second per 2048² 16-bit image, a quarter of a minute at 8192², long enough to freeze the window.

The trick: every filter works on bytes, and a byte at column ``k`` only ever looks at columns
``k`` and ``k - bpp``. So the bytes ``j, j + 1, … j + g - 1`` of every pixel (any group of ``g``
consecutive bytes of the ``bpp``) form an image of their own whose filters are the same, with a
pixel of ``g`` bytes. With ``g`` of 1–4 that is an ordinary 8-bit L, LA, RGB or RGBA PNG, which
Pillow unfilters in C exactly (no colour management touches 8-bit data without such chunks).
"""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np

Array = np.ndarray
_MODES = {1: 0, 2: 4, 3: 2, 4: 6}  # bytes per pixel -> PNG colour type at 8 bits
_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _groups(bpp: int) -> list[int]:
    """Sizes of consecutive byte groups (each 1–4) that cover a pixel of ``bpp`` bytes."""
    sizes = []
    while bpp > 0:
        take = min(4, bpp) if bpp != 5 else 3
        sizes.append(take)
        bpp -= take
    return sizes


_BAND_BYTES = 4 << 20  # filtered bytes handed to Pillow at a time


def unfilter_with_pillow(kinds: Array, data: Array, bpp: int, out: Array | None = None
                         ) -> Array:
    """(h, stride) filtered bytes (``kinds`` the per-row filter types) -> (h, stride) pixels,
    written into ``out`` when given (which may be ``data`` itself).

    A band of rows at a time, each band's PNG starting with the row above it already
    unfiltered (filter None) for its first row to refer to: the whole image at once cost six
    copies of it, a large share of the memory the studio may use.
    """
    from PIL import Image

    h, stride = data.shape
    w = stride // bpp
    result = np.empty((h, stride), np.uint8) if out is None else out
    source, target = data.reshape(h, w, bpp), result.reshape(h, w, bpp)
    band = max(1, _BAND_BYTES // max(stride, 1))
    for top in range(0, h, band):
        bottom, above = min(h, top + band), int(top > 0)
        start = 0
        for size in _groups(bpp):
            part = np.empty((bottom - top + above, 1 + w * size), np.uint8)
            if above:  # the row above, unfiltered already: filter None
                part[0, 0] = 0
                part[0, 1:] = target[top - 1, :, start:start + size].reshape(w * size)
            part[above:, 0] = kinds[top:bottom]
            part[above:, 1:] = source[top:bottom, :, start:start + size].reshape(-1, w * size)
            header = struct.pack(">IIBBBBB", w, len(part), 8, _MODES[size], 0, 0, 0)
            png = b"".join((_SIGNATURE, _chunk(b"IHDR", header),
                            _chunk(b"IDAT", zlib.compress(part.tobytes(), 0)),
                            _chunk(b"IEND", b"")))
            with Image.open(io.BytesIO(png), formats=["PNG"]) as img:
                img.load()
                rows = np.asarray(img).reshape(len(part), w, size)
            target[top:bottom, :, start:start + size] = rows[above:]
            start += size
    return result
