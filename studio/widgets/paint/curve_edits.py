"""The undo command for a pose → area link's response curve.

A curve is an immutable value, so the command is the document's ordinary ``ValueCommand``: a
drag of a curve's handle carries one gesture token and merges into one undo step, like a slider.
Linear curves are not stored (absent = linear), so choosing "linear" removes the entry and a
project without curves stays exactly as before.
"""

from __future__ import annotations

from studio.core.wrinkles.response import LINEAR, ResponseCurve, curve_of
from studio.widgets.commands import ValueCommand
from studio.widgets.document import Document


def link_curve(doc: Document, pose: str, area: str) -> ResponseCurve:
    """The curve of the link ``pose`` → ``area`` (linear when none is set)."""
    return curve_of(doc.project.influence.curves, pose, area)


def set_link_curve(doc: Document, pose: str, area: str, curve: ResponseCurve,
                   gesture: int | None = None) -> None:
    """Give the link its curve as one undo step (commands of one ``gesture`` merge)."""
    if curve == link_curve(doc, pose, area):
        return

    def apply(value: ResponseCurve) -> None:
        curves = doc.project.influence.curves
        if value == LINEAR:
            curves.get(pose, {}).pop(area, None)
            if not curves.get(pose, True):
                curves.pop(pose)
        else:
            curves.setdefault(pose, {})[area] = value
        doc.curvesChanged.emit()
        doc.activationsChanged.emit()

    merge = None if gesture is None else ("link curve", gesture, pose, area)
    doc.undo_stack.push(ValueCommand(f"Curve of {pose} → {area}",
                                     lambda: link_curve(doc, pose, area), apply, curve, merge))
