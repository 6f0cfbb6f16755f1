"""A synthesised map's record draws it again (issue 45, point 6): a map recorded as the Synthesise
dialog records it (the strain alone, over the neutral map's detail or not) is, with the controls
at their defaults, the very map the synthesis makes for its pose, and follows the controls from
there; the record is saved and read back whole, and a file without ``over_neutral`` reads as
over the neutral (every map recorded before the dialog's were)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.sample.synthetic import make_test_face
from studio.core.setup.furrow_maps import FurrowMaps
from studio.core.setup.wrinkle_synth import SynthOptions, synthesise_wrinkle_map
from studio.core.wrinkles.furrow_controls import FurrowControls, SynthesisedMap

pytestmark = pytest.mark.core

POSE = "surprise"
OPTIONS = SynthOptions(size=128, spacing=6.0, depth=2.0)


@pytest.fixture(scope="module")
def face():
    """The small test face with a neutral normal map of its own detail (pores, say)."""
    project = make_test_face(561, texture_size=128, mask_size=32)
    rng = np.random.default_rng(5)
    neutral = np.full((128, 128, 3), (128, 128, 255), np.uint8)
    neutral[..., :2] = rng.integers(118, 139, (128, 128, 2))
    project.textures.normal_neutral = neutral
    return project


@pytest.mark.parametrize("over_neutral", [True, False])
def test_a_dialog_record_draws_the_map_the_synthesis_made(face, over_neutral):
    record = SynthesisedMap((POSE,), OPTIONS.spacing, OPTIONS.depth, anatomy=False,
                            over_neutral=over_neutral)
    drawn = FurrowMaps().draw(face, record, face.furrows, OPTIONS.size)
    made = synthesise_wrinkle_map(face, [POSE], OPTIONS, over_neutral=over_neutral).normal
    assert np.array_equal(drawn, made)
    deeper = FurrowMaps().draw(face, record, face.furrows.with_controls(
        POSE, FurrowControls(depth=2.0)), OPTIONS.size)
    assert not np.array_equal(deeper, made)
    untouched = (made == made[0, 0]).all(axis=-1) if not over_neutral else \
        (made == face.textures.normal_neutral).all(axis=-1)
    assert untouched.mean() > 0.3  # away from the furrows: flat, or the neutral's own detail


def test_a_record_round_trips_and_an_older_one_lies_over_the_neutral():
    record = SynthesisedMap((POSE, "frown"), 6.0, 2.0, anatomy=False, digest="ab",
                            over_neutral=False)
    assert SynthesisedMap.from_dict(record.to_dict()) == record
    older = {k: v for k, v in record.to_dict().items() if k != "over_neutral"}
    assert SynthesisedMap.from_dict(older).over_neutral
    with pytest.raises(ValueError, match="over_neutral"):
        SynthesisedMap.from_dict({**record.to_dict(), "over_neutral": "no"})
