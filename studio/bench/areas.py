"""Influence areas for the benchmark: the sample's own eight, then soft blobs spread over the
face, each linked to a key pose so activations change every frame as in a real animation."""

from __future__ import annotations

import numpy as np

from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup


def blob_mask(size: int, centre: tuple[float, float], radius: float) -> np.ndarray:
    y, x = np.mgrid[0:size, 0:size].astype(np.float32)
    d = np.hypot((x + 0.5) / size - centre[0], (y + 0.5) / size - centre[1]) / radius
    return np.clip(1.0 - d, 0.0, 1.0) ** 2


def benchmark_areas(preset: InfluenceSetup, count: int, poses: list[str],
                    seed: int = 7) -> InfluenceSetup:
    """``count`` areas: the preset's first, then blobs over the face region of the UV square."""
    areas = [InfluenceArea(a.name, a.mask, a.colour) for a in preset.areas[:count]]
    links = {p: {a: g for a, g in d.items() if a in {x.name for x in areas}}
             for p, d in preset.links.items()}
    size = preset.areas[0].mask.shape[0]
    rng = np.random.default_rng(seed)
    for i in range(len(areas), count):
        centre = (float(rng.uniform(0.25, 0.75)), float(rng.uniform(0.2, 0.75)))
        name = f"blob {i}"
        areas.append(InfluenceArea(name, blob_mask(size, centre, float(rng.uniform(0.04, 0.1)))))
        links.setdefault(poses[i % len(poses)], {})[name] = 1.0
    return InfluenceSetup(areas, links)
