"""One pose's link to the selected influence area in the Areas panel: its gain, its response
curve's kind and the curve's plot.

The Areas panel shows an editor for each pose that drives the selected area ("driven by"); the
gain spin box is the link itself (0 or ✕ unlinks); the curve choice and the plot are made
only for a linked pose (``show_link`` adds or drops them in place when the link changes), so an
ARKit face's 52 poses cost 52 spin boxes, not 52 plots of ~10 ms each. Every change is
an undo command (edits.set_link, curve_edits.set_link_curve); the editor shows the document back
on ``refresh``, which the panel calls when the curves change (an edit, its undo or redo).
"""

from __future__ import annotations

from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from studio.core.wrinkles.response import LABELS, ResponseCurve
from studio.core.wrinkles.response_handles import converted
from studio.widgets.document import Document
from studio.widgets.paint import edits
from studio.widgets.paint.curve_edits import link_curve, set_link_curve
from studio.widgets.paint.curve_plot import CurvePlot


class LinkEditor(QWidget):
    def __init__(self, doc: Document, pose: str, area: str) -> None:
        super().__init__()
        self.doc, self.pose, self.area = doc, pose, area
        self.spin = QDoubleSpinBox()
        self.spin.setRange(0.0, 2.0)
        self.spin.setSingleStep(0.1)
        self.spin.setKeyboardTracking(False)
        self.spin.setSpecialValueText("not linked")
        self.spin.setToolTip("Gain: the most this pose adds to the area's activation")
        self.spin.valueChanged.connect(lambda g: edits.set_link(doc, pose, area, g))
        self.remove = QToolButton()
        self.remove.setText("✕")
        self.remove.setAutoRaise(True)
        self.remove.setToolTip(f"Unlink {pose}: it no longer drives this area")
        self.remove.clicked.connect(lambda: edits.set_link(doc, pose, area, 0.0))
        self._top = QHBoxLayout()
        self._top.setContentsMargins(0, 0, 0, 0)
        self._top.addWidget(self.spin, 1)
        self._layout = QVBoxLayout(self)
        self._layout.setContentsMargins(0, 0, 0, 0)
        self._top.addWidget(self.remove)
        self._layout.addLayout(self._top)
        self.kind: QComboBox | None = None
        self.plot: CurvePlot | None = None
        self.show_link()

    def gain(self) -> float:
        return self.doc.project.influence.links.get(self.pose, {}).get(self.area, 0.0)

    def show_link(self) -> None:
        """Show the link as the document has it, in place: the gain in the spin box (which
        keeps the focus and the cursor of a person typing in it), the curve's controls made
        when the pose becomes linked and dropped when it is unlinked."""
        gain = self.gain()
        if self.spin.value() != gain:
            self.spin.blockSignals(True)
            self.spin.setValue(gain)
            self.spin.blockSignals(False)
        if (gain != 0.0) != (self.kind is not None):
            self._drop_curve() if gain == 0.0 else self._make_curve()
        self.refresh()

    def _make_curve(self) -> None:
        self.kind = QComboBox()
        for kind, label in LABELS.items():
            self.kind.addItem(label, kind)
        self.kind.setToolTip("Response curve: how the pose's weight becomes its "
                             "contribution (gain × curve(weight))")
        self.kind.setObjectName(f"curve:{self.pose}")
        self.kind.setSizeAdjustPolicy(  # a narrow column elides the curve's name, not the row
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.kind.setMinimumContentsLength(8)
        self.plot = CurvePlot()
        self._top.insertWidget(1, self.kind, 1)  # before the unlink button
        self._layout.addWidget(self.plot)
        self.kind.activated.connect(self._kind_chosen)
        self.plot.edited.connect(self._edited)

    def _drop_curve(self) -> None:
        for widget in (self.kind, self.plot):
            if widget is not None:  # deleted later: the unlinking may have come from it
                widget.hide()
                widget.deleteLater()
        self.kind = self.plot = None

    def curve(self) -> ResponseCurve:
        return link_curve(self.doc, self.pose, self.area)

    def refresh(self) -> None:
        """Show the link's curve as the document has it (nothing to show for no link)."""
        if self.kind is None or self.plot is None:
            return
        curve = self.curve()
        self.kind.blockSignals(True)
        self.kind.setCurrentIndex(self.kind.findData(curve.kind))
        self.kind.blockSignals(False)
        self.plot.show_curve(curve)

    def _kind_chosen(self, row: int) -> None:
        assert self.kind is not None  # connected only when made
        self._edited(converted(self.curve(), self.kind.itemData(row)), None)

    def _edited(self, curve: ResponseCurve, gesture: int | None) -> None:
        set_link_curve(self.doc, self.pose, self.area, curve, gesture)
