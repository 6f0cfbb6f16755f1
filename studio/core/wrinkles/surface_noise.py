"""Smooth, band-limited noise on the face's surface: what makes no two furrows alike.

A sum of plane waves in 3-D (random directions, wavelengths about one ``wavelength``, random
phases), evaluated at points of the surface — so it is continuous across UV charts and seams,
the same on a mirrored island as on its twin's surface, and independent of mesh density. A
fixed seed: the same head gives the same map. Values are about normally distributed with
mean 0 and unit variance.
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray

WAVES = 24  # enough plane waves that their sum looks like noise, not a lattice
SEED = 20100  # the thesis's year, and a fixed map for a fixed head


def surface_noise(points: Array, wavelength: float, channel: int = 0) -> Array:
    """(..., ) noise at ``points`` (..., 3), varying over about ``wavelength`` (model units);
    ``channel`` picks an independent field."""
    rng = np.random.default_rng(SEED + 7919 * channel)
    direction = rng.normal(size=(WAVES, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    # wavelengths spread over an octave around the asked one: no single period shows
    k = 2.0 * np.pi / (wavelength * rng.uniform(0.7, 1.4, WAVES))
    phase = rng.uniform(0.0, 2.0 * np.pi, WAVES)
    p = np.asarray(points, np.float64)
    flat = p.reshape(-1, 3)
    values = np.cos(flat @ (direction * k[:, None]).T + phase).sum(axis=1)
    return (values * np.sqrt(2.0 / WAVES)).astype(np.float32).reshape(p.shape[:-1])
