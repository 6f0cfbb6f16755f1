"""PNG images as numpy arrays, exactly, at 8 and 16 bits per channel.

Why not only Pillow: Pillow has no 16-bit RGB image mode, so it silently reduces 16-bit normal
maps to 8 bits on both reading and writing. This module writes 8- and 16-bit greyscale / RGB(A)
PNGs itself (signature, IHDR, IDAT, IEND, each chunk with its CRC-32) and decodes any 16-bit PNG
exactly; everything at 8 bits or fewer (palettes, 1-bit, …) is left to Pillow, which reads those
without loss. Every problem with the bytes raises :class:`PngError` (a ``ValueError``).

Decoding is vectorised: rows filtered with None/Sub/Up are undone with cumulative sums; the
Average and Paeth filters depend on the pixel to the left *and* the row above, so images that use
them are undone by Pillow's C decoder, a few bytes of each pixel at a time
(``studio.core.files.png_unfilter``).
"""

from __future__ import annotations

import io
import struct
import sys
import zlib

import numpy as np

Array = np.ndarray

SIGNATURE = b"\x89PNG\r\n\x1a\n"
MAX_SIDE = 1 << 16  # pixels per side this studio accepts (PNG allows 2**31 - 1)

# colour type -> channels, for the types this module decodes itself
_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}
_COLOUR_TYPE = {channels: kind for kind, channels in _CHANNELS.items()}
_ADAM7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2),
          (0, 1, 1, 2))  # x0, y0, dx, dy of the seven interlace passes


class PngError(ValueError):
    """Bytes that are not a PNG this studio can read."""


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


_ENCODE_ROWS = 256  # rows filtered and compressed at a time


def encode_png(image: Array, level: int = 6) -> bytes:
    """PNG bytes for an (H, W) or (H, W, 1–4) uint8/uint16 array; 16-bit stays 16-bit.

    Every row uses the Up filter: smooth maps (normals, masks) compress well with it and it is
    cheap to apply and to undo with whole-array operations. Rows are filtered and compressed
    a block at a time, so a large map costs its compressed size, not two more copies of it.
    """
    image = np.asarray(image)
    if image.ndim == 2:
        image = image[:, :, None]
    if image.ndim != 3 or image.shape[2] not in _COLOUR_TYPE or min(image.shape[:2]) < 1:
        raise PngError(f"cannot write an array of shape {image.shape} as a PNG image")
    if image.dtype == np.uint8:
        depth = 8
    elif image.dtype == np.uint16:
        depth = 16
    else:
        raise PngError(f"cannot write {image.dtype} pixels as a PNG image (8 or 16 bits only)")
    height, width, channels = image.shape
    pack = zlib.compressobj(level)
    parts, above = [], None
    for start in range(0, height, _ENCODE_ROWS):  # a block at a time: no copy of the image
        rows = np.ascontiguousarray(image[start:start + _ENCODE_ROWS],
                                    ">u2" if depth == 16 else np.uint8)
        rows = rows.view(np.uint8).reshape(len(rows), -1)
        filtered = np.empty((len(rows), rows.shape[1] + 1), dtype=np.uint8)
        filtered[:, 0] = 2  # Up
        filtered[0, 1:] = rows[0] if above is None else rows[0] - above
        np.subtract(rows[1:], rows[:-1], out=filtered[1:, 1:])  # wraps modulo 256, as PNG wants
        parts.append(pack.compress(filtered))
        above = rows[-1].copy()
    parts.append(pack.flush())
    header = struct.pack(">IIBBBBB", width, height, depth, _COLOUR_TYPE[channels], 0, 0, 0)
    return b"".join((SIGNATURE, _chunk(b"IHDR", header), _chunk(b"IDAT", b"".join(parts)),
                     _chunk(b"IEND", b"")))


def png_header(data: bytes) -> tuple[int, int, int, int, int]:
    """(width, height, bit depth, colour type, interlace) from the IHDR, checking the basics."""
    if data[:8] != SIGNATURE:
        raise PngError("not a PNG image")
    if len(data) < 33 or data[12:16] != b"IHDR" or data[8:12] != b"\0\0\0\x0d":
        raise PngError("the PNG image has no valid header")
    width, height, depth, colour, compression, filtering, interlace = struct.unpack(
        ">IIBBBBB", data[16:29])
    if zlib.crc32(data[12:29]) != struct.unpack(">I", data[29:33])[0]:
        raise PngError("the PNG image header is damaged (checksum mismatch)")
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise PngError(f"the PNG image is {width}×{height} pixels, outside 1–{MAX_SIDE} per side")
    if compression != 0 or filtering != 0 or interlace not in (0, 1):
        raise PngError("the PNG image uses an unknown compression, filter or interlace method")
    return width, height, depth, colour, interlace


HEADER_BYTES = 33  # signature and IHDR chunk: all png_header reads
METADATA_BYTES = 16 << 20  # room for colour profiles, text, EXIF and thumbnails


def max_file_bytes(data: bytes) -> int:
    """The most bytes a PNG with the header at the start of ``data`` can take: its rows stored
    without compression, a quarter more for the least efficient encoders (fixed Huffman codes
    spend 9 bits on some bytes; small IDAT chunks add 12 bytes each), and METADATA_BYTES.

    Why: a PNG's size does not follow from its header exactly, but it is bounded by it; a
    container (a project archive) can refuse a member larger than this before inflating it,
    so a PNG padded with a gigabyte of zeros in an ancillary chunk costs nothing to refuse.
    """
    width, height, depth, colour, _ = png_header(data)
    channels = 1 if colour == 3 else _CHANNELS.get(colour, 4)  # a palette stores indices
    row = -(-width * depth * channels // 8)
    raw = height * (row + 16)  # + filter bytes and per-pass rounding when interlaced
    return raw + raw // 4 + METADATA_BYTES


def _chunks(data: bytes) -> tuple[bytes, bytes]:
    """(IHDR payload, joined IDAT payloads), every chunk's CRC checked."""
    pos, idat, header = 8, [], b""
    while True:
        if pos + 12 > len(data):
            raise PngError("the PNG image is truncated (no IEND chunk)")
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        end = pos + 8 + length
        if length > 0x7FFFFFFF or end + 4 > len(data):
            raise PngError("the PNG image is truncated or has a damaged chunk length")
        body = data[pos + 8:end]
        if zlib.crc32(kind + body) != struct.unpack(">I", data[end:end + 4])[0]:
            raise PngError(f"the PNG image's {kind.decode('latin-1')!r} chunk is damaged "
                           "(checksum mismatch)")
        if kind == b"IHDR":
            header = body
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            return header, b"".join(idat)
        elif kind[:1].isupper() and kind != b"PLTE":
            raise PngError(f"the PNG image has an unknown critical chunk {kind!r}")
        pos = end + 4


def _unfilter(kinds: Array, out: Array, bpp: int) -> None:
    """Undo PNG row filters in place: ``out`` (h, stride) holds the filtered bytes of rows
    whose filter types are ``kinds`` and ends with the pixel bytes.

    In place because a decoded image can be a large share of the memory the studio is allowed:
    a copy per step used to make a 16-bit 4096² image cost five times its size.
    """
    if (kinds > 4).any():
        raise PngError(f"the PNG image uses an unknown row filter {int(kinds.max())}")
    if ((kinds == 3) | (kinds == 4)).any():  # in C: in numpy these take seconds on big images
        from studio.core.files.png_unfilter import unfilter_with_pillow

        unfilter_with_pillow(kinds, out, bpp, out)
        return
    h, stride = out.shape
    sub = kinds == 1
    if sub.all():  # Sub: running sum along the row, per byte of the pixel
        pixels = out.reshape(h, stride // bpp, bpp)
        np.cumsum(pixels, axis=1, dtype=np.uint8, out=pixels)
    elif sub.any():
        rows = out[sub].reshape(int(sub.sum()), stride // bpp, bpp)
        out[sub] = np.cumsum(rows, axis=1, dtype=np.uint8).reshape(-1, stride)
    up = kinds == 2
    if up.any():  # Up: each row plus the one above (wrapping modulo 256), top to bottom
        # one whole-row addition per row: numpy's cumsum down axis 0 walks the image column by
        # column with a stride of a row, about 100 × slower (0.46 s against 3.5 ms for a
        # 2048² 16-bit RGB map; the studio writes every PNG with Up rows)
        for row in (np.flatnonzero(up[1:]) + 1).tolist():
            np.add(out[row - 1], out[row], out=out[row])


def decode_png(data: bytes, max_bytes: int = 1 << 31) -> Array:
    """Pixels of a non-palette 8- or 16-bit PNG: (H, W) or (H, W, C), uint8 or uint16.

    ``max_bytes`` caps the decompressed size, so a small file cannot claim a huge image.
    """
    width, height, depth, colour, interlace = png_header(data)
    if depth not in (8, 16) or colour not in _CHANNELS:
        raise PngError(f"this PNG decoder reads 8- and 16-bit non-palette images, not colour "
                       f"type {colour} at {depth} bits")
    header, idat = _chunks(data)
    if header != data[16:29]:
        raise PngError("the PNG image has more than one header")
    channels = _CHANNELS[colour]
    bpp = channels * depth // 8
    if interlace:
        passes = [(x0, y0, dx, dy, -(-(width - x0) // dx), -(-(height - y0) // dy))
                  for x0, y0, dx, dy in _ADAM7]
        passes = [p for p in passes if p[4] > 0 and p[5] > 0]
    else:
        passes = [(0, 0, 1, 1, width, height)]
    expected = sum(ph * (1 + pw * bpp) for *_, pw, ph in passes)
    if expected > max_bytes:
        raise PngError(f"the PNG image is too large ({width}×{height} pixels)")
    try:
        raw = zlib.decompressobj().decompress(idat, expected)
    except zlib.error as exc:
        raise PngError(f"the PNG image data is damaged ({exc})") from None
    if len(raw) < expected:
        raise PngError("the PNG image data is truncated")
    buffer = np.frombuffer(raw, dtype=np.uint8)
    pixels = np.empty((height, width * bpp), dtype=np.uint8)
    view = pixels.reshape(height, width, bpp)
    pos = 0
    for x0, y0, dx, dy, pw, ph in passes:
        size = ph * (1 + pw * bpp)
        rows = buffer[pos:pos + size].reshape(ph, 1 + pw * bpp)
        if interlace:
            block = rows[:, 1:].copy()
            _unfilter(rows[:, 0], block, bpp)
            view[y0::dy, x0::dx] = block.reshape(ph, pw, bpp)
        else:  # unfiltered where the pixels go: no copy of the image
            pixels[:] = rows[:, 1:]
            _unfilter(rows[:, 0], pixels, bpp)
        pos += size
    del buffer, raw
    if depth == 16:  # big-endian samples, turned native in place
        if sys.byteorder == "little":
            pixels.view(np.uint16).byteswap(inplace=True)
        image = pixels.view(np.uint16)
    else:
        image = pixels
    image = image.reshape(height, width, channels)
    return image[:, :, 0] if channels == 1 else image


def read_png(data: bytes, max_bytes: int = 1 << 31) -> Array:
    """Pixels of any PNG without loss: 8- and 16-bit images without a palette here, palettes
    and fewer bits through Pillow.

    Palette images come back as RGB (RGBA with transparency), 1/2/4-bit greyscale as 8-bit.
    Why not Pillow for 8 bits too: it holds RGB as four bytes a pixel and hands numpy a copy
    assembled from pieces, three times the image at the peak; decoded here it is twice.
    """
    width, height, depth, colour, _ = png_header(data)
    if depth == 16 or (depth == 8 and colour in _CHANNELS):
        return decode_png(data, max_bytes)
    channels = {3: 3}.get(colour, _CHANNELS.get(colour, 4))
    if width * height * channels > max_bytes:
        raise PngError(f"the PNG image is too large ({width}×{height} pixels)")
    _chunks(data)  # checksums: Pillow only warns about some damage
    from PIL import Image

    try:
        with Image.open(io.BytesIO(data), formats=["PNG"]) as img:
            img.load()
            if img.mode == "1":
                img = img.convert("L")
            elif img.mode == "P":
                img = img.convert("RGBA" if "transparency" in img.info else "RGB")
            array = np.asarray(img)
    except (OSError, SyntaxError, ValueError, EOFError, Image.DecompressionBombError) as exc:
        raise PngError(f"the PNG image cannot be read ({exc})") from None
    if array.dtype not in (np.uint8, np.uint16):
        raise PngError(f"the PNG image has unexpected pixels ({img.mode})")
    return np.ascontiguousarray(array)
