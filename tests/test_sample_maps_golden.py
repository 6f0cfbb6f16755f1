"""The sample face's painted maps do not change unnoticed, down to their small features.

``test_sample_fingerprint`` holds the whole sample at a quick 64-texel size, where the lips'
line, the pupils, the lashes and the thin wrinkles are narrower than a texel and vanish: a
changed colour or curve there would pass it. This test paints every map of ``sample_maps`` at
256 texels and compares the mean of each 16 × 16 block (so every feature lands in some block)
with the recorded reference, within 2e-4 of the map's peak: far above float32 rounding across
machines, far below any visible change. A deliberate change to the sample's painting updates
the reference: run this file with Python (``python -m tests.test_sample_maps_golden``), which
rewrites ``sample_maps_golden.npz``, and look at the sample before committing it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.sample.maps import (
    Texels,
    bake_normal_maps,
    paint_diffuse,
    paint_masks,
    pore_height,
    wrinkle_height,
)

pytestmark = pytest.mark.core

SIZE = 256
BLOCKS = 16  # per side: blocks of 16 × 16 texels
TOLERANCE = 2e-4  # of each map's peak
REFERENCE_FILE = Path(__file__).with_name("sample_maps_golden.npz")


def block_means(image: np.ndarray) -> np.ndarray:
    """(BLOCKS, BLOCKS, channels) means of an (n, n[, channels]) map."""
    data = np.asarray(image, dtype=np.float64)
    data = data.reshape(data.shape[0], data.shape[1], -1)
    n = data.shape[0] // BLOCKS
    return data.reshape(BLOCKS, n, BLOCKS, n, -1).mean(axis=(1, 3))


def painted_maps() -> dict[str, np.ndarray]:
    """Every map the sample is painted from, by name, as block means."""
    texels = Texels.of(SIZE)
    neutral, wrinkled = bake_normal_maps(texels)
    maps = {
        "texels.x": texels.x,
        "texels.y": texels.y,
        "texels.front": texels.front,
        "diffuse": paint_diffuse(texels),
        "normal.neutral": neutral,
        "pores": pore_height(SIZE),
        "height.all": wrinkle_height(texels),
    }
    maps.update({f"normal.{name}": image for name, image in wrinkled.items()})
    maps.update({f"height.{name}": wrinkle_height(texels, name) for name in wrinkled})
    maps.update({f"mask.{name}": mask for name, mask in paint_masks(texels).items()})
    found = {name: block_means(image) for name, image in maps.items()}
    found["texels.theta"] = texels.theta.astype(np.float64)
    found["texels.texel_size"] = np.array(
        [texels.texel_size(0.0, 0.3), texels.texel_size(0.4, -0.2)], dtype=np.float64
    )
    return found


@pytest.fixture(scope="module")
def found() -> dict[str, np.ndarray]:
    return painted_maps()


def test_the_same_maps_are_painted(found: dict[str, np.ndarray]) -> None:
    with np.load(REFERENCE_FILE) as reference:
        assert sorted(found) == sorted(reference.files)


@pytest.mark.parametrize(
    "name",
    sorted(np.load(REFERENCE_FILE).files) if REFERENCE_FILE.exists() else [],
)
def test_each_map_matches_the_reference(found: dict[str, np.ndarray], name: str) -> None:
    with np.load(REFERENCE_FILE) as reference:
        expected = reference[name]
    assert found[name].shape == expected.shape
    peak = max(float(np.abs(expected).max()), 1e-12)
    worst = float(np.abs(found[name] - expected).max())
    assert worst <= TOLERANCE * peak, f"{name}: off by {worst:.3g} (peak {peak:.3g})"


if __name__ == "__main__":
    np.savez_compressed(REFERENCE_FILE, **painted_maps())
