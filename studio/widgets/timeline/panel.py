"""The timeline dock: key-pose tracks, a playhead, transport controls and a curve view.

Each track row is a small graph of its pose's weight over time (its baseline = 0, top = 1), so
where a key sits says both when and how strongly: click in a row to add a key at that time and
height, drag a key sideways to retime it or up and down to change its weight (one undo step per
drag), drag anywhere else to scrub. The curve view below shows the pose weights and the
technique-1 area activations they produce — what actually drives the wrinkles.

As in Blender's timeline, a ruler of frame numbers above the rows is where one scrubs (click or
drag), and a left drag in the curves scrubs too (panning is the middle or right button); the view
never pans before the first frame. Rows are tall enough to set a weight by height and their
height is the user's (drag the names' column, or the Rows control), remembered across sessions.
The current row — the pose K keys: the last one edited here or in the Poses panel — is marked.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QPointF, QSignalBlocker, QSize, Qt
from PySide6.QtGui import QAction, QColor, QIcon, QKeySequence
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
    QScrollBar,
    QSpinBox,
    QStyle,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from studio.core.animation.timeline import INTERPOLATIONS
from studio.core.project.model import Project
from studio.widgets.app_settings import settings
from studio.widgets.commands import new_gesture
from studio.widgets.document import Document
from studio.widgets.timeline.edits import ClipKey, KeyRef, TimelineEdits, TimelineState
from studio.widgets.timeline.playback import Player
from studio.widgets.timeline.pose_panel import pose_label

ROW_PAD = 0.12  # empty part of a track row above and below its 0..1 band (row units)
ROW_BAND = 1.0 - 2 * ROW_PAD
VALUE_SNAP = 0.05
SNAP_PIXELS = 4.0  # a click this close to a row's baseline (or top) is weight 0 (or 1)
HIT_PIXELS = 8.0
PANEL_HEIGHT = 176  # pixels the timeline asks for: its dock is then about 200 high
CONTROLS_WIDTH = 250  # pixels: the transport and key controls left of the tracks
ROW_PIXELS = 32  # a row's height unless the user chose one: 0.05 of weight is over a pixel
ROW_PIXELS_RANGE = (18, 120)  # the heights a user may give the rows
ROW_HEIGHT_KEY = "timeline/row_pixels"  # where the chosen height is remembered
SAY_MS = 10000  # "Keyed …" stays long enough to read, whatever else redraws meanwhile
ROWS_AT_LEAST = 2  # rows kept on screen however short the dock; the rest scroll
NAMES_PIXELS = 130  # the names' column (the current row's name has a pointer before it)
RULER_PIXELS = 36  # the time ruler's height: its frame numbers, and the playhead's
LEGEND_ENTRIES = 10  # curves the legend names (two columns), so it stays as short as the plot
CURVES_PIXELS = 48  # the curve plot's height (the ruler says its frames)
FOLLOW_MARGIN = 0.05  # share of the shown time kept before the playhead when the view pages
INTERPOLATION_LABELS = {"linear": "Linear", "cosine": "Cosine (Parke)",
                        "smooth": "Smooth (ease in/out)", "constant": "Constant (hold)"}


def pose_colour(index: int, count: int) -> QColor:
    return pg.intColor(index, hues=max(count, 1), values=1, maxValue=230, minValue=230,
                       sat=170)


def activation_curves(project: Project, frames: np.ndarray, base: dict[str, float]
                      ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Pose weights and technique-1 activations at many frames at once.

    Poses without keys keep their ``base`` weight (as ``Document.show_frame`` does); the
    activations are ``InfluenceSetup.activations_over`` — own value plus Σ gain·curve(weight),
    hidden areas at 0, clamped — for every frame at once instead of a call per frame.
    """
    timeline, influence = project.timeline, project.influence
    animated = {t.pose: t.values_at(frames) for t in timeline.tracks if t.keys}
    names = [p.name for p in project.poses]
    weights = np.stack([animated.get(n, np.full(len(frames), base.get(n, 0.0))) for n in names],
                       axis=1) if names else np.zeros((len(frames), 0))
    return animated, influence.activations_over(names, weights)


class TimeViewBox(pg.ViewBox):
    """A time view: the wheel zooms time, a middle or right drag pans it (never before the first
    frame: see ``TimelinePanel.frame_all_time``), Shift+wheel scrolls the track rows."""

    def __init__(self, panel: TimelinePanel) -> None:
        super().__init__(enableMenu=False)
        self.panel = panel
        self.setMouseEnabled(x=True, y=False)

    def wheelEvent(self, ev, axis=None) -> None:
        """Shift+wheel scrolls the rows (when they do not all fit); the wheel zooms time."""
        if ev.modifiers() & Qt.KeyboardModifier.ShiftModifier and self.panel.rows.isVisible():
            ev.accept()
            steps = -int(np.sign(ev.delta())) if ev.delta() else 0
            self.panel.rows.setValue(self.panel.rows.value() + steps)
            return
        super().wheelEvent(ev, 0)


class ScrubViewBox(TimeViewBox):
    """The ruler and the curves: a left click or drag moves the playhead (scrubs), as on
    Blender's timeline; it never pans the view."""

    def mouseClickEvent(self, ev) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseClickEvent(ev)
            return
        ev.accept()
        self.panel.player.stop()
        self.panel.scrub_to(self.mapSceneToView(ev.scenePos()).x())

    def mouseDragEvent(self, ev, axis=None) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseDragEvent(ev, 0)
            return
        ev.accept()
        if ev.isStart():
            self.panel.player.stop()
        self.panel.scrub_to(self.mapSceneToView(ev.scenePos()).x())


class TrackViewBox(TimeViewBox):
    """Left button edits keys and scrubs; a left drag in the names' column sets the rows'
    height (the row edge nearest the press follows the pointer)."""

    def mouseClickEvent(self, ev) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseClickEvent(ev)
            return
        ev.accept()
        if not self.sceneBoundingRect().contains(ev.scenePos()):
            return  # a click on the names' column (forwarded by the axis): nothing to add
        self.panel.track_clicked(self.mapSceneToView(ev.scenePos()), ev.modifiers())

    def hoverEvent(self, ev) -> None:
        """The weight a click would set, shown beside the pointer before the click."""
        if ev.isExit():
            self.panel.show_weight_under(None)
        else:
            self.panel.show_weight_under(self.mapSceneToView(ev.scenePos()))

    def mouseDragEvent(self, ev, axis=None) -> None:
        if ev.button() != Qt.MouseButton.LeftButton:
            super().mouseDragEvent(ev, 0)
            return
        ev.accept()
        if axis == 1:  # the names' column: resize the rows
            if ev.isStart():
                self.panel.row_drag_started(self.mapSceneToView(ev.buttonDownScenePos()).y())
            self.panel.row_drag_moved(ev.scenePos().y() - self.sceneBoundingRect().top())
            return
        if ev.isStart():
            self.panel.drag_started(self.mapSceneToView(ev.buttonDownScenePos()))
        self.panel.drag_moved(self.mapSceneToView(ev.scenePos()))
        if ev.isFinish():
            self.panel.drag_finished()


def _remembered_row_pixels() -> int:
    """The row height the user last chose (any session), within the allowed range."""
    try:
        pixels = int(settings().value(ROW_HEIGHT_KEY, ROW_PIXELS))
    except (TypeError, ValueError):
        pixels = ROW_PIXELS
    return min(max(pixels, ROW_PIXELS_RANGE[0]), ROW_PIXELS_RANGE[1])


class TimelinePanel(QWidget):
    def __init__(self, doc: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.edits = TimelineEdits(doc)
        self.player = Player(doc, self)
        self.selection: set[KeyRef] = set()
        self.clipboard: list[ClipKey] = []
        self.current_pose: str | None = None  # the pose last edited (row or slider): K keys it
        self.row_pixels = _remembered_row_pixels()
        self._drag: dict | None = None
        self._row_drag: float | None = None  # rows above the row edge being dragged
        self._updating = False
        self._framed: tuple[int, int] | None = None  # the frame range the time axis last fitted
        self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self._build()
        self._shortcuts()
        doc.timelineChanged.connect(self.refresh)
        doc.projectReplaced.connect(self._project_replaced)
        doc.playheadChanged.connect(self._show_playhead)
        doc.activationsChanged.connect(self._refresh_curves)
        doc.areasChanged.connect(self._refresh_curves)
        doc.posesChanged.connect(self._project_replaced)
        self.player.playingChanged.connect(self._show_playing)
        self._project_replaced()

    # --- layout --------------------------------------------------------------------------------
    def sizeHint(self) -> QSize:
        """A short strip under the viewport, from the window's first frame on."""
        return QSize(super().sizeHint().width(), PANEL_HEIGHT)

    def _build(self) -> None:
        """The controls on the left, the tracks above the curves on the right."""
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.setSpacing(2)
        self.rows = QScrollBar(Qt.Orientation.Vertical)
        self.rows.setToolTip("More key poses than rows fit: scroll them (Shift+wheel)")
        self.rows.hide()
        layout.addWidget(self._build_controls())
        layout.addWidget(self._build_graphs(), 1)
        layout.addWidget(self.rows)
        self.rows.valueChanged.connect(self._fit_rows)

    def _build_controls(self) -> QWidget:
        """Transport, frame, rate and range, the selected keys' mode and weight, curve mode."""
        controls = QVBoxLayout()
        controls.setSpacing(2)
        controls.setContentsMargins(0, 0, 0, 0)
        transport = QHBoxLayout()
        transport.setSpacing(2)
        self.buttons: dict[str, QToolButton] = {}
        for name, text, tip, slot in (
                ("start", "SP_MediaSkipBackward", "Jump to start (Home, Shift+Left)",
                 self.jump_start),
                ("back", "SP_MediaSeekBackward", "Previous frame (Left)", lambda: self.step(-1)),
                ("play", "SP_MediaPlay", "Play / pause (Space)", self.player.toggle),
                ("forward", "SP_MediaSeekForward", "Next frame (Right)", lambda: self.step(1)),
                ("end", "SP_MediaSkipForward", "Jump to end (End, Shift+Right)", self.jump_end)):
            button = QToolButton()
            button.setIcon(self._icon(text))
            button.setToolTip(tip)
            button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            button.clicked.connect(slot)
            button.setMinimumWidth(30)
            transport.addWidget(button)
            self.buttons[name] = button
        self.loop = QCheckBox("Loop")
        self.loop.setChecked(True)
        self.loop.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.loop.toggled.connect(lambda on: setattr(self.player, "loop", on))
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
        self.row_height.setValue(self.row_pixels)
        self.row_height.valueChanged.connect(self.set_row_pixels)
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
        self.fps.valueChanged.connect(lambda v: self._set_range(fps=v))
        self.start.valueChanged.connect(lambda v: self._set_range(start=v))
        self.end.valueChanged.connect(lambda v: self._set_range(end=v))
        form.addRow("Rate", self.fps)
        form.addRow("Frames", range_row)
        self.interpolation = QComboBox()
        for mode in INTERPOLATIONS:
            self.interpolation.addItem(INTERPOLATION_LABELS[mode], mode)
        self.interpolation.setToolTip("How the selected keys go on to the next key")
        self.interpolation.activated.connect(self._interpolation_chosen)
        self.key_value = QDoubleSpinBox()
        self.key_value.setRange(0.0, 1.0)
        self.key_value.setSingleStep(VALUE_SNAP)
        self.key_value.setKeyboardTracking(False)
        self.key_value.setToolTip("Weight of the selected keys (0 = neutral, 1 = the full pose)")
        self.key_value.valueChanged.connect(self._value_chosen)
        key_row = QHBoxLayout()
        key_row.addWidget(self.interpolation, 1)
        key_row.addWidget(self.key_value)
        form.addRow("Key", key_row)
        controls.addLayout(form)
        self.sequence = QPushButton("Sequence all poses")
        self.sequence.setToolTip("Replace the animation by neutral → pose → neutral for each "
                                 "key pose in turn (0.5 s up, 0.5 s hold, 0.5 s down)")
        self.sequence.clicked.connect(lambda: self.edits.sequence_all_poses())
        controls.addWidget(self.sequence)
        self.curve_mode = QComboBox()
        for text, mode in (("Curves: pose weights", "weights"),
                           ("Curves: area activations (t1)", "activations"),
                           ("Curves: both", "both")):
            self.curve_mode.addItem(text, mode)
        self.curve_mode.setCurrentIndex(2)
        self.curve_mode.currentIndexChanged.connect(self._refresh_curves)
        controls.addWidget(self.curve_mode)
        controls.addStretch(1)
        side = QWidget()
        side.setLayout(controls)
        # a short dock scrolls the controls rather than hiding the graphs
        scroll = QScrollArea()
        scroll.setWidget(side)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        scroll.setSizeAdjustPolicy(QAbstractScrollArea.SizeAdjustPolicy.AdjustIgnored)
        scroll.setFixedWidth(CONTROLS_WIDTH + scroll.verticalScrollBar().sizeHint().width())
        scroll.setMinimumHeight(0)
        return scroll

    def _build_graphs(self) -> pg.GraphicsLayoutWidget:
        """One graphics layout: the tracks above the curves, sharing the time axis; the legend
        sits in its own column so that it never hides a curve."""
        self.view = pg.GraphicsLayoutWidget()
        self.view.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.view.setToolTip("Click a row: add a key (its height is the weight) · drag a key: "
                             "move it · drag elsewhere, or on the ruler: scrub\nMouse over the "
                             "timeline: Space plays, K keys the last edited pose · Del · Ctrl+C/V"
                             " · wheel: zoom time · Shift+wheel: scroll rows")
        self.view.ci.setSpacing(2)
        self.ruler = self.view.addPlot(row=0, col=0, viewBox=ScrubViewBox(self))
        self.ruler.hideButtons()
        self.ruler.setMenuEnabled(False)
        self.ruler.hideAxis("bottom")
        self.ruler.showAxis("top")
        self.ruler.getAxis("top").setStyle(tickLength=-5)
        ruler_left = self.ruler.getAxis("left")
        ruler_left.setWidth(NAMES_PIXELS)
        ruler_left.setTicks([[], []])
        ruler_left.setPen(pg.mkPen(None))
        self.ruler.getViewBox().setBackgroundColor((38, 38, 44))
        self.ruler.setYRange(0, 1, padding=0)
        self.ruler.setFixedHeight(RULER_PIXELS)
        self.ruler.setToolTip("Click or drag on the ruler: move the playhead (scrub)")
        self.track_box = TrackViewBox(self)
        self.tracks = self.view.addPlot(row=1, col=0, viewBox=self.track_box)
        self.tracks.hideButtons()
        self.tracks.showGrid(x=True, y=False, alpha=0.15)
        names = self.tracks.getAxis("left")
        names.setWidth(NAMES_PIXELS)
        names.setCursor(Qt.CursorShape.SizeVerCursor)
        names.setToolTip("Drag up or down: the rows' height")
        self.tracks.hideAxis("bottom")  # the ruler above says the frames
        self.tracks.setMenuEnabled(False)
        self.track_box.sigResized.connect(self._fit_rows)
        self.curves = self.view.addPlot(row=2, col=0, viewBox=ScrubViewBox(self))
        self.curves.hideButtons()
        self.curves.showGrid(x=True, y=True, alpha=0.15)
        self.curves.getAxis("left").setWidth(NAMES_PIXELS)
        self.curves.hideAxis("bottom")
        self.curves.setToolTip("Pose weights (solid) and the area activations they drive "
                               "(dashed): click or drag to scrub")
        self.curves.setYRange(-0.05, 1.08, padding=0)
        self.curves.setMenuEnabled(False)
        self.curves.setXLink(self.tracks)
        self.ruler.setXLink(self.tracks)
        self.legend = pg.LegendItem(colCount=2, labelTextSize="7pt", verSpacing=-6)
        self.view.addItem(self.legend, row=1, col=1, rowspan=2)  # beside rows and curves
        self.view.ci.layout.setColumnFixedWidth(1, 230)
        self.view.ci.layout.setRowMinimumHeight(2, CURVES_PIXELS)
        self.curves.setMaximumHeight(CURVES_PIXELS)  # the rows get what the curves leave

        self.row_marker = pg.LinearRegionItem(orientation="horizontal", movable=False,
                                              brush=pg.mkBrush(255, 200, 40, 36),
                                              pen=pg.mkPen(255, 200, 40, 90))
        self.row_marker.setZValue(-25)
        self.tracks.addItem(self.row_marker)
        self.ruler_playhead = pg.InfiniteLine(angle=90, pen=pg.mkPen(255, 200, 40, width=2),
                                              label="{value:.0f}",
                                              labelOpts={"position": 0.5, "color": (20, 20, 20),
                                                         "fill": (255, 200, 40, 230)})
        self.ruler.addItem(self.ruler_playhead)
        self.range_region = pg.LinearRegionItem(movable=False, brush=pg.mkBrush(255, 255, 255, 12),
                                                pen=pg.mkPen(120, 120, 120, 160))
        self.range_region.setZValue(-20)
        self.tracks.addItem(self.range_region)
        self.playhead = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen(255, 200, 40, width=2),
                                        hoverPen=pg.mkPen(255, 230, 120, width=3))
        self.playhead.setZValue(30)
        self.playhead.sigPositionChanged.connect(self._playhead_dragged)
        self.tracks.addItem(self.playhead)
        self.curve_playhead = pg.InfiniteLine(angle=90, pen=pg.mkPen(255, 200, 40, width=1))
        self.curves.addItem(self.curve_playhead)
        self.keys_item = pg.ScatterPlotItem(symbol="d", size=13, pxMode=True)
        self.keys_item.setZValue(20)
        self.weight_label = pg.TextItem(color=(255, 230, 150), anchor=(-0.15, 1.0),
                                        fill=(20, 20, 24, 190))
        self.weight_label.setZValue(40)
        self.weight_label.hide()
        self.tracks.addItem(self.weight_label, ignoreBounds=True)
        self.tracks.addItem(self.keys_item)
        self.track_curves: dict[str, pg.PlotDataItem] = {}
        self._track_pool: list[pg.PlotDataItem] = []
        self._line_pool: list[pg.InfiniteLine] = []
        self._curve_pool: list[pg.PlotDataItem] = []
        self._legend_labels: list = []
        self._more = pg.PlotDataItem(pen=None)  # the legend's "+N more" line: no curve of its own
        self._retired: list = []
        return self.view

    def _icon(self, name: str) -> QIcon:
        return self.style().standardIcon(getattr(QStyle.StandardPixmap, name))

    def key_bindings(self) -> list[tuple[list[str], Callable[[], None], str]]:
        """The timeline's keys (Blender's dope sheet): one table for the focus shortcuts and
        the keys that act while the mouse is over the panel."""
        return [
            (["Space"], self.player.toggle, "Play / pause"),
            (["Left"], lambda: self.step(-1), "Previous frame"),
            (["Right"], lambda: self.step(1), "Next frame"),
            (["Home", "Shift+Left"], self.jump_start, "Jump to start"),
            (["End", "Shift+Right"], self.jump_end, "Jump to end"),
            (["Delete", "Backspace", "X"], self.delete_selected, "Delete keys"),
            (["Ctrl+C"], self.copy_selected, "Copy keys"),
            (["Ctrl+V"], self.paste, "Paste keys at the playhead"),
            (["K"], self.key_current_pose, "Key the pose weight at the playhead"),
            (["Escape"], lambda: self._select(set()), "Deselect keys"),
        ]

    def hover_keys(self) -> dict[str, Callable[[], None]]:
        """Every key of :meth:`key_bindings` by its sequence, for ``HoverKeys.add``."""
        return {key: slot for keys, slot, _ in self.key_bindings() for key in keys}

    def _shortcuts(self) -> None:
        """Keys that work while the timeline (or a child of it) has the focus."""
        for keys, slot, text in self.key_bindings():
            action = QAction(text, self)
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.triggered.connect(slot)
            self.addAction(action)

    # --- geometry of the rows ------------------------------------------------------------------
    @property
    def poses(self) -> list[str]:
        return [p.name for p in self.doc.project.poses]

    def row_of(self, pose: str) -> int:
        """Row index from the bottom (the first pose is the top row)."""
        return len(self.poses) - 1 - self.poses.index(pose)

    def key_y(self, pose: str, value: float) -> float:
        return self.row_of(pose) + ROW_PAD + ROW_BAND * value

    def pose_at(self, y: float) -> str | None:
        row = int(np.floor(y))
        poses = self.poses
        if not 0 <= row < len(poses):
            return None
        return poses[len(poses) - 1 - row]

    def value_at_y(self, y: float) -> float:
        """The weight a click at height ``y`` means: 0.05 steps, with the baseline (0) and the
        top (1) a few pixels wide, so a click on the drawn baseline is 0 at any row height."""
        value = (y - np.floor(y) - ROW_PAD) / ROW_BAND
        snap = SNAP_PIXELS / (self.row_pixels * ROW_BAND)
        value = 0.0 if value < snap else 1.0 if value > 1 - snap else value
        return float(np.clip(np.round(value / VALUE_SNAP) * VALUE_SNAP, 0.0, 1.0))

    def key_scene_pos(self, pose: str, frame: float, value: float) -> QPointF:
        """Where a key is drawn, in scene coordinates (for hit tests and for tests)."""
        return self.track_box.mapViewToScene(QPointF(frame, self.key_y(pose, value)))

    def key_widget_pos(self, pose: str, frame: float, value: float):
        """Where a key is drawn, in the track view's widget pixels."""
        return self.view.mapFromScene(self.key_scene_pos(pose, frame, value))

    def key_at(self, pos: QPointF) -> KeyRef | None:
        """The key under a point (view coordinates), within a few pixels."""
        target = self.track_box.mapViewToScene(pos)
        best, best_d = None, HIT_PIXELS
        state = TimelineState.of(self.doc.project.timeline)
        for pose, keys in state.tracks:
            if pose not in self.poses:
                continue
            for i, (frame, value, _) in enumerate(keys):
                p = self.key_scene_pos(pose, frame, value)
                d = float(np.hypot(p.x() - target.x(), p.y() - target.y()))
                if d <= best_d:
                    best, best_d = (pose, i), d
        return best

    # --- refresh -------------------------------------------------------------------------------
    def _pooled(self, pool: list, count: int, make: Callable[[], object]) -> list:
        """``count`` graphics items from ``pool``, made as needed; the rest hidden.

        Why a pool: removing pyqtgraph items from a scene while Qt is delivering a mouse event
        to it can crash PySide; reusing and hiding items never removes any."""
        while len(pool) < count:
            pool.append(make())
        for i, item in enumerate(pool):
            item.setVisible(i < count)
        return pool[:count]

    def _project_replaced(self) -> None:
        self.selection = set()
        self.set_current_pose(self.poses[0] if self.poses else None)
        poses = self.poses

        def make_curve() -> pg.PlotDataItem:
            curve = pg.PlotDataItem()
            self.tracks.addItem(curve)
            return curve

        def make_line() -> pg.InfiniteLine:
            line = pg.InfiniteLine(angle=0, pen=pg.mkPen(90, 90, 96, 150))
            self.tracks.addItem(line)
            return line

        curves = self._pooled(self._track_pool, len(poses), make_curve)
        lines = self._pooled(self._line_pool, len(poses), make_line)
        self.track_curves = {}
        for i, (pose, curve, line) in enumerate(zip(poses, curves, lines, strict=True)):
            colour = pose_colour(i, len(poses))
            fill = QColor(colour)
            fill.setAlpha(55)
            row = self.row_of(pose)
            curve.setData([], [])
            curve.setPen(pg.mkPen(colour, width=1.5))
            curve.setBrush(pg.mkBrush(fill))
            curve.setFillLevel(row + ROW_PAD)
            self.track_curves[pose] = curve
            line.setValue(row + ROW_PAD)  # the baseline: weight 0
        self._rows_at_least()
        self._name_rows()
        self.rows.setValue(0)
        self._fit_rows()
        self.refresh()
        self.frame_all_time()

    def _rows_at_least(self) -> None:
        """A few rows on screen however short the dock (the rest scroll), the curves below."""
        count = min(max(len(self.poses), 1), ROWS_AT_LEAST)
        self.view.ci.layout.setRowMinimumHeight(1, self.row_pixels * count + 4)

    def _fit_rows(self) -> None:
        """Rows exactly ``row_pixels`` tall from the scroll bar's row down (empty space below
        the last, as in Blender's dope sheet); the bar shows only when some rows do not fit."""
        count = max(len(self.poses), 1)
        shown = max(self.track_box.height() / self.row_pixels, 1.0)  # rows' worth of height
        fit = max(int(shown), 1)
        top = 0
        if fit >= count:
            self.rows.setVisible(False)
        else:
            blocker = QSignalBlocker(self.rows)
            self.rows.setRange(0, count - fit)
            self.rows.setPageStep(fit)
            del blocker
            self.rows.setVisible(True)
            top = self.rows.value()  # rows hidden above
        self.tracks.setYRange(count - top - shown, count - top, padding=0)

    def set_row_pixels(self, pixels: int) -> None:
        """The rows' height (a view preference, not an edit: remembered, not undone)."""
        pixels = min(max(int(pixels), ROW_PIXELS_RANGE[0]), ROW_PIXELS_RANGE[1])
        if pixels == self.row_pixels:
            return
        self.row_pixels = pixels
        settings().setValue(ROW_HEIGHT_KEY, pixels)
        with QSignalBlocker(self.row_height):
            self.row_height.setValue(pixels)
        self._rows_at_least()
        self._fit_rows()

    def row_drag_started(self, y: float) -> None:
        """A press in the names' column takes the row edge nearest it."""
        top = self.track_box.viewRange()[1][1]
        self._row_drag = max(top - round(y), 1.0)

    def row_drag_moved(self, pixels_below_top: float) -> None:
        """The taken edge follows the pointer: the rows above it share its distance from the
        top of the rows."""
        if self._row_drag:
            self.set_row_pixels(round(pixels_below_top / self._row_drag))

    def visible_rows(self) -> list[str]:
        """The poses whose track rows are on screen, top first."""
        lo, hi = self.track_box.viewRange()[1]
        return [p for p in self.poses if lo - 1e-6 <= self.row_of(p) and self.row_of(p) + 1
                <= hi + 1e-6]

    def frame_all_time(self) -> None:
        """Fit the time axis to the frame range (and every key beyond it)."""
        timeline = self.doc.project.timeline
        frames = [k.frame for t in timeline.tracks for k in t.keys]
        lo, hi = min([timeline.start, *frames]), max([timeline.end, *frames])
        span = max(hi - lo, 1)
        margin = max(0.02 * span, 1.0)
        # panning and zooming stop at the first frame: nothing is ever before it
        self.track_box.setLimits(xMin=lo - margin)
        self.tracks.setXRange(lo - margin, hi + margin, padding=0)
        self._framed = (timeline.start, timeline.end)

    def _follow_playhead(self) -> None:
        """Page the time axis when the playhead leaves it (playing, stepping, jumping), so
        that the playhead is always on screen."""
        lo, hi = self.track_box.viewRange()[0]
        frame = self.doc.frame
        if lo <= frame <= hi:
            return
        span = hi - lo
        start = frame - FOLLOW_MARGIN * span
        self.tracks.setXRange(start, start + span, padding=0)

    def refresh(self) -> None:
        """Redraw keys, curves and controls from the timeline (after any edit or undo)."""
        timeline = self.doc.project.timeline
        self._updating = True
        try:
            self.fps.setValue(timeline.fps)
            self.start.setValue(timeline.start)
            self.end.setValue(timeline.end)
        finally:
            self._updating = False
        self.range_region.setRegion((timeline.start, timeline.end))
        if self._framed is not None and self._framed != (timeline.start, timeline.end):
            self.frame_all_time()  # a new range (sequencing, a capture, typed): show it all
        state = TimelineState.of(timeline)
        self.selection = {(p, i) for p, i in self.selection if i < len(state.keys(p))}
        frames = self._sample_frames()
        poses = self.poses
        spots = []
        for pose, keys in state.tracks:
            if pose not in self.track_curves:
                continue
            colour = pose_colour(poses.index(pose), len(poses))
            track = timeline.track(pose)
            values = track.values_at(frames) if keys else np.zeros_like(frames)
            self.track_curves[pose].setData(frames, self.row_of(pose) + ROW_PAD
                                            + ROW_BAND * values)
            for i, (frame, value, mode) in enumerate(keys):
                selected = (pose, i) in self.selection
                spots.append({"pos": (frame, self.key_y(pose, value)), "data": (pose, i),
                              "brush": pg.mkBrush("w" if selected else colour),
                              "pen": pg.mkPen((255, 200, 40) if selected else (20, 20, 20),
                                              width=2 if selected else 1),
                              "symbol": "s" if mode == "constant" else "d",
                              "size": 15 if selected else 12})
        for pose in self.track_curves:
            if not state.keys(pose):
                self.track_curves[pose].setData([], [])
        self.keys_item.setData(spots)
        self._show_selection()
        self._refresh_curves()
        self._show_playhead()

    def _sample_frames(self) -> np.ndarray:
        timeline = self.doc.project.timeline
        frames = [k.frame for t in timeline.tracks for k in t.keys]
        lo = min([timeline.start, *frames]) - 10
        hi = max([timeline.end, *frames]) + 10
        return np.linspace(lo, hi, int(min((hi - lo) * 4, 4000)) + 2)

    def _refresh_curves(self) -> None:
        mode = self.curve_mode.currentData()
        frames = self._sample_frames()
        project = self.doc.project
        animated, act = activation_curves(project, frames, self.doc.pose_weights)
        poses = self.poses
        shown: list[tuple[np.ndarray, object, str]] = []  # values, pen, legend label
        if mode in ("weights", "both"):
            for pose, values in animated.items():
                if pose in poses:
                    colour = pose_colour(poses.index(pose), len(poses))
                    shown.append((values, pg.mkPen(colour, width=2), pose_label(pose)))
        if mode in ("activations", "both"):
            style = Qt.PenStyle.DashLine if mode == "both" else Qt.PenStyle.SolidLine
            for i, area in enumerate(project.influence.areas):
                if act[:, i].any():
                    shown.append((act[:, i], pg.mkPen(area.colour, width=1.5, style=style),
                                  area.name))

        def make() -> pg.PlotDataItem:
            curve = pg.PlotDataItem()
            self.curves.addItem(curve)
            return curve

        curves = self._pooled(self._curve_pool, len(shown), make)
        for curve, (values, pen, _) in zip(curves, shown, strict=True):
            curve.setData(frames, values)
            curve.setPen(pen)
        labels = [(label, pen.color().name(), pen.style()) for _, pen, label in shown]
        if labels != self._legend_labels:  # rebuilt only when what is shown changes
            self._legend_labels = labels
            self._retired.extend(self.legend.items)  # keep Python wrappers alive (see _pooled)
            self.legend.clear()
            listed = len(shown) if len(shown) <= LEGEND_ENTRIES else LEGEND_ENTRIES - 1
            for curve, (_, _, label) in zip(curves[:listed], shown[:listed], strict=True):
                self.legend.addItem(curve, label)
            if listed < len(shown):  # a legend taller than the plot would push it off screen
                self.legend.addItem(self._more, f"+{len(shown) - listed} more")

    def _show_selection(self) -> None:
        state = TimelineState.of(self.doc.project.timeline)
        keys = [state.keys(p)[i] for p, i in sorted(self.selection)]
        enabled = bool(keys)
        self.interpolation.setEnabled(enabled)
        self.key_value.setEnabled(enabled)
        self._updating = True
        try:
            if not keys:
                self.interpolation.setCurrentIndex(-1)
            else:
                modes = {k[2] for k in keys}
                self.interpolation.setCurrentIndex(
                    INTERPOLATIONS.index(modes.pop()) if len(modes) == 1 else -1)
                self.key_value.setValue(keys[0][1])
        finally:
            self._updating = False

    def _show_playhead(self) -> None:
        frame = self.doc.frame
        timeline = self.doc.project.timeline
        self._updating = True
        try:
            self.playhead.setValue(frame)
            self.curve_playhead.setValue(frame)
            self.ruler_playhead.setValue(frame)
        finally:
            self._updating = False
        self._follow_playhead()
        seconds = (frame - timeline.start) / timeline.fps
        self.frame_label.setText(f"Frame {frame:.0f}   ·   {seconds:.2f} s")

    def _show_playing(self, playing: bool) -> None:
        self.buttons["play"].setIcon(self._icon("SP_MediaPause" if playing else "SP_MediaPlay"))

    # --- transport -----------------------------------------------------------------------------
    def step(self, frames: int) -> None:
        self.player.stop()
        timeline = self.doc.project.timeline
        frame = min(max(round(self.doc.frame) + frames, timeline.start), timeline.end)
        self.doc.show_frame(frame)

    def jump_start(self) -> None:
        self.player.stop()
        self.doc.show_frame(self.doc.project.timeline.start)

    def jump_end(self) -> None:
        self.player.stop()
        self.doc.show_frame(self.doc.project.timeline.end)

    def scrub_to(self, x: float) -> None:
        """Move the playhead to the whole frame nearest ``x``, within the frame range."""
        timeline = self.doc.project.timeline
        frame = min(max(round(x), timeline.start), timeline.end)
        if frame != self.doc.frame:
            self.doc.show_frame(frame)

    def _playhead_dragged(self) -> None:
        if self._updating:
            return
        frame = round(self.playhead.value())
        if frame != self.doc.frame:
            self.doc.show_frame(frame)
        else:
            self._show_playhead()  # snap the line to the whole frame

    # --- key editing ---------------------------------------------------------------------------
    def _select(self, refs: set[KeyRef]) -> None:
        self.selection = set(refs)
        self.refresh()

    def track_clicked(self, pos: QPointF, modifiers) -> None:
        """Click on a key: select it (Ctrl/Shift: add to the selection). Elsewhere in a row: a
        new key at that frame, its weight set by the height in the row."""
        self.view.setFocus()
        hit = self.key_at(pos)
        if hit is not None:
            self.set_current_pose(hit[0])
            extend = modifiers & (Qt.KeyboardModifier.ControlModifier
                                  | Qt.KeyboardModifier.ShiftModifier)
            if extend:
                self._select(self.selection ^ {hit})
            else:
                self._select({hit})
            return
        pose = self.pose_at(pos.y())
        if pose is None:
            self._select(set())
            return
        self.set_current_pose(pose)
        ref = self.edits.add_key(pose, float(round(pos.x())), self.value_at_y(pos.y()))
        self._select({ref})

    def show_weight_under(self, pos: QPointF | None) -> None:
        """Beside the pointer in a row: the frame and weight a click there would key (nothing
        over a key, which a click selects, or outside the rows)."""
        pose = None if pos is None or self._drag else self.pose_at(pos.y())
        if pose is None or self.key_at(pos) is not None:
            self.weight_label.hide()
            return
        self.weight_label.setText(f"{round(pos.x())}: {self.value_at_y(pos.y()):.2f}")
        self.weight_label.setPos(pos)
        self.weight_label.show()

    def drag_started(self, pos: QPointF) -> None:
        self.view.setFocus()
        hit = self.key_at(pos)
        if hit is None:
            self.player.stop()
            self._drag = {"scrub": True}
            return
        if hit not in self.selection:
            self._select({hit})
        self.set_current_pose(hit[0])
        self._drag = {"scrub": False, "origin": pos, "base": self.edits.state(),
                      "refs": sorted(self.selection), "gesture": new_gesture(), "axis": None}

    def drag_moved(self, pos: QPointF) -> None:
        drag = self._drag
        if drag is None:
            return
        if drag["scrub"]:
            self.scrub_to(pos.x())
            return
        origin = drag["origin"]
        dframe = float(round(pos.x() - origin.x()))
        dvalue = float(np.round((pos.y() - origin.y()) / ROW_BAND / VALUE_SNAP) * VALUE_SNAP)
        if drag["axis"] is None:  # the first clear movement picks time or weight
            a, b = self.track_box.mapViewToScene(origin), self.track_box.mapViewToScene(pos)
            dx, dy = abs(b.x() - a.x()), abs(b.y() - a.y())
            if max(dx, dy) < 4:
                return
            drag["axis"] = "time" if dx >= dy else "value"
        if drag["axis"] == "time":
            dvalue = 0.0
        else:
            dframe = 0.0
        self.selection = set(self.edits.move_keys(drag["base"], drag["refs"], dframe, dvalue,
                                                  drag["gesture"]))
        self.refresh()

    def drag_finished(self) -> None:
        self._drag = None

    def delete_selected(self) -> None:
        if self.selection:
            refs, self.selection = self.selection, set()
            self.edits.delete_keys(refs)

    def copy_selected(self) -> None:
        self.clipboard = self.edits.copy_keys(sorted(self.selection))

    def paste(self) -> None:
        if self.clipboard:
            self._select(set(self.edits.paste_keys(self.clipboard, round(self.doc.frame))))

    def set_current_pose(self, pose: str | None) -> None:
        """The pose K keys (the last edited, in a row or on its Poses slider), marked by a band
        across its row and its row scrolled into view."""
        self.current_pose = pose if pose in self.poses else None
        self._name_rows()
        if self.current_pose is None:
            self.row_marker.setVisible(False)
            return
        row = self.row_of(self.current_pose)
        self.row_marker.setRegion((row, row + 1))
        self.row_marker.setVisible(True)
        if self.rows.isVisible():
            index = self.poses.index(self.current_pose)
            top, fit = self.rows.value(), self.rows.pageStep()
            if not top <= index < top + fit:
                self.rows.setValue(min(index, self.rows.maximum()))

    def _name_rows(self) -> None:
        """Each row's pose name in the names' column; the current row's with a pointer."""
        self.tracks.getAxis("left").setTicks([[
            (self.row_of(p) + 0.5, ("▸ " if p == self.current_pose else "") + pose_label(p))
            for p in self.poses], []])

    def key_current_pose(self) -> None:
        """K: key the last edited pose at the playhead with the weight it has now (the slider's
        value), and say so in the status bar, since the row may be scrolled out of view."""
        pose = self.current_pose
        if pose is None:
            return
        value = self.doc.pose_weights.get(pose, 0.0)
        frame = float(round(self.doc.frame))
        self._select({self.edits.add_key(pose, frame, value)})
        self.set_current_pose(pose)
        self.say(f"Keyed {pose_label(pose)} at frame {frame:g}: weight {value:.2f}")

    def say(self, text: str) -> None:
        """A line in the main window's status bar (nothing when the panel stands alone)."""
        bar = getattr(self.window(), "statusBar", None)
        if callable(bar):
            bar().showMessage(text, SAY_MS)

    def _interpolation_chosen(self, index: int) -> None:
        if self.selection and index >= 0:
            self.edits.set_interpolation(sorted(self.selection), INTERPOLATIONS[index])

    def _value_chosen(self, value: float) -> None:
        if not self._updating and self.selection:
            self.edits.set_value(sorted(self.selection), value)

    def _set_range(self, **changes) -> None:
        if self._updating:
            return
        if not self.edits.set_range(**changes):
            self.refresh()  # refused (end before start): show the timeline as it is
