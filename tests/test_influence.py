"""Technique 1's activation vector (SPEC §4) follows every edit of the areas and links, although
what it derives from them is built once per change rather than walked every frame."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup


def _plain(influence: InfluenceSetup, weights: dict[str, float]) -> np.ndarray:
    """The activations written the obvious way: a walk over every link."""
    values = np.array([a.activation for a in influence.areas], np.float64)
    index = {a.name: i for i, a in enumerate(influence.areas)}
    for pose, weight in weights.items():
        for area, gain in influence.links.get(pose, {}).items():
            if area in index:
                values[index[area]] += gain * weight
    values[np.array([not a.visible for a in influence.areas], bool)] = 0.0
    return np.clip(values, 0.0, 1.0)


WEIGHTS = {"surprise": 0.8, "squeeze": 0.3, "frown": 1.0, "brow_raise_left": 0.4}


@pytest.mark.core
def test_activations_follow_changes_made_straight_to_the_data(sample):
    influence = sample.influence
    names = [a.name for a in influence.areas]
    names_mask = influence.areas[0].mask
    edits = [
        lambda: influence.links["squeeze"].update({names[0]: 0.2}),  # a gain added in place
        lambda: influence.links["surprise"].pop(names[0]),  # and one removed in place
        lambda: influence.links.update({"frown": {names[-1]: 0.5}}),  # a pose's gains replaced
        lambda: setattr(influence, "links", {"surprise": {names[2]: 0.9}}),  # all links replaced
        lambda: influence.areas.append(InfluenceArea("extra", names_mask, activation=0.4)),
        lambda: setattr(influence.areas[2], "activation", 0.35),
        lambda: setattr(influence.areas[2], "visible", False),
        lambda: setattr(influence.areas[3], "name", names[2]),  # the last of a name is linked
        lambda: influence.areas.reverse(),
        lambda: influence.areas.pop(0),
    ]
    previous = influence.activations(WEIGHTS)
    np.testing.assert_allclose(previous, _plain(influence, WEIGHTS), atol=1e-6)
    for i, edit in enumerate(edits):
        edit()
        now = influence.activations(WEIGHTS)
        np.testing.assert_allclose(now, _plain(influence, WEIGHTS), atol=1e-6, err_msg=f"edit {i}")
        assert now.shape != previous.shape or not np.array_equal(now, previous), f"edit {i}"
        previous = now


def test_activations_follow_the_studios_area_and_link_edits_and_their_undo(qtbot, sample):
    from studio.widgets.document import Document
    from studio.widgets.paint.edits import (
        add_area,
        delete_area,
        duplicate_area,
        move_area,
        rename_area,
        set_area_visible,
        set_link,
    )

    doc = Document(sample)
    for pose, weight in WEIGHTS.items():
        doc.set_pose_weight(pose, weight)
    names = [a.name for a in doc.project.influence.areas]

    def index(name: str) -> int:
        return [a.name for a in doc.project.influence.areas].index(name)

    def activations() -> np.ndarray:
        values = doc.activations()
        np.testing.assert_allclose(values, _plain(doc.project.influence, doc.pose_weights),
                                   atol=1e-6)
        return values

    edits = [
        lambda: set_link(doc, "surprise", names[7], 0.5),  # a new link
        lambda: set_link(doc, "surprise", names[0], 0.25),  # a gain changed
        lambda: set_link(doc, "squeeze", names[7], 0.0),  # a link removed
        lambda: rename_area(doc, 0, "brow R"),  # links follow the name: nothing changes
        lambda: move_area(doc, 0, 3),
        lambda: add_area(doc, "new", links={"frown": 0.7}),
        lambda: duplicate_area(doc, 2),
        lambda: delete_area(doc, 1),
        lambda: set_area_visible(doc, index("new"), False),
        lambda: doc.set_area_activation(index(names[3]), 0.6),
    ]
    history = [activations()]
    for edit in edits:
        edit()
        history.append(activations())
    changed = [a.shape != b.shape or not np.array_equal(a, b)
               for a, b in itertools.pairwise(history)]
    assert changed == [True, True, True, False, True, True, True, True, True, True]
    steps = doc.undo_stack.count()
    doc.set_pose_weight("surprise", 0.1)  # a view of the face: the activations follow it,
    assert not np.array_equal(activations(), history[-1])  # but it is no step to undo
    assert doc.undo_stack.count() == steps
    doc.set_pose_weight("surprise", WEIGHTS["surprise"])
    for expected in reversed(history[:-1]):
        doc.undo_stack.undo()
        np.testing.assert_array_equal(activations(), expected)
    for expected in history[1:]:
        doc.undo_stack.redo()
        np.testing.assert_array_equal(activations(), expected)
    doc.undo_stack.clear()  # now: a stack destroyed after its document signals a deleted one
