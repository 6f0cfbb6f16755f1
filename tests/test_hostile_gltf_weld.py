"""Welding a glTF face's vertices in bounded memory (issue #39): rows of position and every
morph offset hashed instead of sorted as records, with exactly ``np.unique``'s answer (the
vertices that agree in all of them, numbered by first appearance), collisions included."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.formats.gltf import face as gltf_face

pytestmark = pytest.mark.core


def rows(seed: int) -> list[np.ndarray]:
    """Positions and three offsets of 300 vertices, a third of them repeated, some differing
    from a repeat in one offset only, and zeros of both signs."""
    rng = np.random.default_rng(seed)
    blocks = [rng.integers(-2, 3, (100, 3)).astype(np.float32).astype(np.float64) * 0.25
              for _ in range(4)]
    blocks = [np.concatenate([b, b, b]) for b in blocks]
    blocks[2][200:210, 1] += 0.5  # the same position, another offset: not welded
    blocks[0][250:260] *= -1.0  # -0.0 where there was 0.0: welded, as np.unique does
    return blocks


def exact(blocks: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    _, first, inverse = np.unique(np.concatenate(blocks, axis=1), axis=0, return_index=True,
                                  return_inverse=True)
    return first, inverse.reshape(-1)


def same_welding(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> None:
    """The same vertices welded, the same first vertex kept for each."""
    np.testing.assert_array_equal(a[0][a[1]], b[0][b[1]])


@pytest.mark.parametrize("seed", range(5))
def test_hashed_welding_is_exact(seed: int) -> None:
    blocks = rows(seed)
    same_welding(gltf_face._weld(blocks), exact(blocks))


def test_colliding_hashes_fall_back_to_the_exact_welding(monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    """A prime of 0 hashes every row alike: the check finds rows that differ and the exact
    welding is used."""
    monkeypatch.setattr(gltf_face, "_HASH_PRIME", np.uint64(0))
    blocks = rows(7)
    same_welding(gltf_face._weld(blocks), exact(blocks))
