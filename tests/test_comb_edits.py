"""A comb stroke's dabs as undo commands (widgets/wdv/edits.py): one step per stroke, holding
the values before the stroke and after it, and no step for a stroke that changed nothing."""

from __future__ import annotations

import numpy as np

from studio.widgets.commands import new_gesture
from studio.widgets.document import Document
from studio.widgets.wdv.edits import comb_directions


def test_the_dabs_of_one_stroke_are_one_step_with_the_values_before_it(qtbot, sample):
    """Red once with the bug put back by hand: with ``mergeWith`` keeping the later dab's
    "before" where both dabs touched a vertex (``for cmd in (self, other)``), undo left vertex
    11 at the first dab's direction."""
    doc = Document(sample)
    area = doc.project.wdv.areas[0]
    before_d, before_l = area.directions.copy(), area.lengths.copy()
    stroke = new_gesture()
    x, y = np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    comb_directions(doc, area, np.array([10, 11]), np.stack([x, x]), np.array([0.5, 0.5]),
                    stroke)
    comb_directions(doc, area, np.array([11, 12]), np.stack([y, y]), np.array([0.5, 0.5]),
                    stroke)
    assert doc.undo_stack.count() == 1
    assert np.allclose(area.directions[[10, 11, 12]], [x, y, y])
    doc.undo_stack.undo()
    assert np.array_equal(area.directions, before_d)
    assert np.array_equal(area.lengths, before_l)
    doc.undo_stack.redo()
    assert np.allclose(area.directions[[10, 11, 12]], [x, y, y])
    assert np.allclose(area.lengths[[10, 11, 12]], 0.5)
    # another stroke is another step
    comb_directions(doc, area, np.array([10]), x[None] * -1, np.array([0.5]), new_gesture())
    assert doc.undo_stack.count() == 2


def test_a_stroke_combed_back_to_where_it_began_leaves_no_step(qtbot, sample):
    doc = Document(sample)
    area = doc.project.wdv.areas[0]
    vertex = np.array([int(np.flatnonzero(area.authored)[0])])
    old_d, old_l = area.directions[vertex].copy(), area.lengths[vertex].copy()
    stroke = new_gesture()
    comb_directions(doc, area, vertex, np.array([[0.0, 0, 1]]), old_l, stroke)
    assert doc.undo_stack.count() == 1
    comb_directions(doc, area, vertex, old_d, old_l, stroke)
    assert doc.undo_stack.count() == 0
    assert np.array_equal(area.directions[vertex], old_d)
    # a dab that changes nothing pushes nothing
    comb_directions(doc, area, vertex, old_d, old_l, new_gesture())
    assert doc.undo_stack.count() == 0
