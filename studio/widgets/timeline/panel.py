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
from PySide6.QtGui import QAction, QIcon, QKeySequence
from PySide6.QtWidgets import QHBoxLayout, QScrollBar, QStyle, QWidget

from studio.core.animation.timeline import INTERPOLATIONS
from studio.widgets.app_settings import settings
from studio.widgets.commands import new_gesture
from studio.widgets.document import Document
from studio.widgets.timeline.controls import TimelineControls
from studio.widgets.timeline.edits import ClipKey, KeyRef, TimelineEdits, TimelineState
from studio.widgets.timeline.graphs import TimelineGraphs
from studio.widgets.timeline.playback import Player
from studio.widgets.timeline.pose_panel import pose_label
from studio.widgets.timeline.track_model import (  # noqa: F401  (ROW_BAND, ROW_PAD: for tests)
    ROW_BAND,
    ROW_PAD,
    ROW_PIXELS,
    TrackRows,
    activation_curves,
    clamp_row_pixels,
    clicked_selection,
    drag_axis,
    drag_offset,
    frame_in_range,
    frame_text,
    framed_time,
    key_marks,
    paged_start,
    sample_frames,
    shared_interpolation,
)

HIT_PIXELS = 8.0
PANEL_HEIGHT = 176  # pixels the timeline asks for: its dock is then about 200 high
ROW_HEIGHT_KEY = "timeline/row_pixels"  # where the chosen height is remembered
SAY_MS = 10000  # "Keyed …" stays long enough to read, whatever else redraws meanwhile
ROWS_AT_LEAST = 2  # rows kept on screen however short the dock; the rest scroll


def _remembered_row_pixels() -> int:
    """The row height the user last chose (any session), within the allowed range."""
    try:
        return clamp_row_pixels(int(settings().value(ROW_HEIGHT_KEY, ROW_PIXELS)))
    except (TypeError, ValueError):
        return ROW_PIXELS


class TimelinePanel(QWidget):
    """The view of the timeline: draws ``TrackRows`` and the document's timeline, and turns
    clicks, drags and keys into ``TimelineEdits`` and playhead moves."""

    def __init__(self, doc: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.edits = TimelineEdits(doc)
        self.player = Player(doc, self)
        self._row_pixels = _remembered_row_pixels()
        self.selection: set[KeyRef] = set()
        self.clipboard: list[ClipKey] = []
        self.current_pose: str | None = None  # the pose last edited (row or slider): K keys it
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
        doc.activationsChanged.connect(self.refresh_curves)
        doc.areasChanged.connect(self.refresh_curves)
        doc.posesChanged.connect(self._project_replaced)
        self.player.playingChanged.connect(self._show_playing)
        self._project_replaced()

    # --- layout --------------------------------------------------------------------------------
    def sizeHint(self) -> QSize:
        """A short strip under the viewport, from the window's first frame on."""
        return QSize(super().sizeHint().width(), PANEL_HEIGHT)

    def _build(self) -> None:
        """The controls on the left, the tracks above the curves on the right; the parts other
        modules and tests reach are named on the panel."""
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.setSpacing(2)
        self.rows = QScrollBar(Qt.Orientation.Vertical)
        self.rows.setToolTip("More key poses than rows fit: scroll them (Shift+wheel)")
        self.rows.hide()
        self.controls = controls = TimelineControls(self)
        self.view = view = TimelineGraphs(self)
        layout.addWidget(controls)
        layout.addWidget(view, 1)
        layout.addWidget(self.rows)
        self.rows.valueChanged.connect(self._fit_rows)
        self.buttons, self.loop, self.frame_label = (controls.buttons, controls.loop,
                                                     controls.frame_label)
        self.row_height, self.fps, self.start, self.end = (controls.row_height, controls.fps,
                                                           controls.start, controls.end)
        self.interpolation, self.key_value = controls.interpolation, controls.key_value
        self.sequence, self.curve_mode = controls.sequence, controls.curve_mode
        self.ruler, self.tracks, self.curves = view.ruler, view.tracks, view.curves
        self.track_box, self.legend, self.keys_item = view.track_box, view.legend, view.keys_item
        self.playhead, self.curve_playhead = view.playhead, view.curve_playhead
        self.ruler_playhead, self.range_region = view.ruler_playhead, view.range_region
        self.row_marker, self.weight_label = view.row_marker, view.weight_label
        self.track_box.sigResized.connect(self._fit_rows)
        self.playhead.sigPositionChanged.connect(self._playhead_dragged)

    @property
    def track_curves(self) -> dict[str, pg.PlotDataItem]:
        return self.view.track_curves

    @property
    def row_pixels(self) -> int:
        return self._row_pixels

    @property
    def model(self) -> TrackRows:
        """The rows as they are now: the document's poses at the chosen height."""
        return TrackRows(self.poses, self._row_pixels)

    def icon(self, name: str) -> QIcon:
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

    # --- geometry of the rows (the model's, in the track view) ---------------------------------
    @property
    def poses(self) -> list[str]:
        return [p.name for p in self.doc.project.poses]

    def row_of(self, pose: str) -> int:
        """Row index from the bottom (the first pose is the top row)."""
        return self.model.row_of(pose)

    def key_scene_pos(self, pose: str, frame: float, value: float) -> QPointF:
        """Where a key is drawn, in scene coordinates (for hit tests and for tests)."""
        return self.track_box.mapViewToScene(QPointF(frame, self.model.key_y(pose, value)))

    def key_widget_pos(self, pose: str, frame: float, value: float):
        """Where a key is drawn, in the track view's widget pixels."""
        return self.view.mapFromScene(self.key_scene_pos(pose, frame, value))

    def key_at(self, pos: QPointF) -> KeyRef | None:
        """The key under a point (view coordinates), within a few pixels on screen."""
        target = self.track_box.mapViewToScene(pos)
        best, best_d = None, HIT_PIXELS
        state = TimelineState.of(self.doc.project.timeline)
        for mark in key_marks(state.tracks, self.model, set()):
            p = self.track_box.mapViewToScene(QPointF(mark.frame, mark.y))
            d = float(np.hypot(p.x() - target.x(), p.y() - target.y()))
            if d <= best_d:
                best, best_d = mark.ref, d
        return best

    def visible_rows(self) -> list[str]:
        """The poses whose track rows are on screen, top first."""
        return self.model.visible(*self.track_box.viewRange()[1])

    # --- rows ----------------------------------------------------------------------------------
    def _project_replaced(self) -> None:
        self.selection = set()
        self.view.show_rows(self.model)
        self.set_current_pose(self.poses[0] if self.poses else None)
        self._rows_at_least()
        self.rows.setValue(0)
        self._fit_rows()
        self.refresh()
        self.frame_all_time()

    def _rows_at_least(self) -> None:
        """A few rows on screen however short the dock (the rest scroll), the curves below."""
        count = min(max(len(self.poses), 1), ROWS_AT_LEAST)
        self.view.rows_at_least(self.row_pixels * count + 4)

    def _fit_rows(self) -> None:
        """Rows exactly ``row_pixels`` tall from the scroll bar's row down; the bar shows only
        when some rows do not fit."""
        fit, shown = self.model.fit(self.track_box.height())
        count = max(len(self.model.poses), 1)
        top = 0
        if fit >= count:
            self.rows.setVisible(False)
        else:
            with QSignalBlocker(self.rows):
                self.rows.setRange(0, count - fit)
                self.rows.setPageStep(fit)
            self.rows.setVisible(True)
            top = self.rows.value()  # rows hidden above
        self.tracks.setYRange(*self.model.shown_heights(shown, top), padding=0)

    def set_row_pixels(self, pixels: int) -> None:
        """The rows' height (a view preference, not an edit: remembered, not undone)."""
        pixels = clamp_row_pixels(pixels)
        if pixels == self.row_pixels:
            return
        self._row_pixels = pixels
        settings().setValue(ROW_HEIGHT_KEY, pixels)
        with QSignalBlocker(self.row_height):
            self.row_height.setValue(pixels)
        self._rows_at_least()
        self._fit_rows()

    def row_drag_started(self, y: float) -> None:
        """A press in the names' column takes the row edge nearest it."""
        self._row_drag = self.model.row_drag_rows(self.track_box.viewRange()[1][1], y)

    def row_drag_moved(self, pixels_below_top: float) -> None:
        """The taken edge follows the pointer: the rows above it share its distance from the
        top of the rows."""
        if self._row_drag:
            self.set_row_pixels(round(pixels_below_top / self._row_drag))

    # --- drawing -------------------------------------------------------------------------------
    def frame_all_time(self) -> None:
        """Fit the time axis to the frame range (and every key beyond it)."""
        timeline = self.doc.project.timeline
        lo, hi = framed_time(timeline)
        self.view.set_time(lo, hi, first=lo)
        self._framed = (timeline.start, timeline.end)

    def _follow_playhead(self) -> None:
        """Page the time axis when the playhead leaves it, so that it is always on screen."""
        lo, hi = self.track_box.viewRange()[0]
        start = paged_start(lo, hi, self.doc.frame)
        if start is not None:
            self.view.set_time(start, start + hi - lo)

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
        frames = sample_frames(timeline)
        for pose in self.track_curves:
            values = timeline.track(pose).values_at(frames) if state.keys(pose) else None
            self.view.show_track(self.model, pose, frames, values)
        self.view.show_keys(key_marks(state.tracks, self.model, self.selection), self.poses)
        self._show_selection()
        self.refresh_curves()
        self._show_playhead()

    def refresh_curves(self) -> None:
        """The curves the mode asks for: pose weights, the area activations they drive, or
        both (activations dashed)."""
        project = self.doc.project
        frames = sample_frames(project.timeline)
        animated, act = activation_curves(project, frames, self.doc.pose_weights)
        self.view.show_activity(self.curve_mode.currentData(), frames, animated, act,
                                self.poses, project.influence.areas)

    def _show_selection(self) -> None:
        state = TimelineState.of(self.doc.project.timeline)
        keys = [state.keys(p)[i] for p, i in sorted(self.selection)]
        self.interpolation.setEnabled(bool(keys))
        self.key_value.setEnabled(bool(keys))
        self._updating = True
        try:
            self.interpolation.setCurrentIndex(shared_interpolation(keys) if keys else -1)
            if keys:
                self.key_value.setValue(keys[0][1])
        finally:
            self._updating = False

    def _show_playhead(self) -> None:
        frame = self.doc.frame
        self._updating = True
        try:
            self.view.show_playhead(frame)
        finally:
            self._updating = False
        self._follow_playhead()
        self.frame_label.setText(frame_text(self.doc.project.timeline, frame))

    def _show_playing(self, playing: bool) -> None:
        self.buttons["play"].setIcon(self.icon("SP_MediaPause" if playing else "SP_MediaPlay"))

    # --- transport -----------------------------------------------------------------------------
    def step(self, frames: int) -> None:
        self.player.stop()
        self.doc.show_frame(frame_in_range(self.doc.project.timeline,
                                           round(self.doc.frame) + frames))

    def jump_start(self) -> None:
        self.player.stop()
        self.doc.show_frame(self.doc.project.timeline.start)

    def jump_end(self) -> None:
        self.player.stop()
        self.doc.show_frame(self.doc.project.timeline.end)

    def scrub_to(self, x: float) -> None:
        """Move the playhead to the whole frame nearest ``x``, within the frame range."""
        frame = frame_in_range(self.doc.project.timeline, x)
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
            self._select(clicked_selection(self.selection, hit, bool(extend)))
            return
        pose = self.model.pose_at(pos.y())
        if pose is None:
            self._select(set())
            return
        self.set_current_pose(pose)
        ref = self.edits.add_key(pose, float(round(pos.x())), self.model.value_at_y(pos.y()))
        self._select({ref})

    def show_weight_under(self, pos: QPointF | None) -> None:
        """Beside the pointer in a row: the frame and weight a click there would key (nothing
        over a key, which a click selects, or outside the rows)."""
        pose = None if pos is None or self._drag else self.model.pose_at(pos.y())
        if pose is None or self.key_at(pos) is not None:
            self.weight_label.hide()
            return
        self.weight_label.setText(f"{round(pos.x())}: {self.model.value_at_y(pos.y()):.2f}")
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
        if drag["axis"] is None:  # the first clear movement picks time or weight
            a, b = self.track_box.mapViewToScene(origin), self.track_box.mapViewToScene(pos)
            drag["axis"] = drag_axis(abs(b.x() - a.x()), abs(b.y() - a.y()))
            if drag["axis"] is None:
                return
        dframe, dvalue = drag_offset(drag["axis"], pos.x() - origin.x(), pos.y() - origin.y())
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
        self.view.name_rows(self.model, self.current_pose, pose_label)
        if self.current_pose is None:
            self.row_marker.setVisible(False)
            return
        row = self.row_of(self.current_pose)
        self.row_marker.setRegion((row, row + 1))
        self.row_marker.setVisible(True)
        if self.rows.isVisible():
            self.rows.setValue(self.model.scrolled_to(self.current_pose, self.rows.value(),
                                                      self.rows.pageStep(),
                                                      self.rows.maximum()))

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

    def interpolation_chosen(self, index: int) -> None:
        if self.selection and index >= 0:
            self.edits.set_interpolation(sorted(self.selection), INTERPOLATIONS[index])

    def value_chosen(self, value: float) -> None:
        if not self._updating and self.selection:
            self.edits.set_value(sorted(self.selection), value)

    def set_range(self, **changes) -> None:
        if self._updating:
            return
        if not self.edits.set_range(**changes):
            self.refresh()  # refused (end before start): show the timeline as it is
