"""The timeline's graphs: the ruler, the track rows and the curves, sharing one time axis, and
the legend in its own column so that it never hides a curve.

Why their own module: the panel decides what is shown (``track_model``); this draws it, reusing
pyqtgraph items rather than removing them (see :func:`pooled`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtGui import QColor

from studio.widgets.timeline.pose_panel import pose_label
from studio.widgets.timeline.track_model import ROW_BAND, ROW_PAD, KeyMark, TrackRows
from studio.widgets.timeline.view_boxes import ScrubViewBox, TrackViewBox

if TYPE_CHECKING:
    from studio.widgets.timeline.host import TimelineHost

NAMES_PIXELS = 130  # the names' column (the current row's name has a pointer before it)
RULER_PIXELS = 36  # the time ruler's height: its frame numbers, and the playhead's
LEGEND_ENTRIES = 10  # curves the legend names (two columns), so it stays as short as the plot
CURVES_PIXELS = 48  # the curve plot's height (the ruler says its frames)
SELECTED = (255, 200, 40)

Curve = tuple[np.ndarray, object, str]  # values, pen, legend label


def pose_colour(index: int, count: int) -> QColor:
    return pg.intColor(index, hues=max(count, 1), values=1, maxValue=230, minValue=230,
                       sat=170)


def pooled(pool: list, count: int, make: Callable[[], object]) -> list:
    """``count`` graphics items from ``pool``, made as needed; the rest hidden.

    Why a pool: removing pyqtgraph items from a scene while Qt is delivering a mouse event
    to it can crash PySide; reusing and hiding items never removes any."""
    while len(pool) < count:
        pool.append(make())
    for i, item in enumerate(pool):
        item.setVisible(i < count)
    return pool[:count]


class TimelineGraphs(pg.GraphicsLayoutWidget):
    """The ruler above the track rows above the curves; the legend beside rows and curves."""

    def __init__(self, panel: TimelineHost) -> None:
        super().__init__()
        self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.setToolTip("Click a row: add a key (its height is the weight) · drag a key: "
                             "move it · drag elsewhere, or on the ruler: scrub\nMouse over the "
                             "timeline: Space plays, K keys the last edited pose · Del · Ctrl+C/V"
                             " · wheel: zoom time · Shift+wheel: scroll rows")
        self.ci.setSpacing(2)
        self.ruler = self.addPlot(row=0, col=0, viewBox=ScrubViewBox(panel))
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
        self.track_box = TrackViewBox(panel)
        self.tracks = self.addPlot(row=1, col=0, viewBox=self.track_box)
        self.tracks.hideButtons()
        self.tracks.showGrid(x=True, y=False, alpha=0.15)
        names = self.tracks.getAxis("left")
        names.setWidth(NAMES_PIXELS)
        names.setCursor(Qt.CursorShape.SizeVerCursor)
        names.setToolTip("Drag up or down: the rows' height")
        self.tracks.hideAxis("bottom")  # the ruler above says the frames
        self.tracks.setMenuEnabled(False)
        self.curves = self.addPlot(row=2, col=0, viewBox=ScrubViewBox(panel))
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
        self.addItem(self.legend, row=1, col=1, rowspan=2)  # beside rows and curves
        self.ci.layout.setColumnFixedWidth(1, 230)
        self.ci.layout.setRowMinimumHeight(2, CURVES_PIXELS)
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
        self._track_pool: list[pg.PlotDataItem] = []
        self._line_pool: list[pg.InfiniteLine] = []
        self._curve_pool: list[pg.PlotDataItem] = []
        self._legend_labels: list = []
        self._more = pg.PlotDataItem(pen=None)  # the legend's "+N more" line: no curve of its own
        self._retired: list = []

        self.track_curves: dict[str, pg.PlotDataItem] = {}

    def show_rows(self, rows: TrackRows) -> None:
        """A filled weight curve and a baseline (weight 0) for each pose's row."""

        def make_curve() -> pg.PlotDataItem:
            curve = pg.PlotDataItem()
            self.tracks.addItem(curve)
            return curve

        def make_line() -> pg.InfiniteLine:
            line = pg.InfiniteLine(angle=0, pen=pg.mkPen(90, 90, 96, 150))
            self.tracks.addItem(line)
            return line

        poses = rows.poses
        curves = pooled(self._track_pool, len(poses), make_curve)
        lines = pooled(self._line_pool, len(poses), make_line)
        self.track_curves = {}
        for i, (pose, curve, line) in enumerate(zip(poses, curves, lines, strict=True)):
            colour = pose_colour(i, len(poses))
            fill = QColor(colour)
            fill.setAlpha(55)
            row = rows.row_of(pose)
            curve.setData([], [])
            curve.setPen(pg.mkPen(colour, width=1.5))
            curve.setBrush(pg.mkBrush(fill))
            curve.setFillLevel(row + ROW_PAD)
            self.track_curves[pose] = curve
            line.setValue(row + ROW_PAD)

    def show_track(self, rows: TrackRows, pose: str, frames: np.ndarray,
                   values: np.ndarray | None) -> None:
        """A pose's weight over time in its row (nothing without keys)."""
        if values is None:
            self.track_curves[pose].setData([], [])
        else:
            self.track_curves[pose].setData(frames, rows.row_of(pose) + ROW_PAD
                                            + ROW_BAND * values)

    def show_keys(self, marks: list[KeyMark], poses: list[str]) -> None:
        """The keys: diamonds (squares when held) in the pose's colour, white when selected."""
        spots = []
        for mark in marks:
            colour = pose_colour(poses.index(mark.ref[0]), len(poses))
            spots.append({"pos": (mark.frame, mark.y), "data": mark.ref,
                          "brush": pg.mkBrush("w" if mark.selected else colour),
                          "pen": pg.mkPen(SELECTED if mark.selected else (20, 20, 20),
                                          width=2 if mark.selected else 1),
                          "symbol": "s" if mark.held else "d",
                          "size": 15 if mark.selected else 12})
        self.keys_item.setData(spots)

    def show_activity(self, mode: str, frames: np.ndarray, animated: dict[str, np.ndarray],
                      activations: np.ndarray, poses: list[str], areas: list) -> None:
        """The curves ``mode`` asks for: the keyed pose weights (in their rows' colours), the
        area activations they drive (in the areas' colours; dashed beside the weights), or
        both; areas never active are left out."""
        shown: list[Curve] = []
        if mode in ("weights", "both"):
            for pose, values in animated.items():
                if pose in poses:
                    colour = pose_colour(poses.index(pose), len(poses))
                    shown.append((values, pg.mkPen(colour, width=2), pose_label(pose)))
        if mode in ("activations", "both"):
            style = Qt.PenStyle.DashLine if mode == "both" else Qt.PenStyle.SolidLine
            for i, area in enumerate(areas):
                if activations[:, i].any():
                    shown.append((activations[:, i],
                                  pg.mkPen(area.colour, width=1.5, style=style), area.name))
        self.show_curves(frames, shown)

    def show_curves(self, frames: np.ndarray, shown: list[Curve]) -> None:
        """The curves below the rows, and the legend naming them (rebuilt only when what is
        shown changes; past ``LEGEND_ENTRIES`` the last line says how many more)."""

        def make() -> pg.PlotDataItem:
            curve = pg.PlotDataItem()
            self.curves.addItem(curve)
            return curve

        curves = pooled(self._curve_pool, len(shown), make)
        for curve, (values, pen, _) in zip(curves, shown, strict=True):
            curve.setData(frames, values)
            curve.setPen(pen)
        labels = [(label, pen.color().name(), pen.style()) for _, pen, label in shown]
        if labels == self._legend_labels:
            return
        self._legend_labels = labels
        self._retired.extend(self.legend.items)  # keep Python wrappers alive (see pooled)
        self.legend.clear()
        listed = len(shown) if len(shown) <= LEGEND_ENTRIES else LEGEND_ENTRIES - 1
        for curve, (_, _, label) in zip(curves[:listed], shown[:listed], strict=True):
            self.legend.addItem(curve, label)
        if listed < len(shown):  # a legend taller than the plot would push it off screen
            self.legend.addItem(self._more, f"+{len(shown) - listed} more")

    def show_playhead(self, frame: float) -> None:
        for line in (self.playhead, self.curve_playhead, self.ruler_playhead):
            line.setValue(frame)

    def name_rows(self, rows: TrackRows, current: str | None, label: Callable[[str], str]) -> None:
        """Each row's pose name in the names' column; the current row's with a pointer."""
        self.tracks.getAxis("left").setTicks([[
            (rows.row_of(p) + 0.5, ("▸ " if p == current else "") + label(p))
            for p in rows.poses], []])

    def rows_at_least(self, pixels: int) -> None:
        """The track rows' least height, however short the dock (the rest scroll)."""
        self.ci.layout.setRowMinimumHeight(1, pixels)

    def set_time(self, lo: float, hi: float, first: float | None = None) -> None:
        """Show frames ``lo..hi``; with ``first``, panning and zooming stop there."""
        if first is not None:
            self.track_box.setLimits(xMin=first)
        self.tracks.setXRange(lo, hi, padding=0)
