"""Reading and writing texture and mask images, with errors that name the file.

PNGs go through ``studio.core.files.png`` so 16-bit maps keep their precision; other formats (JPEG,
TIFF, BMP, …) through Pillow.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from studio.core.files.errors import ImageError
from studio.core.files.png import SIGNATURE, PngError, encode_png, png_header, read_png

Array = np.ndarray
MAX_PIXELS = 16384 * 16384


def read_image(path: str | Path) -> Array:
    """Pixels as stored: (H, W) or (H, W, C), uint8 or uint16."""
    from studio.core.files.budgets import FILE_BYTES
    from studio.core.files.safe_io import read_regular

    path = Path(path)
    data = read_regular(path, FILE_BYTES.value, ImageError, "image", FILE_BYTES.setting)
    return decode_image(data, path)


# Bytes a pixel takes once decoded, by Pillow mode (palettes become RGB or RGBA; "I" and "F"
# pass through float64 on their way to 16 bits).
_PIL_PIXEL_BYTES = {"1": 1, "L": 1, "LA": 2, "RGB": 3, "RGBA": 4, "I;16": 2, "I;16B": 2,
                    "I;16L": 2, "I": 8, "F": 8}
_PNG_CHANNELS = {0: 1, 2: 3, 3: 4, 4: 2, 6: 4}  # by colour type; a palette becomes RGB(A)


def _check_size(width: int, height: int, pixel_bytes: int, source: str | Path) -> None:
    """Refuse, from the header, an image over the pixel budget or whose decoded pixels would
    be over the byte budget (before any of it is decoded)."""
    from studio.core.files.budgets import IMAGE_BYTES, IMAGE_PIXELS

    IMAGE_PIXELS.check(width * height, "the image", source, ImageError)
    IMAGE_BYTES.check(width * height * pixel_bytes, f"the image decoded ({width}×{height}, "
                      f"{pixel_bytes} bytes a pixel)", source, ImageError)


def decoded_bytes(data: bytes) -> int:
    """The bytes the image ``data`` decodes to, from its header alone (0 when unknown)."""
    try:
        if data.startswith(SIGNATURE):
            width, height, depth, colour, _ = png_header(data)
            return width * height * _PNG_CHANNELS.get(colour, 4) * (2 if depth == 16 else 1)
        Image.MAX_IMAGE_PIXELS = MAX_PIXELS
        with Image.open(io.BytesIO(data)) as img:
            return img.width * img.height * _PIL_PIXEL_BYTES.get(img.mode, 4)
    except (PngError, OSError, ValueError, SyntaxError, Image.DecompressionBombError,
            UnidentifiedImageError):
        return 0  # decode_image says what is wrong


def decode_image(data: bytes, source: str | Path) -> Array:
    """Pixels of an encoded image (PNG exactly, other formats through Pillow); ``source`` names
    where the bytes came from in error messages."""
    try:
        if data.startswith(SIGNATURE):
            width, height, depth, colour, _ = png_header(data)
            _check_size(width, height, _PNG_CHANNELS.get(colour, 4) * (2 if depth == 16 else 1),
                        source)
            return read_png(data, max_bytes=MAX_PIXELS * 8)
        Image.MAX_IMAGE_PIXELS = MAX_PIXELS
        with Image.open(io.BytesIO(data)) as img:
            _check_size(img.width, img.height, _PIL_PIXEL_BYTES.get(img.mode, 4), source)
            if img.mode in ("I;16", "I;16B", "I;16L"):
                return np.asarray(img, dtype=np.uint16)
            if img.mode in ("I", "F"):
                arr = np.asarray(img, dtype=np.float64)
                return np.clip(arr, 0, 65535).astype(np.uint16)
            if img.mode not in ("L", "RGB", "RGBA", "LA"):
                img = img.convert("RGBA" if "A" in img.getbands() else "RGB")
            return np.asarray(img)
    except (PngError, OSError, ValueError, SyntaxError, Image.DecompressionBombError,
            UnidentifiedImageError) as exc:
        raise ImageError(f"not an image this studio can read ({exc})", source) from None


def _with_channels(image: Array, channels: int) -> Array:
    if image.ndim == 2:
        image = image[:, :, None]
    if image.shape[2] in (2, 4):  # drop alpha
        image = image[:, :, : image.shape[2] - 1]
    if image.shape[2] == 1 and channels == 3:
        image = np.repeat(image, 3, axis=2)
    return np.ascontiguousarray(image)


def load_rgb(path: str | Path) -> Array:
    """An RGB texture, (H, W, 3) uint8 or uint16."""
    return _with_channels(read_image(path), 3)


def to_unit_float(image: Array) -> Array:
    scale = 65535.0 if image.dtype == np.uint16 else 255.0
    return image.astype(np.float32) / np.float32(scale)


def load_grey(path: str | Path) -> Array:
    """A greyscale mask in [0, 1], (H, W) float32 (colour images by their luminance)."""
    image = _with_channels(read_image(path), 1)
    values = to_unit_float(image)
    if values.shape[2] == 3:
        return values @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    return values[:, :, 0]


def write_png(path: str | Path, image: Array) -> None:
    from studio.core.files.atomic_write import write_atomic

    write_atomic(path, encode_png(image), ImageError, what="image")


def write_tiff(path: str | Path, image: Array) -> None:
    """An 8-bit image as an uncompressed TIFF, all or nothing: O3DE's model builder finds a
    morph target's wrinkle mask only as a ``.tif`` file."""
    from studio.core.files.atomic_write import write_atomic

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image, np.uint8)).save(buffer, format="TIFF")
    write_atomic(path, buffer.getvalue(), ImageError, what="image")


def write_image(path: str | Path, image: Array) -> None:
    """PNG, or TIFF for a ``.tif`` name."""
    (write_tiff if Path(path).suffix.lower() in (".tif", ".tiff") else write_png)(path, image)
