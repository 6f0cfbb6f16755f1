"""Technique 1 data: influence-area masks, the activation vector, and links from poses (SPEC §4).

Masks are UV-space greyscale images with 1 = full influence, all of one resolution so they pack
into one texture array. Image row 0 is the top of the UV square (v = 1), as in any image editor.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray


@dataclass(eq=False)
class InfluenceArea:
    name: str
    mask: Array  # (H, W) float32 in [0, 1]
    colour: tuple[int, int, int] = (255, 128, 0)
    activation: float = 0.0  # the user's own slider, added to what linked poses give
    visible: bool = True
    wrinkle_map: str = ""  # the wrinkled normal map this area reveals ("" = the first one)

    def __post_init__(self) -> None:
        self.mask = np.clip(np.ascontiguousarray(self.mask, dtype=np.float32), 0.0, 1.0)


@dataclass(eq=False)
class InfluenceSetup:
    areas: list[InfluenceArea] = field(default_factory=list)
    # pose name -> {area name: gain}: moving toward the pose raises those areas' activations
    links: dict[str, dict[str, float]] = field(default_factory=dict)

    @property
    def resolution(self) -> tuple[int, int] | None:
        return self.areas[0].mask.shape if self.areas else None

    def mask_stack(self) -> Array:
        """(N, H, W) float32 masks in area order, for the texture array."""
        if not self.areas:
            return np.zeros((0, 1, 1), dtype=np.float32)
        return np.stack([a.mask for a in self.areas])

    def activations(self, pose_weights: Mapping[str, float] | None = None) -> Array:
        """Each area's own value plus ``Σ gain·weight`` of its linked poses, clamped to [0, 1]."""
        values = np.array([a.activation for a in self.areas], dtype=np.float32)
        index = {a.name: i for i, a in enumerate(self.areas)}
        for pose, weight in (pose_weights or {}).items():
            for area, gain in self.links.get(pose, {}).items():
                if area in index:
                    values[index[area]] += gain * weight
        hidden = np.array([not a.visible for a in self.areas], dtype=bool)
        values[hidden] = 0.0
        return np.clip(values, 0.0, 1.0)
