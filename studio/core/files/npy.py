"""The header of a ``.npy`` array, read from a stream before any of its data.

Why: a ``.npy`` header is a few hundred bytes that state the dtype and shape, so the data's size
follows from it. Reading the header alone first lets a reader refuse a member that claims the
wrong shape, or more bytes than the shape needs, before inflating it: a 600 kB project whose
member inflates to 600 MB of zeros behind a header claiming shape (50000000, 3) used to be
refused only after all 600 MB were in memory. ``np.lib.format``'s own header readers read the
header length's worth of bytes before checking it (a version-2 header may claim 4 GiB), so the
length is checked here first and only the bounded header text is handed to numpy's parser.
"""

from __future__ import annotations

import io
import math
import struct
import warnings
from dataclasses import dataclass
from typing import BinaryIO

import numpy as np

MAGIC = b"\x93NUMPY"
MAX_HEADER_BYTES = 10_000  # numpy's own limit for the headers it reads (max_header_size)
_LENGTH_FORMAT = {1: "<H", 2: "<I"}  # version -> the header length's struct format


@dataclass(frozen=True)
class NpyHeader:
    """What a ``.npy`` header declares, and how many bytes of the stream it took."""

    shape: tuple[int, ...]
    fortran_order: bool
    dtype: np.dtype
    size: int  # bytes before the data: magic, version, header length and header text

    @property
    def data_bytes(self) -> int:
        """The bytes of data the header's dtype and shape need after it."""
        return math.prod(self.shape) * self.dtype.itemsize


def _exactly(stream: BinaryIO, count: int, what: str) -> bytes:
    data = stream.read(count)
    if len(data) != count:
        raise ValueError(f"it ends inside its {what}")
    return data


def read_npy_header(stream: BinaryIO) -> NpyHeader:
    """Read only the header of the ``.npy`` array at the stream's position (at most
    :data:`MAX_HEADER_BYTES` and a dozen more); ValueError, in words, when it is damaged."""
    prefix = _exactly(stream, len(MAGIC) + 2, "header")
    if prefix[:len(MAGIC)] != MAGIC:
        raise ValueError("it does not start as a .npy array does")
    major = prefix[len(MAGIC)]
    if major not in _LENGTH_FORMAT:
        raise ValueError(f"unsupported .npy version {major}")
    length_format = _LENGTH_FORMAT[major]
    length_bytes = _exactly(stream, struct.calcsize(length_format), "header")
    (length,) = struct.unpack(length_format, length_bytes)
    if length > MAX_HEADER_BYTES:
        raise ValueError(f"its header claims {length} bytes, more than the "
                         f"{MAX_HEADER_BYTES} any array's needs")
    text = _exactly(stream, length, "header")
    parse = np.lib.format.read_array_header_1_0 if major == 1 else \
        np.lib.format.read_array_header_2_0
    try:
        with warnings.catch_warnings():  # a damaged header makes ast warn as well as fail
            warnings.simplefilter("ignore")
            shape, fortran_order, dtype = parse(io.BytesIO(length_bytes + text))
    except Exception as exc:  # numpy parses the header with tokenize and ast: their errors
        # (TokenError, SyntaxError, ValueError, …) vary by version, all mean "damaged"
        raise ValueError(str(exc) or type(exc).__name__) from None
    if any(n < 0 for n in shape):
        raise ValueError(f"its header claims the shape {shape}, with a negative length")
    return NpyHeader(tuple(shape), bool(fortran_order), dtype, len(prefix) + len(length_bytes)
                     + length)
