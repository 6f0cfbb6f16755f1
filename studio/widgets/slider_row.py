"""A labelled slider with a spin box: the studio's control for one number.

A drag is one gesture (one undo step); each spin-box or keyboard step is its own. Setting the value
from the document (after an undo, say) does not echo back as an edit.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QDoubleSpinBox, QHBoxLayout, QLabel, QSlider, QWidget

from studio.widgets.commands import new_gesture

STEPS = 1000
LABEL_WIDTH = 96  # pixels: an ARKit name such as "mouthShrugLower" in the default font
FIELD_WIDTH = 64


class SliderRow(QWidget):
    edited = Signal(float, object)  # value, gesture token (None for a single step)
    touched = Signal()  # the person took hold of the slider, whether or not it then moved

    def __init__(self, label: str, minimum: float = 0.0, maximum: float = 1.0,
                 decimals: int = 2, suffix: str = "", parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.minimum, self.maximum = minimum, maximum
        self.label = QLabel(label)
        # a fixed column in a 300-pixel panel leaves the slider room to be dragged (a 110-pixel
        # label and a 78-pixel field left it 58); the whole name is in the tooltip
        self.label.setFixedWidth(LABEL_WIDTH)
        self.label.setToolTip(label)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, STEPS)
        self.slider.setObjectName(f"slider:{label}")
        self.spin = QDoubleSpinBox()
        self.spin.setRange(minimum, maximum)
        self.spin.setDecimals(decimals)
        self.spin.setSingleStep((maximum - minimum) / 100.0)
        self.spin.setSuffix(suffix)
        self.spin.setKeyboardTracking(False)
        self.spin.setFixedWidth(FIELD_WIDTH)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.label)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.spin)
        self._gesture: int | None = None
        self.slider.sliderPressed.connect(self._begin)
        self.slider.sliderReleased.connect(self._end)
        self.slider.valueChanged.connect(self._slider_moved)
        self.spin.valueChanged.connect(lambda v: self.edited.emit(float(v), None))

    def _to_slider(self, value: float) -> int:
        span = self.maximum - self.minimum
        return round((value - self.minimum) / span * STEPS) if span else 0

    def _from_slider(self, position: int) -> float:
        return self.minimum + (self.maximum - self.minimum) * position / STEPS

    def _begin(self) -> None:
        self._gesture = new_gesture()
        self.touched.emit()

    def _end(self) -> None:
        self._gesture = None

    def _slider_moved(self, position: int) -> None:
        value = self._from_slider(position)
        self.spin.blockSignals(True)
        self.spin.setValue(value)
        self.spin.blockSignals(False)
        self.edited.emit(value, self._gesture)

    def value(self) -> float:
        return self.spin.value()

    def compact(self) -> None:
        """A value field without step arrows, as wide as its widest value (Blender's shape-key
        values are plain fields too): the room goes to the name and the slider. Typing and
        the arrow keys still edit it."""
        self.spin.setButtonSymbols(QDoubleSpinBox.ButtonSymbols.NoButtons)
        text = self.spin.textFromValue(self.spin.maximum()) + self.spin.suffix()
        self.spin.setFixedWidth(self.spin.fontMetrics().horizontalAdvance(text) + 14)
        self.layout().setSpacing(4)

    def label_needs(self) -> int:
        """Pixels the label's words take in its font."""
        return self.label.fontMetrics().horizontalAdvance(self.label.text()) + 2

    def set_value(self, value: float) -> None:
        """Show a value that came from the document, without emitting an edit."""
        for widget, v in ((self.slider, self._to_slider(value)), (self.spin, value)):
            widget.blockSignals(True)
            widget.setValue(v)
            widget.blockSignals(False)


def fit_labels(rows: list[SliderRow]) -> None:
    """One label column for a panel's rows, as wide as the widest name needs and at least
    ``LABEL_WIDTH``: "mouthLowerDown_L" and "Expression factor" read whole, and the sliders
    still line up."""
    width = max([LABEL_WIDTH, *(row.label_needs() for row in rows)])
    for row in rows:
        row.label.setFixedWidth(width)
