"""The skin look: its light rigs and the numpy reference of shaders/skin.glsl.

Why this model (measured against the alternatives in docs/performance.md's terms: a software
renderer runs every line for every pixel): Penner's pre-integrated skin (2011) needs a
curvature per pixel and a lookup texture; separable subsurface scattering (Jimenez et al.
2015) needs a screen-space blur pass. A wrapped diffuse with one wrap width per channel is the
usual cheap fit of Penner's table at moderate curvature: red light reaches past the terminator
and shadows turn warm, without a texture or a pass. Specular is two GGX lobes (a broad one for
the epidermis, a sharp one for the oily film, as engines' dual-lobe skin), with Schlick's
Fresnel at skin's F0 (0.028) and Kelemen's visibility term.

Light comes from a rig a person picks (``RIGS``): the studio three-point (the view's key light,
a cool fill opposite, a rim from behind), a soft overcast sky (light from above and both sides,
much ambient) or one hard raking key from the side (for checking lines: grazing light shows
every furrow). Directions are in view space, toward the light, so the face stays lit while the
user orbits (common.glsl's convention).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

LOOKS = ("clay", "skin")  # clay: the studio's first shading (common.glsl), unchanged
RIG_NAMES = ("studio", "overcast", "raking")
RIG_LABELS = {"studio": "Studio three-point", "overcast": "Soft overcast",
              "raking": "Hard raking key"}
SCATTER = (0.35, 0.15, 0.08)  # wrap width per channel: red scatters furthest
F0 = 0.028  # skin's reflectance at normal incidence
LOBES = ((0.5, 0.8), (0.25, 0.2))  # (GGX roughness, weight): epidermis, oily film
SPECULAR = 0.5  # the lobes' strength (a light of intensity 1)
LIGHTS = 3  # every rig has three lights (unused ones are black): one program for all


@dataclass(frozen=True)
class Rig:
    """Three lights (view-space directions toward them, linear RGB intensities) and the
    ambient light (RGB)."""

    directions: tuple[tuple[float, float, float], ...]
    colours: tuple[tuple[float, float, float], ...]
    ambient: tuple[float, float, float]


def _unit(v) -> tuple[float, float, float]:
    a = np.asarray(v, np.float64)
    a = a / np.linalg.norm(a)
    return (float(a[0]), float(a[1]), float(a[2]))


def light_rig(name: str, key_dir: tuple[float, float, float]) -> Rig:
    """The rig ``name`` around the view's key light ``key_dir`` (the studio rig's key and the
    side the raking key comes from)."""
    key = _unit(key_dir)
    side = 1.0 if key[0] >= 0.0 else -1.0
    if name == "studio":
        return Rig((key, _unit((-key[0], 0.2, 0.6)), _unit((-0.5 * side, 0.45, -0.75))),
                   ((1.0, 0.96, 0.92), (0.12, 0.14, 0.17), (0.3, 0.3, 0.3)),
                   (0.05, 0.05, 0.06))
    if name == "overcast":
        return Rig((_unit((0.0, 0.9, 0.45)), _unit((0.7, 0.3, 0.65)), _unit((-0.7, 0.3, 0.65))),
                   ((0.45, 0.47, 0.5), (0.3, 0.3, 0.31), (0.3, 0.3, 0.31)),
                   (0.22, 0.23, 0.25))
    if name == "raking":
        return Rig((_unit((0.96 * side, 0.12, 0.25)), (0.0, 0.0, 1.0), (0.0, 0.0, 1.0)),
                   ((1.4, 1.35, 1.3), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
                   (0.02, 0.02, 0.02))
    raise ValueError(f"unknown light rig '{name}' (choose from {', '.join(RIG_NAMES)})")


def _ggx(n_h: Array, roughness: float) -> Array:
    a2 = roughness ** 4  # alpha = roughness², as engines parameterise it
    d = n_h * n_h * (a2 - 1.0) + 1.0
    return a2 / (np.pi * d * d)


def skin_received(n: Array, view_dir: Array, rig: Rig) -> tuple[Array, Array]:
    """((..., 3) diffuse, (..., 3) specular) light a unit normal receives from the rig's
    lights (ambient not included): skin.glsl's ``skin_receive``."""
    diffuse = np.zeros((*n.shape[:-1], 3))
    specular = np.zeros((*n.shape[:-1], 3))
    wrap = np.asarray(SCATTER)
    for direction, colour in zip(rig.directions, rig.colours, strict=True):
        l_dir = np.asarray(direction)
        colour = np.asarray(colour)
        n_l = (n * l_dir).sum(axis=-1)[..., None]
        diffuse += colour * np.clip((n_l + wrap) / (1.0 + wrap), 0.0, 1.0) ** (1.0 + wrap)
        h = view_dir + l_dir
        h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-6)
        n_h = np.clip((n * h).sum(axis=-1), 0.0, 1.0)
        l_h = np.clip((l_dir * h).sum(axis=-1), 0.0, 1.0)
        fresnel = F0 + (1.0 - F0) * (1.0 - l_h) ** 5
        lobes = sum(weight * _ggx(n_h, rough) for rough, weight in LOBES)
        spec = SPECULAR * fresnel * lobes / np.maximum(4.0 * l_h * l_h, 0.1)
        specular += colour * (spec * np.clip(n_l[..., 0], 0.0, 1.0))[..., None]
    return diffuse, specular


def skin_colour(albedo: Array, diffuse: Array, specular: Array, rig: Rig) -> Array:
    """(..., 3) linear colour: skin.glsl's ``skin_finish``."""
    return albedo * (np.asarray(rig.ambient) + diffuse) + specular
