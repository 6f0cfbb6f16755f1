"""The numpy reference of the face's fragment stage (shaders/face.frag with common.glsl's light).

The shader is the part of the studio that core's mutation testing never reaches, so its
formulas are written again here, per pixel and vectorised, and ``tests/test_fragment_reference``
holds rendered pixels of small hand-built faces to them. Per pixel:

- the wrinkle weights (one per wrinkled map) times the skin (0 on not-face), scaled by 1 / W
  where their sum W exceeds 1 (README "Several wrinkled maps": a weighted average, the same in
  any order);
- the neutral and wrinkled tangent-space normals (x, y from the maps, z rebuilt), turned into
  view space by the tangent frame;
- blend "colour" (the thesis): (1 − W) · light(neutral) + Σ w_m · light(wrinkled_m), then
  albedo · (ambient + diffuse) + specular; blend "normal": the same average of the normals,
  lit once; the skin look (a ``Rig`` given) receives and finishes the light by skin_light.py
  (shaders/skin.glsl) instead;
- the debug views: "heat" the weight W, "heat-shows" what the weights reveal,
  clamp(Σ w_m · |wrinkled_m − neutral| / SHOWS_FULL, 0, 1), both in the shader's palette over a
  dimmed shading; "normals" the blended normal; "uv" a checker of the texture coordinates.

Colours are linear inside and sRGB (gamma 2.2, as the shader) out, in [0, 1].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.wrinkles.skin_light import Rig, skin_colour, skin_received
from studio.core.wrinkles.skin_tone import blended_tone

Array = np.ndarray

# |wrinkled − neutral| of unit tangent-space normals at which the "what shows" heat view is hot:
# a normal tilted by about 23°, the wall of a typical furrow (the synthesised maps' walls measure
# 0.45 at their 99th percentile). shaders/face.frag holds the same number.
SHOWS_FULL = 0.4
HEAT_VIEWS = ("heat", "heat-shows")


@dataclass(frozen=True)
class Lighting:
    """common.glsl's uniforms: view-space direction toward the key light, the ambient term,
    specular strength and Blinn-Phong exponent."""

    light_dir: tuple[float, float, float] = (0.45, 0.5, 0.75)
    ambient: float = 0.1
    specular: float = 0.12
    shininess: float = 20.0


def _unit(v: Array) -> Array:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def unpack_normal(xy: Array, dtype: type = np.float64) -> Array:
    """(..., 3) tangent-space unit normals from a map's x and y stored in [0, 1] (face.frag's
    ``unpack_normal``: z rebuilt, 0 where x² + y² > 1)."""
    n = np.asarray(xy, dtype) * dtype(2.0) - dtype(1.0)
    z = np.sqrt(np.maximum(dtype(1.0) - (n * n).sum(axis=-1), dtype(0.0)))
    return np.concatenate([n, z[..., None]], axis=-1)


def map_xy(image: Array, dtype: type = np.float64) -> Array:
    """A normal map's x and y channels as the GPU samples them: 8- or 16-bit to [0, 1]."""
    image = np.asarray(image)
    top = 65535.0 if image.dtype == np.uint16 else 255.0
    return image[..., :2].astype(dtype) / dtype(top)


def reveal_difference(neutral: Array, wrinkled: Array, dtype: type = np.float64) -> Array:
    """(H, W) |wrinkled − neutral| per texel of two tangent-space normal maps of one size:
    what a full weight changes there (0: the wrinkled map is flat where it equals the neutral).
    ``dtype`` float32 halves the time on large maps (flat_reveal.py), to within 1e-6."""
    change = (unpack_normal(map_xy(wrinkled, dtype), dtype)
              - unpack_normal(map_xy(neutral, dtype), dtype))
    return np.sqrt((change * change).sum(axis=-1)).astype(np.float32)


def srgb_to_linear(c: Array) -> Array:
    return np.power(c, 2.2)


def linear_to_srgb(c: Array) -> Array:
    return np.power(np.clip(c, 0.0, 1.0), 1.0 / 2.2)


def light(n: Array, view_dir: Array, lighting: Lighting) -> Array:
    """(..., 2) diffuse (key plus a quarter of the fill) and specular a normal receives."""
    key_dir = _unit(np.asarray(lighting.light_dir, np.float64))
    fill = _unit(np.array([-key_dir[0], 0.2, 0.6]))
    key = np.maximum(n @ key_dir, 0.0)
    back = np.maximum(n @ fill, 0.0) * 0.25
    h = _unit(key_dir + view_dir)
    spec = np.where(key > 0.0, np.power(np.maximum((n * h).sum(axis=-1), 0.0),
                                        lighting.shininess) * lighting.specular, 0.0)
    return np.stack([key + back, spec], axis=-1)


def heat_colour(t: Array) -> Array:
    """The heat views' palette, sRGB: blue at 0, green at 0.5, red at 1."""
    t = np.asarray(t, np.float64)[..., None]
    centre = np.array([3.0, 2.0, 1.0])
    return np.clip(1.5 - np.abs(4.0 * t - centre), 0.0, 1.0)


def blended_weights(weights: Array, skin: Array) -> tuple[Array, Array]:
    """(w, W): the per-map weights times the skin, scaled by 1 / W where their sum W > 1, and
    that sum (at most 1)."""
    w = np.asarray(weights, np.float64) * np.asarray(skin, np.float64)[..., None]
    total = w.sum(axis=-1)
    over = total > 1.0
    w = np.where(over[..., None], w / np.where(over, total, 1.0)[..., None], w)
    return w, np.minimum(total, 1.0)


@dataclass(frozen=True)
class Fragment:
    """One batch of pixels' inputs (any leading shape ``...``): what the vertex stage and the
    textures give face.frag.

    ``weights`` (..., 4) the technique's per-map weights (before the skin); ``skin`` (...) the
    interpolated not-face factor; ``neutral`` (..., 2) and ``wrinkled`` (..., M, 2) the maps'
    x, y in [0, 1]; ``albedo`` (..., 3) the diffuse map in sRGB [0, 1]; ``tbn`` (..., 3, 3)
    columns tangent, bitangent, normal in view space (unit); ``view_pos`` (..., 3); ``texcoord``
    (..., 2) for the UV checker; ``tone`` (..., M, 4) each map's colour (rgb) and cavity (a)
    texels in [0, 1], or None for a face without them (skin_tone.py)."""

    weights: Array
    skin: Array
    neutral: Array
    wrinkled: Array
    albedo: Array
    tbn: Array
    view_pos: Array
    texcoord: Array
    tone: Array | None = None


def _received(n: Array, view_dir: Array, lighting: Lighting, rig: Rig | None
              ) -> tuple[Array, Array]:
    """((..., 3) diffuse, (..., 3) specular) on unit normals: face.frag's ``add_light``."""
    if rig is not None:
        return skin_received(n, view_dir, rig)
    r = light(n, view_dir, lighting)
    return np.repeat(r[..., :1], 3, axis=-1), np.repeat(r[..., 1:], 3, axis=-1)


def fragment_colour(f: Fragment, *, blend: str = "colour", view: str = "shaded",
                    lighting: Lighting = Lighting(), rig: Rig | None = None) -> Array:
    """(..., 3) the sRGB colour face.frag writes, in [0, 1] (a wrinkle technique without
    relief: technique 1, 2 or automatic; technique "none" is all weights 0); ``rig``: the
    skin look under that rig, None for clay."""
    if blend not in ("colour", "normal"):
        raise ValueError(f"unknown blend '{blend}'")
    maps = f.wrinkled.shape[-2]
    w, total = blended_weights(np.asarray(f.weights)[..., :maps], f.skin)
    tbn = np.asarray(f.tbn, np.float64)
    view_dir = _unit(-np.asarray(f.view_pos, np.float64))
    t_neutral = unpack_normal(f.neutral)
    t_wrinkled = unpack_normal(f.wrinkled)  # (..., M, 3)
    n_neutral = _unit(np.einsum("...ij,...j->...i", tbn, t_neutral))
    n_wrinkled = _unit(np.einsum("...ij,...mj->...mi", tbn, t_wrinkled))
    n = _unit(n_neutral * (1.0 - total)[..., None] + (w[..., None] * n_wrinkled).sum(axis=-2))
    albedo = srgb_to_linear(np.asarray(f.albedo, np.float64))
    if blend == "normal":
        diffuse, specular = _received(n, view_dir, lighting, rig)
    else:
        pairs = [_received(n_neutral, view_dir, lighting, rig),
                 _received(n_wrinkled, view_dir[..., None, :], lighting, rig)]
        diffuse, specular = (pairs[0][k] * (1.0 - total)[..., None]
                             + (w[..., None] * pairs[1][k]).sum(axis=-2) for k in (0, 1))
    if rig is not None and f.tone is not None:  # the skin look's tone (clay has none)
        tone = np.asarray(f.tone, np.float64)
        tint, kept = blended_tone(w, total, tone[..., :3], tone[..., 3])
        colour = skin_colour(albedo * tint, diffuse, specular, rig) * kept[..., None]
    elif rig is not None:
        colour = skin_colour(albedo, diffuse, specular, rig)
    else:
        colour = albedo * (lighting.ambient + diffuse) + specular
    if view in HEAT_VIEWS:
        if view == "heat":
            t = total
        else:
            change = np.linalg.norm(t_wrinkled - t_neutral[..., None, :], axis=-1)
            t = np.clip((w * change).sum(axis=-1) / SHOWS_FULL, 0.0, 1.0)
        colour = srgb_to_linear(heat_colour(t)) * 0.65 + colour * 0.3 * 0.35
    elif view == "normals":
        colour = srgb_to_linear(n * 0.5 + 0.5)
    elif view == "uv":
        cell = np.floor(np.asarray(f.texcoord, np.float64) * 16.0)
        check = np.mod(cell[..., 0] + cell[..., 1], 2.0)[..., None]
        base = (1.0 - check) * 0.9 + check * np.array([0.25, 0.45, 0.85])
        key_dir = _unit(np.asarray(lighting.light_dir, np.float64))
        colour = srgb_to_linear(base) * (0.3 + np.maximum(tbn[..., :, 2] @ key_dir, 0.0)
                                         )[..., None]
    elif view != "shaded":
        raise ValueError(f"unknown view '{view}'")
    return linear_to_srgb(colour)
