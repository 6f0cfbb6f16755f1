"""Blending key poses (SPEC §3): ``P = P_neutral + Σ_k w_k (P_k − P_neutral)``."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.poses import NEUTRAL, PoseBlender

pytestmark = pytest.mark.core


def _plain_blend(project, weights: dict[str, float]) -> np.ndarray:
    """The formula written the obvious way, in float64."""
    rest = project.mesh.rest.astype(np.float64)
    return rest + sum((w * (project.pose(name).positions - rest) for name, w in weights.items()),
                      np.zeros_like(rest))


@pytest.mark.parametrize("active", [0, 1, 2, 3, 4, 5])
def test_blend_follows_the_formula_however_many_poses_move(sample, active):
    """Few moving poses are added one by one, many in one product: both give the formula."""
    names = [p.name for p in sample.poses]
    assert len(names) >= active
    rng = np.random.default_rng(active)
    weights = {name: float(rng.uniform(-0.5, 1.5)) for name in names[:active]}
    blender = PoseBlender(sample.mesh.rest, sample.poses)
    blender.blend({name: 1.0 for name in names})  # a previous frame must leave no trace
    out = blender.blend({**weights, **{name: 0.0 for name in names[active:]}})
    assert out.dtype == np.float32 and out.shape == sample.mesh.rest.shape
    np.testing.assert_allclose(out, _plain_blend(sample, weights), atol=2e-6)


def test_blend_ignores_the_neutral_pose_and_refuses_unknown_ones(sample):
    blender = PoseBlender(sample.mesh.rest, sample.poses)
    np.testing.assert_array_equal(blender.blend({NEUTRAL: 1.0}), sample.mesh.rest)
    with pytest.raises(KeyError, match="no such pose"):
        blender.blend({"no such pose": 1.0})
