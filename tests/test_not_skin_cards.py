"""Eyebrow cards are not skin (studio/core/formats/gltf/materials.py ``see_through``,
face_parts.py): a VRoid-style avatar (tests/gltf_avatar.py) whose Head mesh has a second
primitive, eyebrow cards lying half a millimetre over the brows and moving with them in every
pose, so that a brow lowerer squeezes them as it squeezes the skin. Their material is alpha-cut
(glTF ``alphaMode`` MASK), blended (BLEND), or opaque by its mode with a texture that is mostly
clear (hair strokes on nothing). Either way they are marked not face, the report says why, and
no automatic mask reaches them: before, they got the brow lowerer's furrows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.formats.assemble import project_from_files
from studio.core.setup.auto_setup import suggest_setup
from tests.gltf_avatar import BROW_CARDS, brow_card, build_avatar, to_world
from tests.production_head import build_head

pytestmark = pytest.mark.core

WHY = {"MASK": "alpha-cut material", "BLEND": "blended material",
       "texture": "mostly transparent texture"}
MASK_SIZE = 256


def _card_vertices(project) -> np.ndarray:
    """(W,) bool: the project's welded vertices that are the cards' (found by position: the
    builder's cards, in the avatar's metres)."""
    head = build_head("m", vertices=2172, up="y")
    skin = head.parts[0]
    source, lift, _, _ = brow_card(skin, head.face_xy)
    cards = to_world(skin.rest[source] + lift)
    rest = project.mesh.rest.astype(np.float64)
    gaps = np.linalg.norm(rest[:, None, :] - cards[None, :, :], axis=2)
    return gaps.min(axis=1) < 1e-6


@pytest.mark.parametrize("mode", BROW_CARDS)
def test_brow_cards_are_not_face_and_get_no_mask(tmp_path: Path, mode: str):
    found: list[str] = []
    path = build_avatar(tmp_path / "avatar.glb", brows=mode)
    project = project_from_files(path, {}, None, None, None, report=found)
    cards = _card_vertices(project)
    assert cards.sum() > 20  # the cards are in the face mesh, with the brow poses on them
    assert (project.skin_weights()[cards] == 0).all(), found
    assert f"Head/FaceBrow ({WHY[mode]})" in "\n".join(found)
    # the skin under them is still skin
    assert project.skin_weights().sum() > 0.8 * (~cards).sum()
    # the brow lowerer's mask covers none of the cards' texels
    report = suggest_setup(project, poses=["browDownLeft"], mask_size=MASK_SIZE)
    (mask,) = [a.mask for a in report.influence_areas]
    card_tris = cards[project.mesh.welded_triangles].all(axis=1)
    centres = project.mesh.uvs[project.mesh.triangles[card_tris]].mean(axis=1)
    rows = np.clip(((1.0 - centres[:, 1]) * MASK_SIZE).astype(int), 0, MASK_SIZE - 1)
    cols = np.clip((centres[:, 0] * MASK_SIZE).astype(int), 0, MASK_SIZE - 1)
    assert mask.max() > 0.5  # it does squeeze the skin
    assert (mask[rows, cols] == 0.0).all()

