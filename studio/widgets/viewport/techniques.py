"""The techniques a person can show, and the one view change that shows one.

Why a module: the Shading panel's combo, the viewport's technique switch and the Areas panel
(which shows technique 1 when an area is painted or linked) all choose a technique; one list and
one function keep them saying and doing the same.
"""

from __future__ import annotations

from studio.core.wrinkles.techniques import TECHNIQUE_LIST
from studio.widgets.document import Document

# every technique of the registry but flat shading (a benchmark baseline), then the split view
TECHNIQUE_CHOICES = [*((t.label, t.key) for t in TECHNIQUE_LIST if t.key != "flat"),
                     ("Split: t1 | t2 | automatic", "split")]


def choose_technique(doc: Document, key: str) -> None:
    """Show ``key`` (a technique's key, or "split" for the three side by side)."""
    if key == "split":
        doc.set_view(split=True)
    else:
        doc.set_view(split=False, technique=key)


def show_technique_1(doc: Document) -> str:
    """Switch the single view to technique 1 if it shows something else (an area painted or
    linked is technique 1's, and shows nothing under technique 2); returns what to say, or ""
    when nothing changed. The split view already shows technique 1 in its left pane."""
    view = doc.view
    if view.split or view.technique == "t1":
        return ""
    choose_technique(doc, "t1")
    # short: it follows what the gesture did in one status-bar line (1280 pixels wide)
    return "Technique 1 on, where areas show (the viewport's label switches back)"
