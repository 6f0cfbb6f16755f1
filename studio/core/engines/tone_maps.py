"""Each engine wrinkle map's cavity and colour (core/wrinkles/skin_tone.py) as the engine's
shader takes them, beside the normal map it goes with:

- MetaHuman style: an animated colour map (the albedo as the wrinkle shows it: the head's
  diffuse times the tint) and a cavity map (white open skin), ``<map>_color`` and
  ``<map>_cavity`` beside ``<map>``'s normal map;
- Character Creator style: an AO map (the cavity as it is) and a redness map (greyscale, white
  where the skin flushes fully), ``<map>_AO`` and ``<map>_Redness``.

A slot composed from several project maps takes each texel's from the same map as its normals
(``slot_image``). Other layouts (O3DE, Source) have no such inputs; a face without cavity and
colour maps writes none. Documented in docs/engines/metahuman.md and cc.md.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from studio.core.project.model import Project
from studio.core.wrinkles.shading import linear_to_srgb, srgb_to_linear
from studio.core.wrinkles.skin_tone import FLUSH, TINT_ONE, neutral_cavity, neutral_colour
from studio.core.wrinkles.textures import eight_bit, resize_nearest

Array = np.ndarray
# layout → (suffix of the colour image, suffix of the cavity image)
STYLES = {"metahuman": ("_color", "_cavity"), "cc": ("_Redness", "_AO")}


def tone_images(project: Project, layout: str, normal_file: str,
                compose: Callable[[dict[str, Array], Array], Array]) -> list[tuple[str, Array]]:
    """[(file, image)] for the slot whose normal map is ``normal_file``; ``compose(images,
    neutral)``: the slot's image of per-map ``images``."""
    textures = project.textures
    if layout not in STYLES or not textures.has_tone:
        return []
    colour_suffix, cavity_suffix = STYLES[layout]
    tint = compose(textures.colour_maps, neutral_colour(1, 1)).astype(np.float64) / TINT_ONE
    cavity = compose(textures.cavity_maps, neutral_cavity(1, 1))
    stem = Path(normal_file)
    name = stem.stem.removesuffix("_normal")
    colour = animated_colour(textures.diffuse, tint) if layout == "metahuman" else redness(tint)
    return [(str(stem.with_name(f"{name}{colour_suffix}.png")), colour),
            (str(stem.with_name(f"{name}{cavity_suffix}.png")), cavity)]


def animated_colour(diffuse: Array, tint: Array) -> Array:
    """(H, W, 3) uint8 at the diffuse's size: the albedo the wrinkle shows (linear × tint)."""
    h, w = diffuse.shape[:2]
    tint = resize_nearest(tint, h, w) if tint.shape[:2] != (h, w) else tint
    albedo = srgb_to_linear(eight_bit(diffuse).astype(np.float64) / 255.0)
    return np.rint(255.0 * np.clip(linear_to_srgb(albedo * tint), 0.0, 1.0)).astype(np.uint8)


def redness(tint: Array) -> Array:
    """(H, W) uint8: how far toward a full flush (``FLUSH``'s drop of green) the tint is."""
    full = 1.0 - FLUSH[1]
    return np.rint(255.0 * np.clip((1.0 - tint[..., 1]) / full, 0.0, 1.0)).astype(np.uint8)
