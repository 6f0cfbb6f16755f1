"""Key-pose weights and technique-1 activations: sliders that deform the face live."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import (
    QFormLayout,
    QGroupBox,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from studio.widgets.document import Document
from studio.widgets.slider_row import SliderRow, fit_labels


class ActivationBar(QWidget):
    """A thin bar in the area's colour. (QProgressBar repaints synchronously on every change,
    which made playback crawl with a dozen of them.)"""

    def __init__(self, colour: tuple[int, int, int]) -> None:
        super().__init__()
        self.colour = QColor(*colour)
        self.fraction = 0.0
        self.setFixedHeight(5)

    def set_fraction(self, fraction: float) -> None:
        if fraction != self.fraction:
            self.fraction = fraction
            self.update()

    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.fillRect(self.rect(), self.palette().color(self.backgroundRole()).darker(115))
        filled = self.rect()
        filled.setWidth(round(self.width() * self.fraction))
        painter.fillRect(filled, self.colour)


FILTER_FROM = 8  # poses beyond which the panel offers a filter field


def pose_label(name: str) -> str:
    """A pose's name as the user's rig spells it (``browInnerUp``, ``eyeBlink_L``): never
    re-cased, so it can be found in the rig, the capture file and the engine."""
    return name


class PosePanel(QScrollArea):
    poseEdited = Signal(str)  # a pose's slider or field was moved by the user (K keys it)

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = document
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.pose_rows: dict[str, SliderRow] = {}
        self.area_rows: list[SliderRow] = []
        self.area_bars: list[ActivationBar] = []
        self._build()
        document.projectReplaced.connect(self._build)
        document.posesChanged.connect(self._build)
        document.areasChanged.connect(self._build)
        document.poseWeightsChanged.connect(self._show_values)
        document.activationsChanged.connect(self._show_values)

    def _build(self) -> None:
        body = QWidget()
        layout = QVBoxLayout(body)
        poses = QGroupBox("Key poses")
        pose_layout = QVBoxLayout(poses)
        self.filter = QLineEdit()
        self.filter.setPlaceholderText("Filter poses (e.g. brow, _L, smile)")
        self.filter.setClearButtonEnabled(True)
        self.filter.setToolTip("Show only the poses whose name contains this text (any case)")
        self.filter.textChanged.connect(self._apply_filter)
        self.filter.setVisible(len(self.doc.project.poses) > FILTER_FROM)
        pose_layout.addWidget(self.filter)
        self.pose_rows = {}
        for pose in self.doc.project.poses:
            row = SliderRow(pose_label(pose.name))
            row.compact()  # a rig's long names whole and a slider of 100 pixels in the column
            row.edited.connect(lambda v, g, n=pose.name: self._pose_edited(n, v, g))
            # the pose K keys is the one last taken hold of, even by a drag that ended where
            # it began: keying another pose, unseen, was the surprise
            row.touched.connect(lambda n=pose.name: self.poseEdited.emit(n))
            pose_layout.addWidget(row)
            self.pose_rows[pose.name] = row
        fit_labels(list(self.pose_rows.values()))
        reset = QPushButton("Back to neutral")
        reset.setToolTip("Set every key-pose weight to 0")
        reset.clicked.connect(self._reset_pose)
        pose_layout.addWidget(reset)
        layout.addWidget(poses)

        areas = QGroupBox("Influence areas (technique 1)")
        form = QFormLayout(areas)
        hint = QLabel("Slider: the area's own activation. Bar: with the pose links.")
        hint.setWordWrap(True)  # the panel is a narrow column
        form.addRow(hint)
        self.area_rows, self.area_bars = [], []
        for index, area in enumerate(self.doc.project.influence.areas):
            row = SliderRow(area.name)
            row.edited.connect(lambda v, g, i=index: self.doc.set_area_activation(i, v, g))
            bar = ActivationBar(area.colour)
            form.addRow(row)
            form.addRow(bar)
            self.area_rows.append(row)
            self.area_bars.append(bar)
        if not self.area_rows:
            form.addRow(QLabel("This project has no influence areas."))
        layout.addWidget(areas)
        layout.addStretch(1)
        self.setWidget(body)
        self._show_values()

    def _pose_edited(self, name: str, value: float, gesture: int | None) -> None:
        self.doc.set_pose_weight(name, value, gesture)
        self.poseEdited.emit(name)

    def _apply_filter(self, text: str) -> None:
        """Rows whose pose name contains the text (any case), like the shape-key filter of a
        3-D package: a pose of a 52-pose rig is found by typing."""
        wanted = text.strip().lower()
        for name, row in self.pose_rows.items():
            row.setVisible(wanted in name.lower())

    def _reset_pose(self) -> None:
        """Every pose back to 0: like the sliders, a view of the face and not an edit."""
        for name in self.pose_rows:
            self.doc.set_pose_weight(name, 0.0)

    def _show_values(self) -> None:
        for name, row in self.pose_rows.items():
            row.set_value(self.doc.pose_weights.get(name, 0.0))
        activations = self.doc.activations()
        areas = self.doc.project.influence.areas
        for row, bar, area, value in zip(self.area_rows, self.area_bars, areas, activations,
                                         strict=False):
            row.set_value(area.activation)
            bar.set_fraction(float(value))
