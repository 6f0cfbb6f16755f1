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
# Files read whole into memory (meshes, glTF, images) before they are parsed.
FILE_BYTES = Budget("MAX_FILE_BYTES", 2 << 30, "bytes")
# Meshes: vertices and triangles of one mesh, and key poses (morph targets) of one face.
MESH_VERTICES = Budget("MAX_MESH_VERTICES", 20_000_000, "vertices")
MESH_TRIANGLES = Budget("MAX_MESH_TRIANGLES", 40_000_000, "triangles")
POSES = Budget("MAX_POSES", 1000, "key poses")
# JSON nesting (project.json, glTF): real documents nest under ten levels.
JSON_DEPTH = Budget("MAX_JSON_DEPTH", 64, "levels")
# Rendering: pixels of one frame (colour + depth, multisampled), frames of one animation, and
# the pixels of a whole GIF (one byte each, the file's size before compression).
RENDER_PIXELS = Budget("MAX_RENDER_PIXELS", 8192 * 8192, "pixels")
FRAMES = Budget("MAX_FRAMES", 100_000, "frames")
GIF_PIXELS = Budget("MAX_GIF_PIXELS", 2_000_000_000, "pixels")
PATTERN_WIDTH = Budget("MAX_PATTERN_WIDTH", 16, "characters")


def json_depth(text: str | bytes) -> int:
    """How deeply the JSON ``text`` nests its arrays and objects (brackets inside strings do
    not count), found without parsing, so a hostile document cannot exhaust the stack."""
    import re

    import numpy as np

    data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    stripped = re.sub(rb'"(?:[^"\\]|\\.)*"', b'""', data, flags=re.DOTALL)
    codes = np.frombuffer(stripped, np.uint8)
    steps = (np.isin(codes, (ord("["), ord("{"))).astype(np.int64)
             - np.isin(codes, (ord("]"), ord("}"))))
    return int(np.cumsum(steps).max(initial=0))


def check_json_depth(text: str | bytes, what: str, path: object = None,
                     error: type[StudioError] = BudgetError) -> None:
    """Refuse a JSON document nested deeper than :data:`JSON_DEPTH` (before ``json.loads``)."""
    JSON_DEPTH.check(json_depth(text), f"the nesting of {what}", path, error)
