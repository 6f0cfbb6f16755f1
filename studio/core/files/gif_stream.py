"""An animated GIF written frame by frame, so memory stays flat in the number of frames.

Why not Pillow's ``save_all``: it wants every frame at once, which kept each rendered frame in
memory until the end (a long timeline ran out of memory before a byte was written). Here each
frame is quantised and LZW-encoded by Pillow as a one-frame GIF, and its image block is copied
into the animation with its palette as a local colour table. Consecutive identical frames are
merged into one with the summed delay (as Pillow does), so only the previous frame is held.
"""

from __future__ import annotations

import io
import struct
from typing import IO

import numpy as np

Array = np.ndarray


def _skip_sub_blocks(data: bytes, pos: int) -> int:
    while True:
        size = data[pos]
        pos += 1 + size
        if size == 0:
            return pos


def _image_block(frame: Array) -> tuple[bytes, bytes]:
    """(palette bits + colour table, LZW data with its code size and sub-blocks) of one frame,
    quantised to 255 colours without dithering like the studio's GIFs always were."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(frame).quantize(colors=255, dither=Image.Dither.NONE).save(buffer, "GIF")
    data = buffer.getvalue()
    packed = data[10]
    pos = 13
    table = b""
    bits = packed & 0x07
    if packed & 0x80:  # global colour table: it becomes this frame's local one
        table = data[pos:pos + 3 * (2 << bits)]
        pos += len(table)
    while data[pos] == 0x21:  # extensions before the image: skip
        pos = _skip_sub_blocks(data, pos + 2)
    if data[pos] != 0x2C:
        raise ValueError("Pillow wrote a GIF without an image block")
    local = data[pos + 9]
    interlace = local & 0x40  # Pillow interlaces frames 16 or more rows high
    pos += 10
    if local & 0x80:  # Pillow chose a local table after all: use it
        bits = local & 0x07
        table = data[pos:pos + 3 * (2 << bits)]
        pos += len(table)
    start = pos
    pos = _skip_sub_blocks(data, pos + 1)
    return bytes([0x80 | interlace | bits]) + table, data[start:pos]


class GifStream:
    """Frames of one size in, an endlessly looping GIF out, written as they come."""

    def __init__(self, handle: IO[bytes], delay_ms: float) -> None:
        self.handle = handle
        self.delay_ms = delay_ms
        self.size: tuple[int, int] | None = None
        self.frames = 0  # frames in the file (identical neighbours count once)
        self._pending: tuple[Array, tuple[bytes, bytes], float] | None = None

    def add(self, frame: Array) -> None:
        """Append one (H, W, 3) uint8 frame."""
        height, width = frame.shape[:2]
        if self.size is None:
            self.size = (width, height)
            self.handle.write(b"GIF89a" + struct.pack("<HHBBB", width, height, 0x70, 0, 0))
            self.handle.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")  # loop for ever
        elif self.size != (width, height):
            raise ValueError(f"a {width}×{height} frame in a {self.size[0]}×{self.size[1]} GIF")
        if self._pending is not None and np.array_equal(self._pending[0], frame):
            previous, block, delay = self._pending
            self._pending = (previous, block, delay + self.delay_ms)
            return
        self._flush()
        self._pending = (frame.copy(), _image_block(frame), self.delay_ms)

    def _flush(self) -> None:
        if self._pending is None or self.size is None:
            return
        _, (table, lzw), delay = self._pending
        centiseconds = min(max(round(delay / 10.0), 1), 0xFFFF)
        self.handle.write(b"\x21\xf9\x04" + struct.pack("<BHB", 0x04, centiseconds, 0) + b"\0")
        self.handle.write(b"\x2c" + struct.pack("<HHHH", 0, 0, *self.size) + table + lzw)
        self.frames += 1
        self._pending = None

    def close(self) -> None:
        """Write the last frame and the trailer (the handle stays open: its owner closes it)."""
        self._flush()
        if self.size is not None:
            self.handle.write(b"\x3b")
