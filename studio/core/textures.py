"""The face's texture maps (SPEC §2, §9).

Images are stored as they are in a PNG: row 0 at the top (v = 1). Normal maps are tangent-space,
OpenGL convention (+Y green up), 8- or 16-bit; a flat map is RGB (128, 128, 255) everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.errors import ImageError

Array = np.ndarray


def flat_normal_map(size: int = 4) -> Array:
    img = np.empty((size, size, 3), dtype=np.uint8)
    img[...] = (128, 128, 255)
    return img


def check_image(image: Array, what: str, channels: int = 3) -> Array:
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != channels or min(image.shape[:2]) < 1:
        raise ImageError(f"the {what} must be an RGB image, got an array of shape {image.shape}")
    if image.dtype not in (np.uint8, np.uint16):
        raise ImageError(f"the {what} must be 8- or 16-bit, got {image.dtype}")
    return np.ascontiguousarray(image)


@dataclass(eq=False)
class FaceTextures:
    diffuse: Array  # (H, W, 3) uint8 sRGB skin colour
    normal_neutral: Array  # (H, W, 3) uint8/uint16 tangent-space normals
    normal_wrinkled: Array  # (H, W, 3) uint8/uint16, every wrinkle the face can show

    def __post_init__(self) -> None:
        self.diffuse = check_image(self.diffuse, "diffuse map")
        self.normal_neutral = check_image(self.normal_neutral, "neutral normal map")
        self.normal_wrinkled = check_image(self.normal_wrinkled, "wrinkled normal map")


def resize_nearest(image: Array, height: int, width: int) -> Array:
    """Nearest-texel resize (for matching map sizes; a flat map stays exactly flat)."""
    rows = (np.arange(height) * image.shape[0] // height)
    cols = (np.arange(width) * image.shape[1] // width)
    return image[rows][:, cols]


def pack_normal_maps(neutral: Array, wrinkled: Array) -> Array:
    """One RGBA image holding both tangent-space maps' x and y (z is rebuilt in the shader), so
    blending the two costs a single texture fetch. The smaller map is resized to the larger."""
    h = max(neutral.shape[0], wrinkled.shape[0])
    w = max(neutral.shape[1], wrinkled.shape[1])
    dtype = np.uint16 if np.uint16 in (neutral.dtype, wrinkled.dtype) else np.uint8

    def as_dtype(img: Array) -> Array:
        img = resize_nearest(img, h, w) if img.shape[:2] != (h, w) else img
        if img.dtype != dtype:  # 8-bit to 16-bit: 255 -> 65535 exactly
            img = img.astype(np.uint16) * 257
        return img

    return np.ascontiguousarray(np.concatenate(
        [as_dtype(neutral)[..., :2], as_dtype(wrinkled)[..., :2]], axis=-1))
