"""The head's own maps as a foreign file's materials name them: the skin material's base colour
and normal map, embedded in the file or beside it, for FBX, OBJ (``.mtl``) and USD alike.

Why one module: each format says differently where a texture is (an FBX embeds it or names it
by a relative and an absolute path, an ``.mtl`` names it relative to itself, USD resolves an
asset), but what follows is the same. The skin's material is the face's largest kept part not
marked not face (the studio has one diffuse map: an eye's texture cannot share it). An image
that cannot be found or read is said in the report and the head keeps plain skin (or a flat
normal map), as Blender opens such a material untextured: a missing texture is a common
hand-over slip, not a reason to refuse the head. An image over the budgets is still refused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from studio.core.files.budgets import FILE_BYTES, GLTF_IMAGE_BYTES, IMAGE_BYTES
from studio.core.files.errors import ImageError, MeshError, StudioError
from studio.core.files.images import decode_image, decoded_bytes
from studio.core.files.naming import shown, shown_list
from studio.core.files.safe_io import read_regular
from studio.core.formats.gltf.face import FaceChoice
from studio.core.formats.gltf.materials import _rgb
from studio.core.wrinkles.textures import MAP_WORDS, FaceTextures, flat_normal_map, plain_diffuse

Array = np.ndarray


class ImageBudget:
    """The decoded bytes of the images one file's face uses, as the glTF reader counts them."""

    def __init__(self, path: object) -> None:
        self.path = path
        self.total = 0

    def take(self, data: bytes, what: str) -> None:
        size = decoded_bytes(data)  # from the header, before anything is decoded
        IMAGE_BYTES.check(size, f"{what} decoded", self.path, MeshError)
        self.total += size
        GLTF_IMAGE_BYTES.check(self.total, f"the images decoded, with {what},", self.path,
                               MeshError)


@dataclass
class MapSource:
    """Where one material map's pixels are: the bytes the file embeds, else the files it
    names, tried in order (the first that exists is read)."""

    written: str  # the texture's name as the file writes it, for the report
    data: bytes | None = None
    paths: list[Path] = field(default_factory=list)


@dataclass
class HeadMaps:
    """The skin's maps (None: the file gives none that could be read) and the report's lines."""

    diffuse: Array | None = None
    normal: Array | None = None
    lines: list[str] = field(default_factory=list)
    files: dict[str, Path] = field(default_factory=dict)  # slot -> the file it was read from

    def textures(self) -> FaceTextures:
        """The project's maps: the file's where it gave them, plain skin and flat otherwise."""
        return FaceTextures(_rgb(self.diffuse, plain_diffuse()),
                            _rgb(self.normal, flat_normal_map()), flat_normal_map())


def skin_part(choice: FaceChoice, primitive_of_triangle: Array) -> int:
    """The kept part (index into ``choice.kept``) whose material is the skin's: the largest
    not marked not face."""
    sizes = np.bincount(primitive_of_triangle, minlength=len(choice.kept))
    skin = [k for k, key in enumerate(choice.kept) if key not in choice.not_face] or [0]
    return max(skin, key=lambda k: sizes[k])


def read_head_maps(sources: dict[str, MapSource | None], material: str, origin: object,
                   budget: ImageBudget | None = None) -> HeadMaps:
    """The skin material's maps (``sources`` by slot, "diffuse" and "normal"), each said in
    the report: which texture, or why none shows."""
    budget = budget or ImageBudget(origin)
    maps = HeadMaps()
    for slot, source in sources.items():
        if source is None:
            continue
        word, fallback = MAP_WORDS[slot]
        image, line, file = _read(source, f"{word}: texture {shown(source.written)} of "
                                  f"material {shown(material or '(unnamed)')}", fallback, budget)
        setattr(maps, slot, image)
        maps.lines.append(line)
        if file is not None and image is not None:
            maps.files[slot] = file
    return maps


def _read(source: MapSource, said: str, fallback: str, budget: ImageBudget
          ) -> tuple[Array | None, str, Path | None]:
    """One map's pixels, its report line and the file it came from (None: embedded)."""
    data, where, found = source.data, "embedded in the file", None
    if not data:
        found = next((p for p in source.paths if p.is_file()), None)
        if found is None:
            tried = shown_list(dict.fromkeys(str(p) for p in source.paths)) or "no path given"
            return None, f"{said} not found (looked for {tried}): {fallback}", None
        try:
            data = read_regular(found, FILE_BYTES.value, ImageError, "texture",
                                FILE_BYTES.setting)
        except StudioError as exc:
            return None, f"{said} cannot be read ({exc.problem}): {fallback}", None
        where = shown(found)
    budget.take(data, f"texture {shown(source.written)}")
    try:
        image = decode_image(data, where)
    except ImageError as exc:
        return None, f"{said} is unreadable ({exc.problem}): {fallback}", None
    return image, f"{said} ({where}, {image.shape[1]}×{image.shape[0]})", found
