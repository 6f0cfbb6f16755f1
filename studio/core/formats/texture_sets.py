"""Texture files as artists hand them over: one image, or a UDIM set (``skin.1001.png``,
``skin.1002.png``, … — also ``skin_1001.png`` and ``skin.<UDIM>.png``), composed into the
atlas the project's UVs were packed into (``uv_tiles``).

Naming any one file of a set loads the whole set; a plain image is tile 1001's. Tiles the mesh
uses but the set lacks get a neutral fill (skin colour, a flat normal), tiles the mesh does not
use are ignored and reported.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.errors import ImageError
from studio.core.files.images import load_rgb
from studio.core.mesh.uv_tiles import FIRST_TILE, TileLayout, atlas_size, compose_atlas

Array = np.ndarray

_TILE_NAME = re.compile(r"^(?P<stem>.*?)(?P<sep>[._])(?P<tile>1\d{3})$")
_TOKEN = "<UDIM>"


@dataclass
class TextureSet:
    """The files of one texture, by UDIM tile."""

    files: dict[int, Path]
    pattern: str  # how the set was found, for messages


def find_tile_set(path: str | Path) -> TextureSet:
    """The UDIM set a file belongs to (just itself, as tile 1001, when its name has no tile)."""
    path = Path(path)
    name = path.name
    if _TOKEN in name.upper():
        start = name.upper().index(_TOKEN)
        prefix, suffix = name[:start], name[start + len(_TOKEN):]
        matches = _siblings(path.parent, prefix, suffix)
        if not matches:
            raise ImageError(f"no files match the UDIM pattern ({prefix}1001{suffix}, …)", path)
        return TextureSet(matches, str(path))
    match = _TILE_NAME.match(path.stem)
    if match is None:
        return TextureSet({FIRST_TILE: path}, str(path))
    prefix = match["stem"] + match["sep"]
    files = _siblings(path.parent, prefix, path.suffix)
    files.setdefault(int(match["tile"]), path)
    return TextureSet(files, str(path.parent / f"{prefix}<UDIM>{path.suffix}"))


def _siblings(folder: Path, prefix: str, suffix: str) -> dict[int, Path]:
    found: dict[int, Path] = {}
    try:
        entries = list(folder.iterdir())
    except OSError:
        return found
    for entry in entries:
        name = entry.name
        if not (name.startswith(prefix) and name.endswith(suffix)):
            continue
        middle = name[len(prefix):len(name) - len(suffix)]
        if len(middle) == 4 and middle.isdigit() and middle.startswith("1") and entry.is_file():
            found[int(middle)] = entry
    return found


def load_texture(path: str | Path, layout: TileLayout | None, fill: Array) -> Array:
    """An RGB texture for the project's UV layout: the file itself for an untiled face, else
    the set's tiles composed into the atlas (each tile's cell at the set's resolution, as far
    as the atlas budget allows)."""
    texture_set = find_tile_set(path)
    if layout is None or layout.trivial:
        tile = FIRST_TILE if FIRST_TILE in texture_set.files else min(texture_set.files)
        return load_rgb(texture_set.files[tile])
    used = {t: p for t, p in texture_set.files.items() if t in layout.tiles}
    if not used:
        raise ImageError(f"none of the texture's tiles ({_tiles(texture_set.files)}) is one the "
                         f"mesh's UVs use ({_tiles(layout.tiles)})", path)
    images = {t: load_rgb(p) for t, p in used.items()}
    tile_size = max(max(image.shape[:2]) for image in images.values())
    size = atlas_size(layout, tile_size)
    return compose_atlas(images, layout, fill, size)


def _tiles(tiles) -> str:
    return ", ".join(str(t) for t in sorted(tiles))
