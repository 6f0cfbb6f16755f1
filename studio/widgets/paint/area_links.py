"""The Areas panel's "driven by" box: the selected area's wrinkled map and the poses that drive
it, each with its gain and response curve, "Add pose…" to link another, and Auto mask.

Why its own module: the box is rebuilt from the document on its own rules (in place while the
same links are shown, so a field being typed in keeps its focus); what it shows comes from
``areas_model``, what it does are document edits.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QComboBox,
    QCompleter,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QVBoxLayout,
)

from studio.core.setup.pose_map import map_on_link
from studio.widgets.flow_layout import FlowLayout, button
from studio.widgets.paint import edits as mask_edits
from studio.widgets.paint.area_row import WARNING_STYLE
from studio.widgets.paint.areas_model import (
    addable_poses,
    linked_poses,
    links_shown,
    map_chosen_text,
)
from studio.widgets.paint.link_editor import LinkEditor
from studio.widgets.rebuild import clear_form
from studio.widgets.timeline.pose_panel import pose_label
from studio.widgets.viewport.techniques import show_technique_1

if TYPE_CHECKING:
    from studio.widgets.paint.hosts import AreasHost


class AreaLinks(QGroupBox):
    """The selected area's map and the poses that drive it: only the linked ones, and "Add
    pose…" to link another by typing part of its name (MetaHuman's and Character Creator's
    "driven by" lists), not one field per pose of the rig."""

    def __init__(self, panel: AreasHost) -> None:
        super().__init__("Selected area: wrinkled map, driven by")
        self.panel = panel
        self.doc, self.state = panel.doc, panel.state
        self.link_spins: dict[str, QDoubleSpinBox] = {}
        self.link_editors: dict[str, LinkEditor] = {}
        self.map_combo: QComboBox | None = None
        self._shown: tuple | None = None  # what the form shows (show_links)
        v = QVBoxLayout(self)
        self.flat_note = QLabel()
        self.flat_note.setWordWrap(True)
        self.flat_note.setStyleSheet(WARNING_STYLE)
        self.flat_note.hide()
        v.addWidget(self.flat_note)
        self.add_pose = QComboBox()
        self.add_pose.setEditable(True)
        self.add_pose.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        self.add_pose.lineEdit().setPlaceholderText("Add pose… (type to search)")
        self.add_pose.setToolTip("Link another key pose to this area (gain 1; change it "
                                 "below). Type part of a name, then Return")
        completer = self.add_pose.completer()
        completer.setFilterMode(Qt.MatchFlag.MatchContains)
        completer.setCompletionMode(QCompleter.CompletionMode.PopupCompletion)
        self.add_pose.activated.connect(self.pose_added)
        v.addWidget(self.add_pose)  # first: in sight under the list, however many links
        self.map_said = QLabel()  # which map a link made the area reveal, and why
        self.map_said.setWordWrap(True)
        self.map_said.hide()
        v.addWidget(self.map_said)
        self.links_form = QFormLayout()
        self.links_form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapAllRows)
        v.addLayout(self.links_form)
        note = QLabel("Moving toward a pose raises this area's activation by gain × "
                      "curve(weight); the curve shapes how (linear unless chosen).")
        note.setWordWrap(True)
        v.addWidget(note)
        auto = FlowLayout()
        auto.addWidget(QLabel("From pose"))
        self.auto_pose = QComboBox()
        self.auto_pose.setToolTip("The key pose whose skin compression becomes the new area")
        self.auto_pose.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.auto_pose.setMinimumContentsLength(10)
        auto.addWidget(self.auto_pose)
        auto.addWidget(button("Auto mask", "A new soft area where this pose compresses "
                                    "the skin, linked to the pose, revealing the wrinkled map "
                                    "whose furrows belong to it", panel.auto_mask))
        v.addLayout(auto)


    def show_links(self) -> None:
        """The selected area's map and the poses that drive it. The same area driven by the
        same poses is shown in place, so the field a person is typing in stays where it is (and
        alive: this runs inside that field's own signal); anything else makes the form again
        (its widgets deleted once the event that asked is over)."""
        area = self.panel.active_area()
        project = self.doc.project
        textures = project.textures
        linked = linked_poses(project, area)
        key = links_shown(project, self.state.active, area)
        if area is not None and key == self._shown and self.map_combo is not None:
            self.map_combo.blockSignals(True)
            self.map_combo.setCurrentIndex(textures.map_index(area.wrinkle_map))
            self.map_combo.blockSignals(False)
            for editor in self.link_editors.values():
                editor.show_link()
            return
        self._shown = key
        clear_form(self.links_form)
        self.link_spins = {}
        self.link_editors = {}
        self.add_pose.setEnabled(area is not None)
        if area is None:
            self.links_form.addRow(QLabel("No area selected."))
            return
        self.map_combo = QComboBox()
        self.map_combo.setToolTip("The wrinkled normal map this area reveals (Maps menu: add "
                                  "more)")
        for name in textures.wrinkle_map_names:
            self.map_combo.addItem(name, name)
        self.map_combo.setCurrentIndex(textures.map_index(area.wrinkle_map))
        index = self.state.active
        self.map_combo.activated.connect(lambda i: self.map_chosen(index, i))
        self.links_form.addRow("Wrinkled map", self.map_combo)
        if not linked:
            hint = QLabel("Driven by no pose yet: add one above, or move the area's own "
                          "activation slider.")
            hint.setWordWrap(True)
            self.links_form.addRow(hint)
        for pose in linked:
            editor = LinkEditor(self.doc, pose, area.name)
            self.links_form.addRow(pose_label(pose), editor)
            self.link_editors[pose] = editor
            self.link_spins[pose] = editor.spin
        self.add_pose.blockSignals(True)
        self.add_pose.clear()
        self.add_pose.addItems(addable_poses(project, linked))
        self.add_pose.setCurrentIndex(-1)
        self.add_pose.blockSignals(False)

    def pose_added(self, row: int) -> None:
        """Link the pose (gain 1) and, for an area whose map nobody chose, reveal the pose's
        own map in the same undo step — a frown's area shows the frown's lines, not the first
        map's forehead furrows — and show technique 1, where areas show; say both."""
        area = self.panel.active_area()
        pose = self.add_pose.itemText(row)
        if area is None or pose not in self.doc.project.pose_names:
            return
        index = self.state.active
        project = self.doc.project
        chosen = map_on_link(project, area, pose)
        stack = self.doc.undo_stack
        stack.beginMacro(f"Link {pose} → {area.name}")
        mask_edits.set_link(self.doc, pose, area.name, 1.0)
        if chosen is not None:
            mask_edits.set_area_map(self.doc, index, chosen)
        stack.endMacro()
        said = [text] if (text := map_chosen_text(area.name, chosen, pose)) else []
        self.map_said.setText(text)
        self.map_said.setVisible(bool(text))
        switched = show_technique_1(self.doc)
        if switched:
            said.append(switched)
        if said:
            self.panel.said.emit(" ".join(said))
        editor = self.link_editors.get(pose)
        if editor is not None:  # on to its gain, as a person goes on to set it
            editor.spin.setFocus()
            editor.spin.selectAll()

    def show_curves(self) -> None:
        for editor in self.link_editors.values():
            editor.refresh()

    def map_chosen(self, index: int, row: int) -> None:
        mask_edits.set_area_map(self.doc, index, self.map_combo.itemData(row))
