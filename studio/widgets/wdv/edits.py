"""Undo commands for technique-2 authoring: areas, the vertex selection and the vectors.

Each command stores only what it changes (the touched vertex indices and their old and new
values, or references to the area objects), so a long authoring session stays small in memory.
The functions at the bottom are what the panel and the viewport tool call.
"""

from __future__ import annotations

from collections.abc import Hashable

import numpy as np
from PySide6.QtGui import QUndoCommand

from studio.core.files.naming import unique_name
from studio.core.wrinkles.colours import distinct_colour
from studio.core.wrinkles.wdv import WdvArea, wrinkle_directions
from studio.widgets.commands import ValueCommand, push_flags
from studio.widgets.document import Document

_SELECTION_ID = 4101
_VECTORS_ID = 4102


class SelectionCommand(QUndoCommand):
    """Changes the selected vertices; a brush stroke (one gesture) merges into one step."""

    def __init__(self, doc: Document, new: np.ndarray, text: str = "Select",
                 gesture: Hashable | None = None) -> None:
        super().__init__(text)
        self.doc = doc
        old = doc.selection
        self.index = np.flatnonzero(old != new)
        self.after = new[self.index].copy()
        self.gesture = gesture
        self.setObsolete(len(self.index) == 0)  # a dab that changed nothing leaves no step

    def redo(self) -> None:
        self.doc.selection[self.index] = self.after
        self.doc.selectionChanged.emit()

    def undo(self) -> None:
        self.doc.selection[self.index] = ~self.after  # only flipped vertices are stored
        self.doc.selectionChanged.emit()

    def id(self) -> int:
        return _SELECTION_ID if self.gesture is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, SelectionCommand) or other.gesture != self.gesture:
            return False
        # the state before self, and the state after other, over the union of touched vertices
        index = np.union1d(self.index, other.index)
        after = self.doc.selection[index].copy()
        before = after.copy()
        for cmd in (other, self):  # undo in reverse order, on the copy
            pos = np.searchsorted(index, cmd.index)
            before[pos] = ~cmd.after
        keep = before != after
        self.index, self.after = index[keep], after[keep]
        self.setObsolete(len(self.index) == 0)  # painted and erased back: no step
        return True


class AreaListCommand(QUndoCommand):
    """Replaces the list of areas (add, delete, reorder): it keeps references to the area
    objects, never copies of their vectors. The current area is part of the step: undo gives
    back the one chosen before, redo the one chosen after (``current``: the area to choose;
    by default the current one, if it stays in the list)."""

    def __init__(self, doc: Document, areas: list[WdvArea], text: str,
                 current: WdvArea | None = None) -> None:
        super().__init__(text)
        self.doc = doc
        self.old = list(doc.project.wdv.areas)
        self.new = list(areas)
        self.old_current = doc.current_wdv_area
        self.new_current = current if current is not None else self.old_current

    def _apply(self, areas: list[WdvArea], current: WdvArea | None) -> None:
        self.doc.project.wdv.areas[:] = areas
        self.doc.set_current_wdv_area(current if any(a is current for a in areas) else None)
        self.doc.wdvChanged.emit()

    def redo(self) -> None:
        self._apply(self.new, self.new_current)

    def undo(self) -> None:
        self._apply(self.old, self.old_current)


class VectorsCommand(QUndoCommand):
    """Sets an area's directions and lengths; stores only the vertices whose values change.

    ``index`` given: ``directions`` and ``lengths`` are the new values of those vertices only
    (a comb dab touches a few dozen of thousands, and must not compare the whole face per mouse
    move). A comb stroke (one ``gesture``) merges into one undo step over every vertex it
    touched."""

    def __init__(self, doc: Document, area: WdvArea, directions: np.ndarray,
                 lengths: np.ndarray, text: str, gesture: Hashable | None = None,
                 index: np.ndarray | None = None) -> None:
        super().__init__(text)
        self.doc = doc
        self.area = area
        self.gesture = gesture
        if index is not None:
            index = np.asarray(index, np.int64)
            directions = np.asarray(directions, np.float32).reshape(-1, 3)
            lengths = np.asarray(lengths, np.float32).reshape(-1)
            changed = (np.any(area.directions[index] != directions, axis=1)
                       | (area.lengths[index] != lengths))
            self.index = index[changed]
            self.new = (directions[changed].copy(), lengths[changed].copy())
        else:
            changed = (np.any(area.directions != directions, axis=1) | (area.lengths != lengths))
            self.index = np.flatnonzero(changed)
            self.new = (directions[self.index].astype(np.float32), lengths[self.index].astype(
                np.float32))
        self.old = (area.directions[self.index].copy(), area.lengths[self.index].copy())
        self.setObsolete(self.empty and gesture is not None)  # a dab that changed nothing

    def _apply(self, values: tuple[np.ndarray, np.ndarray]) -> None:
        self.area.directions[self.index] = values[0]
        self.area.lengths[self.index] = values[1]
        self.doc.wdvChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)

    def id(self) -> int:
        return _VECTORS_ID if self.gesture is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:
        """The state before self and after other, over the union of the vertices they touched
        (``other`` has been applied: the area holds the state after it)."""
        if (not isinstance(other, VectorsCommand) or other.gesture != self.gesture
                or other.area is not self.area):
            return False
        index = np.union1d(self.index, other.index)
        old_d = np.empty((len(index), 3), np.float32)
        old_l = np.empty(len(index), np.float32)
        for cmd in (other, self):  # self's "before" wins where both touched a vertex
            pos = np.searchsorted(index, cmd.index)
            old_d[pos], old_l[pos] = cmd.old
        new_d, new_l = self.area.directions[index].copy(), self.area.lengths[index].copy()
        keep = np.any(old_d != new_d, axis=1) | (old_l != new_l)
        self.index = index[keep]
        self.old = (old_d[keep], old_l[keep])
        self.new = (new_d[keep], new_l[keep])
        self.setObsolete(self.empty)  # combed and back: no step
        return True

    @property
    def empty(self) -> bool:
        return len(self.index) == 0


# --- edits the views call ------------------------------------------------------------------------

def set_selection(doc: Document, new: np.ndarray, text: str = "Select",
                  gesture: Hashable | None = None) -> None:
    new = np.asarray(new, bool)
    if new.shape != doc.selection.shape:
        raise ValueError(f"a selection needs {doc.selection.shape[0]} entries, not {new.shape}")
    if np.array_equal(new, doc.selection) and gesture is None:
        return
    doc.undo_stack.push(SelectionCommand(doc, new, text, gesture))


def add_area(doc: Document, name: str = "area", pose: str | None = None) -> WdvArea:
    """A new, empty area at the end of the list, named uniquely, in a colour unlike the others'
    and the selection's."""
    wdv = doc.project.wdv
    if pose is None:
        pose = doc.project.poses[0].name if doc.project.poses else "neutral"
    colour = distinct_colour(a.colour for a in wdv.areas)
    taken = (a.name for a in wdv.areas)
    area = WdvArea.empty(unique_name(name, taken), pose, doc.project.mesh.n_welded, colour=colour)
    doc.undo_stack.push(AreaListCommand(doc, [*wdv.areas, area], f"Add area {area.name}",
                                        current=area))
    return area


def delete_area(doc: Document, index: int) -> None:
    areas = list(doc.project.wdv.areas)
    area = areas.pop(index)
    doc.undo_stack.push(AreaListCommand(doc, areas, f"Delete area {area.name}"))


def move_area(doc: Document, index: int, to: int) -> None:
    areas = list(doc.project.wdv.areas)
    to = max(0, min(to, len(areas) - 1))
    if to == index:
        return
    areas.insert(to, areas.pop(index))
    doc.undo_stack.push(AreaListCommand(doc, areas, f"Move area {areas[to].name}"))


def clear_areas(doc: Document) -> None:
    if doc.project.wdv.areas:
        doc.undo_stack.push(AreaListCommand(doc, [], "Remove all areas"))


def set_area_value(doc: Document, area: WdvArea, attr: str, value, label: str,
                   gesture: Hashable | None = None) -> None:
    """One property of an area (name, pose, colour, cone angle, enabled) as one undo step."""
    if attr == "name":
        value = str(value).strip()
        if not value:
            raise ValueError("an area needs a name")
        if any(a is not area and a.name == value for a in doc.project.wdv.areas):
            raise ValueError(f"there is already an area called '{value}'")
    if attr == "pose":
        doc.project.pose(value)  # raises with the list of poses when unknown
    if getattr(area, attr) == value:
        return

    def apply(v) -> None:
        setattr(area, attr, v)
        doc.wdvChanged.emit()

    key = None if gesture is None else ("wdv-area", attr, id(area), gesture)
    doc.undo_stack.push(ValueCommand(f"{label} of {area.name}", lambda: getattr(area, attr),
                                     apply, value, key))


def set_cone_angles(doc: Document, area: WdvArea, hits: np.ndarray | None, value: float,
                    gesture: Hashable | None = None) -> None:
    """Paint the cone angle (degrees; 0 = the area's own) of the ``hits`` vertices, or clear
    every painted angle (``hits`` None). A brush stroke (one gesture) is one undo step; each
    step keeps the area's whole angle array before and after (W floats, arrays never mutated)."""
    old = area.cone_angles_deg
    if hits is None:
        new = None
    else:
        new = np.zeros(len(area.lengths), np.float32) if old is None else old.copy()
        new[hits] = value
    if (new is None and old is None) or (
            new is not None and old is not None and np.array_equal(new, old)):
        return

    def apply(v: np.ndarray | None) -> None:
        area.cone_angles_deg = v
        doc.wdvChanged.emit()

    text = (f"Clear painted cone angles of {area.name}" if hits is None
            else f"Paint cone angles of {area.name}")
    key = None if gesture is None else ("wdv-cones", id(area), gesture)
    doc.undo_stack.push(ValueCommand(text, lambda: area.cone_angles_deg, apply, new, key))


def set_enabled_all(doc: Document, enabled: tuple[bool, ...], text: str) -> None:
    """Solo / mute: the enabled flag of every area at once."""
    push_flags(doc.undo_stack, list(doc.project.wdv.areas), "enabled", enabled, text,
               doc.wdvChanged.emit)


def create_directions(doc: Document, area: WdvArea) -> np.ndarray:
    """"Create wrinkle direction" for the selected vertices: d = normalize(P_target −
    P_neutral) and the authored length; every other vertex of the area gets zero. Returns the
    selected vertices that do not move in the area's pose (they get no direction, not NaN)."""
    project = doc.project
    target = project.pose(area.pose).positions
    result = wrinkle_directions(project.mesh.rest, target, np.flatnonzero(doc.selection))
    cmd = VectorsCommand(doc, area, result.directions, result.lengths,
                         f"Create wrinkle directions for {area.name}")
    if not cmd.empty:
        doc.undo_stack.push(cmd)
    return result.still


def clear_directions(doc: Document, area: WdvArea) -> None:
    n = doc.project.mesh.n_welded
    cmd = VectorsCommand(doc, area, np.zeros((n, 3), np.float32), np.zeros(n, np.float32),
                         f"Clear wrinkle directions of {area.name}")
    if not cmd.empty:
        doc.undo_stack.push(cmd)


def comb_directions(doc: Document, area: WdvArea, index: np.ndarray, directions: np.ndarray,
                    lengths: np.ndarray, gesture: Hashable) -> None:
    """One comb dab: new directions and lengths of the ``index`` vertices; the dabs of one
    stroke (``gesture``) are one undo step."""
    cmd = VectorsCommand(doc, area, directions, lengths, f"Comb wrinkle directions of "
                         f"{area.name}", gesture, index)
    if not cmd.empty:
        doc.undo_stack.push(cmd)
