"""The face's texture maps.

Images are stored as they are in a PNG: row 0 at the top (v = 1). Normal maps are tangent-space,
OpenGL convention (+Y green up), 8- or 16-bit; a flat map is RGB (128, 128, 255) everywhere.
"""

from __future__ import annotations

import numpy as np

from studio.core.files.errors import ImageError

Array = np.ndarray


SKIN = (205, 160, 140)  # the diffuse colour of a face imported without a diffuse map


# a head's own map by slot: what the report calls it, and what shows when the file's is missing
MAP_WORDS = {"diffuse": ("diffuse map", "plain skin colour"),
             "normal": ("normal map", "a flat normal map")}


def plain_diffuse(size: int = 256) -> Array:
    image = np.empty((size, size, 3), np.uint8)
    image[...] = SKIN
    return image


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


def eight_bit(image: Array) -> Array:
    """A checked image at 8 bits (a 16-bit one's high byte)."""
    return (image >> 8).astype(np.uint8) if image.dtype == np.uint16 else image


def tone_image(kind: str, image: Array, name: str) -> Array:
    """A wrinkled map's ``kind`` ("cavity": greyscale, "colour": RGB) map, checked, at 8 bits;
    an RGB image given as a cavity map keeps its first channel."""
    image = np.asarray(image)
    if kind == "cavity":
        image = image[..., 0] if image.ndim == 3 else image
        return eight_bit(check_image(image[..., None], f"cavity map of '{name}'", 1))[..., 0]
    return eight_bit(check_image(image, f"colour map of '{name}'"))


DEFAULT_WRINKLE_MAP = "wrinkles"
MAX_WRINKLE_MAPS = 4  # the shader blends up to four wrinkled maps per pixel (one vec4 of weights)


class FaceTextures:
    """Diffuse, neutral normals and one or more named wrinkled normal maps.

    Several wrinkled maps let, say, forehead compression and smile lines be authored
    apart; each technique-1 and technique-2 area names the map it reveals ("" = the first one).
    ``normal_wrinkled`` is the first map, the one a project with a single map has.
    """

    def __init__(self, diffuse: Array, normal_neutral: Array, normal_wrinkled: Array | None = None,
                 *, wrinkle_maps: dict[str, Array] | None = None) -> None:
        if (normal_wrinkled is None) == (wrinkle_maps is None):
            raise ImageError("give either one wrinkled normal map or a dict of named ones")
        maps = {DEFAULT_WRINKLE_MAP: normal_wrinkled} if wrinkle_maps is None else wrinkle_maps
        if not maps:
            raise ImageError("a face needs at least one wrinkled normal map")
        if len(maps) > MAX_WRINKLE_MAPS:
            raise ImageError(f"a face can have at most {MAX_WRINKLE_MAPS} wrinkled normal maps, "
                             f"got {len(maps)}")
        self.diffuse = check_image(diffuse, "diffuse map")
        self.normal_neutral = check_image(normal_neutral, "neutral normal map")
        self.wrinkle_maps: dict[str, Array] = {}
        # each wrinkled map's cavity (H, W) and colour (H, W, 3), 8-bit, where it has them
        # (skin_tone.py); a map without them leaves the skin's tone as it is
        self.cavity_maps: dict[str, Array] = {}
        self.colour_maps: dict[str, Array] = {}
        for name, image in maps.items():
            self.set_wrinkle_map(name, image)

    @property
    def normal_wrinkled(self) -> Array:
        return next(iter(self.wrinkle_maps.values()))

    @normal_wrinkled.setter
    def normal_wrinkled(self, image: Array) -> None:
        self.set_wrinkle_map(self.wrinkle_map_names[0], image)

    @property
    def wrinkle_map_names(self) -> list[str]:
        return list(self.wrinkle_maps)

    def map_index(self, name: str) -> int:
        """Shader index of a named map; "" or a name no longer present means the first map."""
        names = self.wrinkle_map_names
        return names.index(name) if name in names else 0

    def set_wrinkle_map(self, name: str, image: Array) -> None:
        """Replace the named map, or add it after the others."""
        name = str(name).strip()
        if not name:
            raise ImageError("a wrinkled normal map needs a name")
        if name not in self.wrinkle_maps and len(self.wrinkle_maps) >= MAX_WRINKLE_MAPS:
            raise ImageError(f"a face can have at most {MAX_WRINKLE_MAPS} wrinkled normal maps")
        self.wrinkle_maps[name] = check_image(image, f"wrinkled normal map '{name}'")

    def set_tone(self, name: str, cavity: Array | None = None,
                 colour: Array | None = None) -> None:
        """Give the named wrinkled map its cavity (greyscale) and/or colour (RGB) map."""
        if name not in self.wrinkle_maps:
            raise ImageError(f"there is no wrinkled normal map '{name}'")
        if cavity is not None:
            self.cavity_maps[name] = tone_image("cavity", cavity, name)
        if colour is not None:
            self.colour_maps[name] = tone_image("colour", colour, name)

    def tone_for(self, maps: dict[str, Array]) -> tuple[dict[str, Array], dict[str, Array]]:
        """The (cavity, colour) maps that go with ``maps``, a new set of wrinkled maps (the
        Maps menu's add, rename, remove): a renamed map (same place, as many maps) keeps its
        own, a removed map's go."""
        old, new = list(self.wrinkle_maps), list(maps)
        same = len(old) == len(new)
        renamed = dict(zip(old, new, strict=True)) if same else {n: n for n in old if n in maps}
        return ({renamed[k]: v for k, v in self.cavity_maps.items() if k in renamed},
                {renamed[k]: v for k, v in self.colour_maps.items() if k in renamed})

    @property
    def has_tone(self) -> bool:
        """Whether any wrinkled map has a cavity or colour map (else the skin's tone stays)."""
        return bool(self.cavity_maps or self.colour_maps)

    def remove_wrinkle_map(self, name: str) -> Array:
        if len(self.wrinkle_maps) == 1:
            raise ImageError("the last wrinkled normal map cannot be removed")
        self.cavity_maps.pop(name, None)
        self.colour_maps.pop(name, None)
        return self.wrinkle_maps.pop(name)

    def rename_wrinkle_map(self, old: str, new: str) -> None:
        new = str(new).strip()
        if not new or (new in self.wrinkle_maps and new != old):
            raise ImageError(f"a wrinkled normal map needs a new, unused name (got '{new}')")
        for maps in ("wrinkle_maps", "cavity_maps", "colour_maps"):
            setattr(self, maps, {new if k == old else k: v
                                 for k, v in getattr(self, maps).items()})


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


def pack_more_maps(textures: FaceTextures, packed: Array) -> Array:
    """(N, H, W, 2) x and y of the wrinkled maps after the first, at the size and bit depth of
    ``packed`` (the neutral + first map texture); one flat layer when there are none."""
    h, w = packed.shape[:2]
    extra = list(textures.wrinkle_maps.values())[1:] or [flat_normal_map(1)]
    layers = []
    for image in extra:
        image = resize_nearest(image, h, w) if image.shape[:2] != (h, w) else image
        if packed.dtype == np.uint16 and image.dtype == np.uint8:
            image = image.astype(np.uint16) * 257
        elif packed.dtype == np.uint8 and image.dtype == np.uint16:
            image = (image >> 8).astype(np.uint8)
        layers.append(image[..., :2])
    return np.ascontiguousarray(np.stack(layers))
