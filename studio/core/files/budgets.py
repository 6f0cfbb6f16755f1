"""Budgets: how much memory and time one input may cost, checked before the work is done.

Why: a small file can claim a huge image (a 16384² texture, a 10⁹-frame timeline, a
``%999999999d`` pattern), and decoding first and failing later means minutes of work, gigabytes
of memory or a killed process. Each reader compares what the input *declares* with a budget
here and refuses it at once with a :class:`BudgetError` that says which limit was hit and how
to change it.

Every budget has a default that covers real faces with room to spare, and an environment
variable that changes it (``WRINKLE_STUDIO_MAX_IMAGE_PIXELS=300000000 wrinkle-studio …``); the
command-line options that choose a size (``--frames``, ``--size``) say so in their messages.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from studio.core.files.errors import StudioError


class BudgetError(StudioError):
    """An input larger than a budget allows."""


@dataclass(frozen=True)
class Budget:
    """One limit: its name (the environment variable's suffix), default and unit."""

    name: str
    default: int
    unit: str

    @property
    def setting(self) -> str:
        return f"WRINKLE_STUDIO_{self.name}"

    @property
    def value(self) -> int:
        """The limit in force: the environment's setting if it is a positive whole number."""
        text = os.environ.get(self.setting, "")
        try:
            value = int(text.replace("_", ""))
        except ValueError:
            return self.default
        return value if value > 0 else self.default

    def check(self, amount: int, what: str, path: object = None,
              error: type[StudioError] = BudgetError, hint: str = "") -> None:
        """Raise ``error`` when ``amount`` is over the limit; the message names the setting."""
        limit = self.value
        if amount > limit:
            how = f"{hint} or set {self.setting}" if hint else f"set {self.setting}"
            raise error(f"{what} is {amount:,} {self.unit}, more than the limit of {limit:,} "
                        f"{self.unit} ({how} to change it)", path)


# Images: decoded pixels of one image, and decoded bytes of all the images one file holds.
IMAGE_PIXELS = Budget("MAX_IMAGE_PIXELS", 8192 * 8192, "pixels")
TOTAL_IMAGE_BYTES = Budget("MAX_TOTAL_IMAGE_BYTES", 3 << 30, "bytes")
# Decoded bytes of one image (width × height × channels × bytes a channel, from its header):
# 128 MiB, a 4096² RGBA map at 16 bits or an 8192 × 4096 RGBA one at 8. Pixels alone are not
# enough: an 8192² RGBA image at 16 bits is 512 MiB decoded. An image costs about twice its
# decoded size while it is decoded and converted, so 128 MiB keeps the studio under 500 MB; an
# 8K RGB texture (192 MiB) needs this raised (and some 700 MB).
IMAGE_BYTES = Budget("MAX_IMAGE_BYTES", 128 << 20, "bytes")
# Decoded bytes of all the images one glTF file's face uses: two maps at the limit above (a
# diffuse and a normal map, 4096² RGBA at 16 bits: 413 MB for the whole import), four at 4K
# and 8 bits; each stays in memory until the project is made.
GLTF_IMAGE_BYTES = Budget("MAX_GLTF_IMAGE_BYTES", 256 << 20, "bytes")
# Numbers a glTF file's accessors are read as, counted from what the file declares before any
# is read, every placed copy of a mesh and every use of a shared accessor counted again: each
# is a float64 while the scene is placed and welded, and a key pose's copy is made of it, so a
# file at the limit costs about 350 MB. 16 million is a 30 000-vertex head with 170 morph
# targets (ARKit's 52 with room to spare); a hostile file claims billions.
GLTF_VALUES = Budget("MAX_GLTF_VALUES", 16_000_000, "numbers")
# Keys of an animation read from a file (samples × animated key poses): each is a Python object
# in memory and some 70 bytes of project.json, whose reader takes 64 MB.
TIMELINE_KEYS = Budget("MAX_TIMELINE_KEYS", 500_000, "keys")
# Files read whole into memory (meshes, glTF, images) before they are parsed.
FILE_BYTES = Budget("MAX_FILE_BYTES", 2 << 30, "bytes")
# Meshes: vertices and triangles of one mesh, and key poses (morph targets) of one face.
MESH_VERTICES = Budget("MAX_MESH_VERTICES", 20_000_000, "vertices")
MESH_TRIANGLES = Budget("MAX_MESH_TRIANGLES", 40_000_000, "triangles")
POSES = Budget("MAX_POSES", 1000, "key poses")
# JSON nesting (project.json, glTF): real documents nest under ten levels.
JSON_DEPTH = Budget("MAX_JSON_DEPTH", 64, "levels")
# JSON arrays and objects, and bytes outside strings, of one document: parsed, a number costs
# 32 bytes and an empty object 64, so a 200 MB list of numbers would take gigabytes; a real
# glTF has thousands of objects, a project's timeline one list a key.
JSON_CONTAINERS = Budget("MAX_JSON_CONTAINERS", 2_000_000, "arrays and objects")
JSON_SYNTAX_BYTES = Budget("MAX_JSON_SYNTAX_BYTES", 64 << 20, "bytes")
# Rendering: pixels of one frame (colour + depth, multisampled), frames of one animation, and
# the pixels of a whole GIF (one byte each, the file's size before compression).
RENDER_PIXELS = Budget("MAX_RENDER_PIXELS", 8192 * 8192, "pixels")
FRAMES = Budget("MAX_FRAMES", 100_000, "frames")
GIF_PIXELS = Budget("MAX_GIF_PIXELS", 2_000_000_000, "pixels")
PATTERN_WIDTH = Budget("MAX_PATTERN_WIDTH", 16, "characters")


# A JSON string: quotes around anything but a quote or backslash, or a backslash escape
# (written unrolled: one step per run of plain characters, not one per character).
_JSON_STRING = rb'"[^"\\]*(?:\\.[^"\\]*)*"'
_SCAN_PIECE = 1 << 20  # bytes of JSON counted at a time


def json_shape(text: str | bytes) -> tuple[int, int, int]:
    """(how deeply the JSON ``text`` nests its arrays and objects, how many it holds, its
    bytes outside strings), found without parsing (brackets inside strings do not count), so a
    hostile document cannot exhaust the stack or the memory of ``json.loads``.

    Why this way: it must cost less than the parse it guards. Strings (an 11 MB data URI is
    one) are cut out in C, then the brackets are counted a megabyte at a time: the scan costs
    the text without its strings and some 12 MB, where ``json.loads`` spends 50 bytes or more
    on every list or object it makes.
    """
    import re

    import numpy as np

    data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    stripped = re.sub(_JSON_STRING, b"", data, flags=re.DOTALL)
    deepest = depth = containers = 0
    for start in range(0, len(stripped), _SCAN_PIECE):  # a piece at a time: memory is bounded
        folded = np.frombuffer(stripped, np.uint8, min(_SCAN_PIECE, len(stripped) - start),
                               start) | 0x20  # "[" and "{" alike, "]" and "}" alike
        opening = (folded == ord("{")).view(np.int8)
        containers += int(np.count_nonzero(opening))
        steps = opening - (folded == ord("}")).view(np.int8)
        levels = np.cumsum(steps, dtype=np.int64) + depth
        deepest = max(deepest, int(levels.max()))
        depth = int(levels[-1])
    return deepest, containers, len(stripped)


def json_depth(text: str | bytes) -> int:
    """How deeply the JSON ``text`` nests its arrays and objects."""
    return json_shape(text)[0]


def check_json_depth(text: str | bytes, what: str, path: object = None,
                     error: type[StudioError] = BudgetError) -> None:
    """Refuse, before ``json.loads``, a JSON document nested deeper than :data:`JSON_DEPTH` or
    holding more than :data:`JSON_CONTAINERS` arrays and objects or :data:`JSON_SYNTAX_BYTES`
    outside its strings."""
    depth, containers, syntax = json_shape(text)
    JSON_DEPTH.check(depth, f"the nesting of {what}", path, error)
    JSON_CONTAINERS.check(containers, f"the arrays and objects of {what}", path, error)
    JSON_SYNTAX_BYTES.check(syntax, f"{what} outside its strings", path, error)
