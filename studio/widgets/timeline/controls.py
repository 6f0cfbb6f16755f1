"""The timeline's controls left of the tracks: transport, frame, row height, rate and range,
the selected keys' mode and weight, Sequence all poses and what the curves show.

Why their own module: a column of fields built once; each field calls the panel, which turns it
into a timeline edit or a view change.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QScrollArea,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from studio.core.animation.timeline import INTERPOLATIONS
from studio.widgets.timeline.track_model import ROW_PIXELS_RANGE, VALUE_SNAP

if TYPE_CHECKING:
    from studio.widgets.timeline.host import TimelineHost

CONTROLS_WIDTH = 250  # pixels: the transport and key controls left of the tracks
INTERPOLATION_LABELS = {"linear": "Linear", "cosine": "Cosine (Parke)",
                        "smooth": "Smooth (ease in/out)", "constant": "Constant (hold)"}


class TimelineControls(QScrollArea):
    """The controls' column; a short dock scrolls it rather than hiding the graphs."""

    def __init__(self, panel: TimelineHost) -> None:
        super().__init__()
        controls = QVBoxLayout()
        controls.setSpacing(2)
        controls.setContentsMargins(0, 0, 0, 0)
        transport = QHBoxLayout()
        transport.setSpacing(2)
        self.buttons: dict[str, QToolButton] = {}
        for name, text, tip, slot in (
                ("start", "SP_MediaSkipBackward", "Jump to start (Home, Shift+Left)",
                 panel.jump_start),
                ("back", "SP_MediaSeekBackward", "Previous frame (Left)", lambda: panel.step(-1)),
                ("play", "SP_MediaPlay", "Play / pause (Space)", panel.player.toggle),
                ("forward", "SP_MediaSeekForward", "Next frame (Right)", lambda: panel.step(1)),
                ("end", "SP_MediaSkipForward", "Jump to end (End, Shift+Right)", panel.jump_end)):
            button = QToolButton()
            button.setIcon(panel.icon(text))
            button.setToolTip(tip)
            button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            button.clicked.connect(slot)
            button.setMinimumWidth(30)
            transport.addWidget(button)
            self.buttons[name] = button
        self.loop = QCheckBox("Loop")
        self.loop.setChecked(True)
        self.loop.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.loop.toggled.connect(lambda on: setattr(panel.player, "loop", on))
        transport.addWidget(self.loop)
        transport.addStretch(1)
        controls.addLayout(transport)
        self.frame_label = QLabel()
        self.frame_label.setStyleSheet("font-weight: bold;")
        self.row_height = QSpinBox()  # beside the frame: the controls fit a 200-px dock
        self.row_height.setRange(*ROW_PIXELS_RANGE)
        self.row_height.setSuffix(" px")
        self.row_height.setKeyboardTracking(False)
        self.row_height.setToolTip("Height of the track rows (or drag a row's edge in the "
                                   "names' column); taller rows set a weight more finely")
        self.row_height.setValue(panel.row_pixels)
        self.row_height.valueChanged.connect(panel.set_row_pixels)
        frame_row = QHBoxLayout()
        frame_row.addWidget(self.frame_label, 1)
        frame_row.addWidget(QLabel("Rows"))
        frame_row.addWidget(self.row_height)
        controls.addLayout(frame_row)

        form = QFormLayout()
        form.setContentsMargins(0, 0, 0, 0)
        form.setVerticalSpacing(2)
        self.fps = QDoubleSpinBox()
        self.fps.setRange(1.0, 240.0)
        self.fps.setDecimals(2)
        self.fps.setSuffix(" fps")
        self.start = QSpinBox()
        self.end = QSpinBox()
        for spin in (self.start, self.end):
            spin.setRange(-100000, 100000)
        range_row = QHBoxLayout()
        range_row.addWidget(self.start)
        range_row.addWidget(QLabel("to"))
        range_row.addWidget(self.end)
        for spin in (self.fps, self.start, self.end):
            spin.setKeyboardTracking(False)  # one edit when typing ends, not one per digit
        self.fps.valueChanged.connect(lambda v: panel.set_range(fps=v))
        self.start.valueChanged.connect(lambda v: panel.set_range(start=v))
        self.end.valueChanged.connect(lambda v: panel.set_range(end=v))
        form.addRow("Rate", self.fps)
        form.addRow("Frames", range_row)
        self.interpolation = QComboBox()
        for mode in INTERPOLATIONS:
            self.interpolation.addItem(INTERPOLATION_LABELS[mode], mode)
        self.interpolation.setToolTip("How the selected keys go on to the next key")
        self.interpolation.activated.connect(panel.interpolation_chosen)
        self.key_value = QDoubleSpinBox()
        self.key_value.setRange(0.0, 1.0)
        self.key_value.setSingleStep(VALUE_SNAP)
        self.key_value.setKeyboardTracking(False)
        self.key_value.setToolTip("Weight of the selected keys (0 = neutral, 1 = the full pose)")
        self.key_value.valueChanged.connect(panel.value_chosen)
        key_row = QHBoxLayout()
        key_row.addWidget(self.interpolation, 1)
        key_row.addWidget(self.key_value)
        form.addRow("Key", key_row)
        controls.addLayout(form)
        self.sequence = QPushButton("Sequence all poses")
        self.sequence.setToolTip("Replace the animation by neutral → pose → neutral for each "
                                 "key pose in turn (0.5 s up, 0.5 s hold, 0.5 s down)")
        self.sequence.clicked.connect(lambda: panel.edits.sequence_all_poses())
        controls.addWidget(self.sequence)
        self.curve_mode = QComboBox()
        for text, mode in (("Curves: pose weights", "weights"),
                           ("Curves: area activations (t1)", "activations"),
                           ("Curves: both", "both")):
            self.curve_mode.addItem(text, mode)
        self.curve_mode.setCurrentIndex(2)
        self.curve_mode.currentIndexChanged.connect(panel.refresh_curves)
        controls.addWidget(self.curve_mode)
        controls.addStretch(1)
        side = QWidget()
        side.setLayout(controls)
        self.setWidget(side)
        self.setWidgetResizable(True)
        self.setFrameShape(QScrollArea.Shape.NoFrame)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setSizeAdjustPolicy(QAbstractScrollArea.SizeAdjustPolicy.AdjustIgnored)
        self.setFixedWidth(CONTROLS_WIDTH + self.verticalScrollBar().sizeHint().width())
        self.setMinimumHeight(0)
