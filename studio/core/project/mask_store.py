"""Masks shared by several influence areas, and the decoded-pixel budget of one project file.

Why: project.json names each area's mask member, so a file (hand-made or hostile) can point N
areas at one 8192² 16-bit mask: the archive's own limits see one small member, but each area
holds its mask as float32 — 256 MB per area. The loader therefore decodes each member once
(:class:`ImageBudget` keeps it) and charges every image's decoded bytes, and every area's float
copy, to :data:`~studio.core.files.budgets.TOTAL_IMAGE_BYTES` *before* decoding, with the per-image
:data:`~studio.core.files.budgets.IMAGE_PIXELS` limit read from the PNG header. Saving stores a mask
that several areas share (the same array, or equal values) once, every area pointing at it.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from studio.core.files.budgets import IMAGE_PIXELS, TOTAL_IMAGE_BYTES
from studio.core.files.errors import ProjectError
from studio.core.files.png import png_header

Array = np.ndarray
_CHANNELS = {0: 1, 2: 3, 3: 4, 4: 2, 6: 4}  # PNG colour type -> channels decoded (palette: RGBA)


class ImageBudget:
    """Decoded-image accounting for one load: refuse before decoding, decode each member once."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self.total = 0
        self.cache: dict[str, Array] = {}

    def _charge(self, amount: int, what: str) -> None:
        self.total += amount
        TOTAL_IMAGE_BYTES.check(self.total, f"the decoded images, with {what},", self.path,
                                ProjectError)

    def shared(self, name: Any, what: str, grey: bool) -> Array | None:
        """The member's pixels if it was decoded already (a mask shared by several areas): the
        new area's own float32 copy is still charged."""
        image = self.cache.get(name) if isinstance(name, str) else None
        if image is None or (image.ndim == 2) != grey:
            return None
        if grey:
            self._charge(image.size * 4, what)
        return image

    def claim(self, name: str, data: bytes, what: str, grey: bool) -> None:
        """Check the image's declared size against the budgets before it is decoded."""
        width, height, depth, colour, _ = png_header(data)
        IMAGE_PIXELS.check(width * height, f"'{name}' ({what})", self.path, ProjectError)
        amount = width * height * _CHANNELS.get(colour, 4) * (2 if depth == 16 else 1)
        self._charge(amount + (width * height * 4 if grey else 0), what)

    def plan_masks(self, names: Sequence[Any], read: Callable[[str, str], bytes]) -> None:
        """Charge all the areas' masks at once, from their PNG headers, before any is decoded:
        one member shared by N areas costs one decode plus N float32 copies."""
        projected = self.total
        headers: dict[str, tuple[int, int, int, int]] = {}
        for name in names:
            if not isinstance(name, str):
                continue
            if name not in headers:
                try:
                    width, height, depth, colour, _ = png_header(read(name, "a mask"))
                except (ValueError, ProjectError):
                    continue  # reported with its area when it is read
                headers[name] = (width, height, depth, colour)
                projected += width * height * _CHANNELS.get(colour, 4) * (depth // 8 or 1)
            width, height, *_ = headers[name]
            projected += width * height * 4
        TOTAL_IMAGE_BYTES.check(projected, f"the decoded images, with the {len(names)} "
                                "influence masks,", self.path, ProjectError)

    def keep(self, name: str, image: Array) -> None:
        self.cache[name] = image


def _fingerprint(mask: Array) -> bytes:
    """A cheap key for equal masks: the shape and a strided sample of the values."""
    sample = np.ascontiguousarray(mask[::61, ::67])
    return hashlib.blake2b(repr(mask.shape).encode() + sample.tobytes(), digest_size=16).digest()


def mask_members(areas: Sequence[Any], name: Callable[[int, str], str]) -> list[str]:
    """The archive member of each area's mask: the first area's with an equal mask (the same
    array or the same values), else its own ``name(index, area name)``."""
    members: list[str] = []
    seen: dict[bytes, list[int]] = {}
    for i, area in enumerate(areas):
        member = name(i, area.name)
        key = _fingerprint(area.mask)
        for j in seen.get(key, []):
            other = areas[j].mask
            if other is area.mask or (other.shape == area.mask.shape
                                      and np.array_equal(other, area.mask)):
                member = members[j]
                break
        else:
            seen.setdefault(key, []).append(i)
        members.append(member)
    return members
