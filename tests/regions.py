"""Named regions of rendered images: the sample's landmarks projected to pixels."""

from __future__ import annotations

import numpy as np

from studio.core.mesh.camera import OrbitCamera
from studio.core.project.model import Project
from studio.core.sample.synthetic import sample_landmarks


def landmark_pixels(project: Project, camera: OrbitCamera, width: int, height: int
                    ) -> dict[str, tuple[int, int]]:
    marks = sample_landmarks(project)
    names = list(marks)
    px, _ = camera.project(np.array([marks[n] for n in names]), width, height)
    return {n: (int(np.rint(x)), int(np.rint(y))) for n, (x, y) in zip(names, px, strict=True)}


def patch(image: np.ndarray, centre: tuple[int, int], radius: int) -> np.ndarray:
    x, y = centre
    return image[max(y - radius, 0):y + radius + 1, max(x - radius, 0):x + radius + 1]


def region_difference(a: np.ndarray, b: np.ndarray, centre: tuple[int, int],
                      radius: int = 12) -> float:
    """How much two images differ around a pixel: the 90th percentile of the per-pixel
    difference (0–255, largest channel). Wrinkles are thin lines, so a mean would dilute them;
    this is 0 when at most a tenth of the region changed at all."""
    pa = patch(a, centre, radius).astype(np.int16)
    pb = patch(b, centre, radius).astype(np.int16)
    return float(np.percentile(np.abs(pa - pb).max(axis=-1), 90))
