"""Making the set-up fast did not change its look: the sample's synthesised wrinkled normal
maps and its masks, as the studio's first start makes them, equal the recorded ones within
1/255 on every texel (the recorded ones were made before the set-up's speed-up: issue 51).

A deliberate change to the synthesis updates the reference: run this file with Python
(``python -m tests.test_setup_maps_golden``), which rewrites ``setup_maps_golden.npz``, and
look at the sample before committing it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.core

REFERENCE_FILE = Path(__file__).with_name("setup_maps_golden.npz")
STEP = 1.0 / 255.0


def sample_maps() -> dict[str, np.ndarray]:
    """The ready sample's wrinkled maps (``map:NAME``, uint8) and masks (``mask:NAME``, in
    [0, 1] as uint16 steps: 1/255 is 257 of them), built afresh."""
    from studio.core.setup.sample_setup import ready_sample

    project = ready_sample()
    maps = {f"map:{name}": image for name, image in project.textures.wrinkle_maps.items()}
    for area in project.influence.areas:
        maps[f"mask:{area.name}"] = np.round(area.mask * 65535.0).astype(np.uint16)
    return maps


def test_the_sample_set_up_looks_as_it_did():
    with np.load(REFERENCE_FILE) as data:
        reference = {name: data[name] for name in data.files}
    maps = sample_maps()
    assert sorted(maps) == sorted(reference)
    for name, image in maps.items():
        scale = 255.0 if name.startswith("map:") else 65535.0
        expected = reference[name]
        assert image.shape == expected.shape and image.dtype == expected.dtype, name
        worst = np.abs(image.astype(np.float64) - expected) / scale
        assert worst.max() <= STEP + 1e-9, f"{name}: {worst.max() * 255:.2f}/255 off"


if __name__ == "__main__":
    np.savez_compressed(REFERENCE_FILE, **sample_maps())
    print(f"wrote {REFERENCE_FILE}")
