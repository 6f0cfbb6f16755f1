"""The skin's tone under a wrinkled map: a cavity map and a colour map per wrinkled normal map.

A normal map alone gives a crease lit walls and nothing else: carved clay. Skin also shadows
itself at the bottom of a fold (the light there is blocked by its walls) and changes colour
with the blood under it: compressed skin flushes (the blood pools where the tissue bunches),
stretched skin blanches (pressed out of it). Engines carry both: MetaHuman blends animated colour
maps and a cavity map by the same region masks as its wrinkle normals; Character Creator's
wrinkle sets carry AO and redness maps.

The two maps of a wrinkled map, each blended by that map's weight exactly as its normals are
(face.frag: ``(1 − W) · neutral + Σ w_m · map_m``):

- **cavity**, greyscale, 8-bit: white (255) is open skin, darker is deeper in a crease — the
  convention of an engine's cavity or AO map, so it exports as it is. Made from the map's
  wrinkle height (``relief.wrinkle_heights``: the slopes the map adds to the neutral one,
  integrated): the deepest crease of the map keeps ``1 − CAVITY_DARKEST`` of its light.
- **colour**, RGB, 8-bit: a tint the albedo is multiplied by, 128 (mid grey) = unchanged, so
  value / 128 (an overlay a painter can paint over in any editor). Made from the poses' strain
  (``skin_strain``): compression toward ``FLUSH``, stretch toward ``BLANCH``.

The neutral of both is "no change": a face without them renders exactly as before, and a
wrinkled map with a zero weight changes nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.relief import wrinkle_heights
from studio.core.wrinkles.skin_strain import WRINKLING_COMPRESSION, SkinStrain
from studio.core.wrinkles.textures import FaceTextures, resize_nearest

Array = np.ndarray

CAVITY_DARKEST = 0.45  # light taken from the bottom of a map's deepest crease
CAVITY_FLOOR = 0.03  # depths (of the map's deepest) under this are open skin
CAVITY_SIZE = 512  # the heights are integrated at most this size (the cost grows with area)
TINT_ONE = 128  # the colour map's value of an unchanged albedo
FLUSH = (1.0, 0.8, 0.78)  # linear tint of fully compressed skin: redder (blood pooled)
BLANCH = (1.04, 1.1, 1.1)  # linear tint of fully stretched skin: paler, less red
FULL_SHARE = 95  # percentile of a pose's compressed (stretched) skin at which the tint is full
LEAST_FULL = 0.05  # … but never below 5 % strain, so a pose that barely moves stays pale
COLOUR_SIZE = 512  # strain is smooth: the colour map is at most this size
COLOUR_SOFTNESS = 0.01  # blur radius, share of the map: no triangle edges in the colour


def neutral_cavity(height: int, width: int) -> Array:
    """(H, W) uint8: open skin everywhere."""
    return np.full((height, width), 255, np.uint8)


def neutral_colour(height: int, width: int) -> Array:
    """(H, W, 3) uint8: an unchanged albedo everywhere."""
    return np.full((height, width, 3), TINT_ONE, np.uint8)


def cavity_map(neutral: Array, wrinkled: Array) -> Array:
    """(H, W) uint8 at the wrinkled map's size: how deep each texel lies in a crease the
    wrinkled map adds to the neutral one (its valleys; the skin bunched between furrows and
    the neutral map's own detail stay open)."""
    height = wrinkle_heights(neutral, [wrinkled], max_size=CAVITY_SIZE)[0]
    # the integration's slow drift (a few hundredths) is no crease: open skin stays open
    depth = np.clip((-height - CAVITY_FLOOR) / (1.0 - CAVITY_FLOOR), 0.0, 1.0)
    h, w = wrinkled.shape[:2]
    if depth.shape != (h, w):
        depth = np.clip(mask_ops.resample(depth, (w, h)), 0.0, 1.0)
    return np.rint(255.0 * (1.0 - CAVITY_DARKEST * depth)).astype(np.uint8)


def strain_tint(compression: Array, stretch: Array) -> Array:
    """(..., 3) linear tint of skin this compressed and stretched (each in [0, 1] of full):
    where both (a squeeze one way bulging the other), they offset."""
    amount = np.clip(np.asarray(compression, np.float32) - np.asarray(stretch, np.float32),
                     -1.0, 1.0)[..., None]
    flush = 1.0 + np.maximum(amount, 0.0) * (np.asarray(FLUSH, np.float32) - 1.0)
    blanch = 1.0 + np.maximum(-amount, 0.0) * (np.asarray(BLANCH, np.float32) - 1.0)
    return flush * blanch


def encode_tint(tint: Array) -> Array:
    return np.clip(np.rint(np.asarray(tint) * TINT_ONE), 0, 255).astype(np.uint8)


def _full(values: Array) -> float:
    """The strain at which a pose's tint is full: most of its strained skin's, at least
    ``LEAST_FULL``."""
    strained = values[values >= WRINKLING_COMPRESSION]
    if strained.size == 0:
        return np.inf
    return float(max(np.percentile(strained, FULL_SHARE), LEAST_FULL))


def pose_strain(strain: SkinStrain, target: Array) -> tuple[Array, Array]:
    """((W,), (W,)) how compressed and how stretched a pose (a shape of the face's welded
    vertices) leaves the skin at each vertex, each in [0, 1] of that pose's own full strain."""
    s = strain.of(np.asarray(target))
    stretched = np.maximum(s.stretch, 0.0)
    return (strain.per_vertex(np.clip(s.compression / _full(s.compression), 0.0, 1.0)),
            strain.per_vertex(np.clip(stretched / _full(stretched), 0.0, 1.0)))


def colour_map(strains: Sequence[tuple[Array, Array]], weld: Array,
               image: Callable[[Array], Array]) -> Array:
    """(S, S, 3) uint8: the tint of the skin the poses (``pose_strain`` of each) strain
    most, each texel by the pose compressing (or stretching) it most. ``image`` draws
    per-render-vertex values (``weld``: render vertex → welded) into an (S, S) UV image; the
    strain is smooth, so S may be well under the normal map's size (the renderer and the
    exports scale it)."""
    welded = strains[0][0].shape if strains else (int(weld.max(initial=-1)) + 1,)
    most = [np.zeros(welded, np.float32), np.zeros(welded, np.float32)]
    for pose in strains:
        most = [np.maximum(m, v) for m, v in zip(most, pose, strict=True)]
    images = []
    for values in most:
        drawn = image(values[weld])
        images.append(np.clip(mask_ops.blur(drawn, COLOUR_SOFTNESS * drawn.shape[0]), 0.0, 1.0))
    return encode_tint(strain_tint(*images))


def blended_tone(weights: Array, total: Array, colour: Array, cavity: Array
                 ) -> tuple[Array, Array]:
    """((..., 3) tint, (...) light kept) at a texel: the neutral (no change) and each map's
    tone blended by the per-map ``weights`` (..., M) summing to ``total``, as face.frag's
    ``blended_tone``. ``colour`` (..., M, 3) and ``cavity`` (..., M) are texel values in
    [0, 1] (value / 255)."""
    w = np.asarray(weights, np.float64)
    rest = (1.0 - np.asarray(total, np.float64))
    tint = rest[..., None] + (w[..., None] * np.asarray(colour) * (255.0 / TINT_ONE)).sum(-2)
    kept = rest + (w * np.asarray(cavity)).sum(-1)
    return tint, kept


def pack_tone(textures: FaceTextures) -> Array:
    """(M, H, W, 4) uint8, a layer per wrinkled map: its colour (rgb) and cavity (a), the
    neutral where it lacks one, all at the size of the largest (nearest texel)."""
    names = textures.wrinkle_map_names
    images = [*textures.cavity_maps.values(), *textures.colour_maps.values()]
    h = max(image.shape[0] for image in images)
    w = max(image.shape[1] for image in images)
    layers = np.empty((len(names), h, w, 4), np.uint8)
    for m, name in enumerate(names):
        colour = textures.colour_maps.get(name, neutral_colour(1, 1))
        cavity = textures.cavity_maps.get(name, neutral_cavity(1, 1))
        layers[m, ..., :3] = resize_nearest(colour, h, w)
        layers[m, ..., 3] = resize_nearest(cavity, h, w)
    return layers
