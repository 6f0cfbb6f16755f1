"""One row of the Areas panel's list: an area's visibility, colour, name (renamed in place)
and its own activation slider, each a document edit.

Why its own module: the row is a small view of one area; the panel only lays rows out.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QSlider,
    QToolButton,
    QWidget,
)

from studio.widgets.commands import new_gesture
from studio.widgets.paint import edits as mask_edits
from studio.widgets.swatch import swatch

if TYPE_CHECKING:
    from studio.widgets.paint.hosts import AreasHost

WARNING_STYLE = "color: #e0a030;"


class AreaRow(QWidget):
    """One layer: visibility, colour, name and its own activation slider."""

    def __init__(self, panel: AreasHost, index: int) -> None:
        super().__init__()
        self.panel, self.index = panel, index
        area = panel.doc.project.influence.areas[index]
        self.visible = QCheckBox()
        self.visible.setChecked(area.visible)
        self.visible.setToolTip("Show / hide this area (hidden areas give no wrinkles)")
        self.colour = QToolButton()
        self.colour.setIcon(swatch(area.colour))
        self.colour.setToolTip("Change the area's colour")
        self.colour.setAutoRaise(True)
        self.name = QLabel(area.name)
        self.name.setMinimumWidth(max(110, self.name.sizeHint().width()))  # never cut
        self.editor = QLineEdit(area.name)  # the name, renamed in place (F2, double-click)
        self.editor.hide()
        self.editor.returnPressed.connect(self._renamed)
        self.editor.editingFinished.connect(self._renamed)
        self.editor.installEventFilter(self)
        self.flag = QLabel("⚠")  # shown when the area reveals a flat part of its map
        self.flag.setStyleSheet(WARNING_STYLE)
        self.flag.hide()
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, 100)
        self.slider.setToolTip("The area's own activation (pose links add to it)")
        self.slider.setObjectName(f"activation:{area.name}")
        self.value = QLabel()
        self.value.setFixedWidth(34)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 1, 4, 1)
        for w in (self.visible, self.colour, self.name, self.editor, self.flag):
            layout.addWidget(w)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.value)
        self._gesture: int | None = None
        self.flagged = ""  # why the area shows nothing (AreasPanel._show_flat), or ""
        self.show_values()
        self.visible.toggled.connect(
            lambda v: mask_edits.set_area_visible(panel.doc, self.index, v))
        self.colour.clicked.connect(self._pick_colour)
        self.slider.sliderPressed.connect(self._begin)
        self.slider.sliderReleased.connect(self._end)
        self.slider.valueChanged.connect(self._moved)

    def rename(self) -> None:
        """Edit the name where it is, as the Wrinkle vectors panel and Blender's lists do:
        Return or a click elsewhere keeps it, Escape leaves it as it was."""
        self.name.hide()
        self.editor.setText(self.name.text())
        self.editor.show()
        self.editor.setFocus()
        self.editor.selectAll()

    def _renamed(self) -> None:
        if self.editor.isHidden():
            return  # (Return, then the focus leaving: one rename)
        self.editor.hide()
        self.name.show()
        name = self.editor.text().strip()
        if name and name != self.name.text() and not mask_edits.rename_area(
                self.panel.doc, self.index, name):
            self.panel.say_taken(name)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if (watched is self.editor and event.type() == QEvent.Type.KeyPress
                and event.key() == Qt.Key.Key_Escape):
            self.editor.setText(self.name.text())
            self.editor.hide()
            self.name.show()
            return True
        return super().eventFilter(watched, event)

    def _begin(self) -> None:
        self._gesture = new_gesture()

    def _end(self) -> None:
        self._gesture = None

    def _moved(self, value: int) -> None:
        self.panel.doc.set_area_activation(self.index, value / 100.0, self._gesture)

    def _pick_colour(self) -> None:
        area = self.panel.doc.project.influence.areas[self.index]
        colour = QColorDialog.getColor(QColor(*area.colour), self, f"Colour of {area.name}")
        if colour.isValid():
            mask_edits.set_area_colour(self.panel.doc, self.index,
                                       (colour.red(), colour.green(), colour.blue()))

    def show_values(self) -> None:
        doc = self.panel.doc
        area = doc.project.influence.areas[self.index]
        self.slider.blockSignals(True)
        self.slider.setValue(round(area.activation * 100))
        self.slider.blockSignals(False)
        total = doc.activations()[self.index]
        self.value.setText(f"{total:.2f}")
        self.value.setToolTip("Activation now, pose links included")
