"""``mask_ops.blur`` blurs a mask over the box its non-zero pixels reach only (issue 51: the
set-up and the synthesis blur hundreds of pose masks that each cover a small part of the
map). The result must equal, bit for bit, the three box passes per axis over the whole image,
wherever the mask lies: in the middle, against an edge, near a corner, nowhere, everywhere."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles import mask_ops

pytestmark = pytest.mark.core


def _whole(mask: np.ndarray, radius: float) -> np.ndarray:
    """Three box passes along the rows then three down the columns, over every pixel."""
    r = max(round(radius / 2.0), 0)
    out = mask.astype(np.float32)
    for axis in (1, 1, 1, 0, 0, 0):
        out = mask_ops._box(out, r, axis)
    return np.clip(out, 0.0, 1.0)


def _mask(where: str, shape: tuple[int, int] = (512, 384)) -> np.ndarray:
    """A soft blob (values in [0, 1], uneven) at ``where`` on a zero mask."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    centre = {"middle": (0.45 * h, 0.55 * w), "left edge": (0.3 * h, 0.0),
              "near a corner": (h - 40.0, w - 35.0), "everywhere": (0.5 * h, 0.5 * w)}[where]
    spread = 4000.0 if where == "everywhere" else 300.0
    blob = np.exp(-((y - centre[0]) ** 2 + (x - centre[1]) ** 2) / spread)
    blob *= 0.8 + 0.2 * np.sin(0.37 * x) * np.cos(0.23 * y)
    return np.where(blob > 0.05, blob, 0.0).astype(np.float32) if where != "everywhere" \
        else blob.astype(np.float32)


@pytest.mark.parametrize("where", ["middle", "left edge", "near a corner", "everywhere"])
@pytest.mark.parametrize("radius", [2.0, 9.0, 30.0])
def test_a_blur_over_the_mask_s_reach_equals_the_blur_over_the_whole_image(where, radius):
    mask = _mask(where)
    blurred = mask_ops.blur(mask, radius)
    np.testing.assert_array_equal(blurred, _whole(mask, radius))
    if where != "everywhere":
        assert (blurred > 0).sum() > (mask > 0).sum()  # it spread


def test_an_empty_mask_stays_empty():
    assert not mask_ops.blur(np.zeros((64, 48), np.float32), 12.0).any()
