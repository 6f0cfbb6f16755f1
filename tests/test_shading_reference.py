"""The numpy reference of the fragment stage (studio/core/wrinkles/shading.py) against
hand-computed cases; tests/test_fragment_reference.py holds the real shader to it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.core.wrinkles.shading import (
    SHOWS_FULL,
    Fragment,
    Lighting,
    blended_weights,
    fragment_colour,
    heat_colour,
    light,
    linear_to_srgb,
    srgb_to_linear,
)

pytestmark = pytest.mark.core

FLAT_XY = (0.5, 0.5)  # x = y = 0: the normal straight out
TILT_XY = (192 / 255, 0.5)  # x = 0.5059: |tilted − flat| = 0.5242 (z 0.8626 against 1)
TILT_CHANGE = math.hypot(2 * 192 / 255 - 1, 1 - math.sqrt(1 - (2 * 192 / 255 - 1) ** 2))


def pixel(weights, wrinkled, skin: float = 1.0, neutral=FLAT_XY, albedo=(0.8, 0.6, 0.5)
          ) -> Fragment:
    """One pixel seen straight on (the tangent frame is view space's axes) from 3 units."""
    return Fragment(weights=np.array([*weights, 0, 0, 0, 0][:4], float), skin=np.array(skin),
                    neutral=np.array(neutral), wrinkled=np.array(wrinkled, float),
                    albedo=np.array(albedo), tbn=np.eye(3), view_pos=np.array([0, 0, -3.0]),
                    texcoord=np.array([0.3, 0.3]))


@pytest.mark.parametrize(("weights", "skin", "expected", "total"), [
    ((1.0, 1.0), 1.0, (0.5, 0.5), 1.0),  # a sum over 1 is scaled by 1 / W
    ((0.6, 0.2, 0.2), 1.0, (0.6, 0.2, 0.2), 1.0),  # exactly 1: unchanged
    ((0.3, 0.2), 0.5, (0.15, 0.1), 0.25),  # the skin scales before the sum
    ((1.0, 1.0), 0.0, (0.0, 0.0), 0.0),  # not-face: nothing
    ((0.9, 0.9, 0.6), 1.0, (0.375, 0.375, 0.25), 1.0),
])
def test_several_maps_weights_by_hand(weights, skin, expected, total):
    w, t = blended_weights(np.array(weights), np.array(skin))
    np.testing.assert_allclose(w, expected, atol=1e-12)
    assert t == pytest.approx(total)


def test_the_palette_by_hand():
    np.testing.assert_allclose(heat_colour(np.array([0.0, 0.5, 1.0])),
                               [[0, 0, 0.5], [0.5, 1, 0.5], [0.5, 0, 0]])


def test_the_light_by_hand():
    """The normal toward the key light (0, 0, 1) seen straight on: diffuse 1 plus a quarter of
    the fill (−0, 0.2, 0.6)/0.632 → 0.25 · 0.949; specular 0.12 (the half vector is the
    normal)."""
    got = light(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]),
                Lighting(light_dir=(0.0, 0.0, 2.0)))
    np.testing.assert_allclose(got, [1 + 0.25 * 0.6 / math.sqrt(0.4), 0.12], atol=1e-12)


def test_no_weight_is_the_neutral_shading_and_a_full_weight_the_wrinkled_one():
    side = Lighting(light_dir=(1.0, 0.0, 0.3))  # grazing: the tilt toward +x shows
    neutral = fragment_colour(pixel((0.0,), [FLAT_XY]), lighting=side)
    as_neutral = fragment_colour(pixel((0.0,), [TILT_XY]), lighting=side)
    tilted = fragment_colour(pixel((1.0,), [TILT_XY]), lighting=side)
    tilted_alone = fragment_colour(pixel((0.0,), [TILT_XY], neutral=TILT_XY), lighting=side)
    np.testing.assert_allclose(as_neutral, neutral)
    np.testing.assert_allclose(tilted, tilted_alone, atol=1e-12)
    assert np.abs(tilted - neutral).max() > 0.05


def test_half_a_weight_blends_shaded_colours_or_normals():
    """Colour blend: the average of the two lights received; normal blend: the light of the
    average normal — the same where the light is linear in the normal (no specular, the key
    and fill both lit)."""
    matte = Lighting(light_dir=(0.0, 0.3, 1.0), specular=0.0)
    half = pixel((0.5,), [TILT_XY])
    albedo = srgb_to_linear(np.array([0.8, 0.6, 0.5]))
    received = [light(np.array(n), np.array([0.0, 0.0, 1.0]), matte)[0] for n in (
        [0.0, 0.0, 1.0], [2 * 192 / 255 - 1, 0.0, math.sqrt(1 - (2 * 192 / 255 - 1) ** 2)])]
    by_hand = linear_to_srgb(albedo * (0.1 + (received[0] + received[1]) / 2))
    np.testing.assert_allclose(fragment_colour(half, lighting=matte), by_hand, atol=1e-12)
    normal = fragment_colour(half, blend="normal", lighting=matte)
    assert np.abs(normal - by_hand).max() < 0.02  # the normalised average is a little brighter


def test_the_heat_of_the_weight_against_the_heat_of_what_shows():
    """A full weight on a flat part of the map: the weight is hot, what shows is cold; on a
    tilt of 0.524 (over SHOWS_FULL) both are hot; half the weight there shows 0.655."""
    flat = pixel((1.0,), [FLAT_XY])
    tilt = pixel((1.0,), [TILT_XY])
    shaded = srgb_to_linear(fragment_colour(flat))

    def heat_view(t: float, under: np.ndarray) -> np.ndarray:
        return linear_to_srgb(srgb_to_linear(heat_colour(np.array(t))) * 0.65 + under * 0.105)

    np.testing.assert_allclose(fragment_colour(flat, view="heat"), heat_view(1.0, shaded))
    np.testing.assert_allclose(fragment_colour(flat, view="heat-shows"), heat_view(0.0, shaded))
    shaded_tilt = srgb_to_linear(fragment_colour(tilt))
    np.testing.assert_allclose(fragment_colour(tilt, view="heat-shows"),
                               heat_view(1.0, shaded_tilt))
    half = pixel((0.5,), [TILT_XY])
    t = 0.5 * TILT_CHANGE / SHOWS_FULL
    assert t == pytest.approx(0.655, abs=1e-3)
    np.testing.assert_allclose(fragment_colour(half, view="heat-shows"),
                               heat_view(t, srgb_to_linear(fragment_colour(half))))


def test_not_face_shows_neither_wrinkles_nor_heat():
    off = pixel((1.0, 1.0), [TILT_XY, TILT_XY], skin=0.0)
    np.testing.assert_allclose(fragment_colour(off), fragment_colour(pixel((0.0,), [FLAT_XY])))
    np.testing.assert_allclose(fragment_colour(off, view="heat"),
                               fragment_colour(pixel((0.0,), [FLAT_XY]), view="heat"))


def test_the_normals_view_by_hand():
    np.testing.assert_allclose(fragment_colour(pixel((0.0,), [FLAT_XY]), view="normals"),
                               [0.5, 0.5, 1.0], atol=1e-12)
