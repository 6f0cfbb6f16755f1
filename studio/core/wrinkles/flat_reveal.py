"""Where an area's weight lands on a flat part of its wrinkled map.

An area reveals its wrinkled map with a weight, but where that map equals the neutral one the
weight changes no pixel: the heat view of the weight says "hot" while the picture shows nothing
(issue #28: the left forehead fully hot, 0.00 % of its pixels changed). This measures, per area,
the share of its weight that lands where its map differs from the neutral by less than
``FLAT_BELOW``, so the panels can say why an area shows nothing.

Technique 1: the weight is the area's mask (the activation scales it as a whole). Technique 2:
the visibility its vectors give at its own key pose, per vertex, interpolated over the skin's
UV triangles as the renderer does. Both are measured on a grid of at most ``GRID`` texels a
side, the maps reduced to it by their largest difference in each block (a thin furrow keeps its
block from counting as flat).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.mask_ops import rasterise_uv, resample
from studio.core.wrinkles.shading import reveal_difference
from studio.core.wrinkles.textures import FaceTextures, pack_more_maps, pack_normal_maps
from studio.core.wrinkles.wdv import WdvArea, WdvSetup, visibility

Array = np.ndarray

# |wrinkled − neutral| of unit normals below which a texel shows nothing: about 1.1°, above the
# 8-bit maps' quantisation (one step moves x or y by 0.008)
FLAT_BELOW = 0.02
FLAGGED_SHARE = 0.9  # flagged when at least this share of its weight shows nothing: a soft
# mask over a forehead of furrows puts about half its weight on the flat skin between and around
# them (the sample face: 0.1 to 0.65), which is how wrinkles look, not a mistake
GRID = 256
_ROWS = 256  # rows of a map unpacked at once (a whole 4096² map would take 200 MB)


@dataclass(frozen=True)
class FlatReveal:
    """How much of an area's weight lands where its wrinkled map ``map_name`` is flat."""

    map_name: str
    share: float  # 0..1 of the area's weight

    @property
    def flagged(self) -> bool:
        return self.share >= FLAGGED_SHARE

    def reason(self) -> str:
        return (f"reveals a flat part of '{self.map_name}': {self.share * 100:.0f} % of its "
                "weight shows nothing")


def _block_max(values: Array, shape: tuple[int, int]) -> Array:
    """``values`` reduced to ``shape`` (no larger) by the largest value in each block."""
    rows = np.arange(shape[0]) * values.shape[0] // shape[0]
    cols = np.arange(shape[1]) * values.shape[1] // shape[1]
    return np.maximum.reduceat(np.maximum.reduceat(values, rows, axis=0), cols, axis=1)


class RevealMaps:
    """Per wrinkled map, the grid of texels where it differs from the neutral map, read from the
    maps at the size and bit depth the renderer uploads them (render/face_maps.py)."""

    def __init__(self, textures: FaceTextures, grid: int = GRID) -> None:
        self._sources = self._identity(textures)
        self.names = textures.wrinkle_map_names
        packed = pack_normal_maps(textures.normal_neutral, textures.normal_wrinkled)
        layers = [packed[..., 2:], *list(pack_more_maps(textures, packed))[:len(self.names) - 1]]
        h, w = packed.shape[:2]
        self.shape = (min(h, grid), min(w, grid))
        self.flat: dict[str, Array] = {}
        for name, layer in zip(self.names, layers, strict=True):
            change = np.empty((h, w), np.float32)
            for top in range(0, h, _ROWS):
                rows = slice(top, top + _ROWS)
                change[rows] = reveal_difference(packed[rows, :, :2], layer[rows], np.float32)
            self.flat[name] = _block_max(change, self.shape) < FLAT_BELOW

    @staticmethod
    def _identity(textures: FaceTextures) -> tuple:
        return (id(textures.normal_neutral),
                *((name, id(image)) for name, image in textures.wrinkle_maps.items()))

    def current(self, textures: FaceTextures) -> bool:
        """Built from these very maps (a replaced map is a new array)."""
        return self._sources == self._identity(textures)

    def name(self, wrinkle_map: str) -> str:
        """An area's map ("" or a removed name means the first, as in the renderer)."""
        return wrinkle_map if wrinkle_map in self.flat else self.names[0]

    def share(self, weight: Array, wrinkle_map: str) -> FlatReveal | None:
        """The share of ``weight`` (a UV image, row 0 at v = 1, any size) on flat texels;
        None when the weight is zero everywhere (nothing to show or not)."""
        name = self.name(wrinkle_map)
        h, w = self.shape
        weight = resample(np.asarray(weight, np.float32), (w, h)).astype(np.float64)
        total = weight.sum()
        if total <= 0.0:
            return None
        return FlatReveal(name, float(weight[self.flat[name]].sum() / total))


_CACHE: list[RevealMaps] = []


def reveal_maps(textures: FaceTextures) -> RevealMaps:
    """The measure for these maps, kept while they stay the same arrays (the panels ask on
    every change of an area; the maps change far less often)."""
    if not (_CACHE and _CACHE[0].current(textures)):
        _CACHE[:] = [RevealMaps(textures)]
    return _CACHE[0]


def t1_reveal(maps: RevealMaps, area: InfluenceArea) -> FlatReveal | None:
    """Technique 1: the area's mask against its map."""
    return maps.share(area.mask, area.wrinkle_map)


def t2_weights(area: WdvArea, rest: Array, posed: Array, expression_factor: float = 1.0,
               scale_free: bool = True) -> Array:
    """(W,) the visibility the area's vectors give each welded vertex at ``posed`` (its key
    pose), the area alone (numpy reference of the vertex shader)."""
    alone = WdvSetup([area]).pack_slots(len(rest))
    return visibility(np.asarray(posed, np.float64) - rest, alone, expression_factor,
                      scale_free)[:, 0]


def t2_reveal(maps: RevealMaps, skin: FaceMesh, area: WdvArea, posed: Array,
              expression_factor: float = 1.0, scale_free: bool = True) -> FlatReveal | None:
    """Technique 2: the area's visibility at its key pose, drawn over ``skin``'s UV triangles
    (only those the area reaches), against its map."""
    weights = t2_weights(area, skin.rest, posed, expression_factor, scale_free)[skin.weld]
    reached = (weights[skin.triangles] > 0.0).any(axis=1)
    if not reached.any():
        return None
    size = max(maps.shape)
    image, _ = rasterise_uv(skin.uvs, skin.triangles[reached], weights.astype(np.float32), size)
    return maps.share(image, area.wrinkle_map)
