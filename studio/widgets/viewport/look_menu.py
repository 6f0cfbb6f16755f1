"""View ▸ Look: the clay or the skin look, and the lights the skin is seen under.

As Blender's viewport shading (Solid or Material Preview, and the studio light it uses): a
view of the face, not an edit, so it is a view setting (saved with the project, never on the
undo stack). Each choice is a checkable item of an exclusive group that follows the document,
whatever changed the view.
"""

from __future__ import annotations

from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import QMenu

from studio.core.wrinkles.skin_light import RIG_LABELS
from studio.widgets.document import Document

LOOK_LABELS = {"clay": "&Clay", "skin": "&Skin"}
LOOK_TIPS = {"clay": "The first shading: one key light and a fill on the albedo",
             "skin": "A skin shader: light scattering under the skin, two specular lobes, the "
                     "head's own albedo, under the chosen lights"}


class LookMenu:
    """The Look submenu's items, kept checked as the document's view says."""

    def __init__(self, menu: QMenu, document: Document) -> None:
        self.document = document
        self.looks = self._group(menu, "look", LOOK_LABELS, LOOK_TIPS)
        menu.addSeparator()
        self.lights = menu.addMenu("Skin &Lights")  # the skin look's: greyed in clay
        self.rigs = self._group(self.lights, "light_rig", RIG_LABELS, {})
        document.viewChanged.connect(self._show)
        self._show()

    def _group(self, menu: QMenu, field: str, labels: dict[str, str],
               tips: dict[str, str]) -> dict[str, QAction]:
        group = QActionGroup(menu)
        actions = {}
        for value, label in labels.items():
            action = QAction(label, menu, checkable=True)
            action.setStatusTip(tips.get(value, ""))
            action.triggered.connect(lambda _=False, v=value: self.document.set_view(**{field: v}))
            group.addAction(action)
            menu.addAction(action)
            actions[value] = action
        return actions

    def _show(self) -> None:
        view = self.document.view
        self.looks[view.look].setChecked(True)
        self.rigs[view.light_rig].setChecked(True)
        self.lights.setEnabled(view.look == "skin")
