"""The Furrows panel: depth, spacing and sharpness of the synthesised furrows, and how soon along
a pose's weight its lines appear (its onset), for all poses or one, live in the viewport
(issue 45, point 6).

Depth, spacing and sharpness are factors (1 = as synthesised, the look the blind review scored
best) and shape the synthesised maps only; the onset is a pose weight (0 = lines from the first
movement, as before) and reaches every technique's wrinkles, authored or synthesised, so the
pose list holds every pose. A slider
drag is one undo step (a ``ValueCommand`` merged by its gesture), a typed value with Return one
more; the document keeps the controls (``Project.furrows``), saved with the project. A change
makes again only the synthesised maps that hold the changed pose's furrows
(``core.setup.furrow_maps``) as soon as the controls rest a moment, however many slider ticks
came: the viewport follows the drag. Undo restores the controls, and the maps follow them back.
"""

from __future__ import annotations

import contextlib
from concurrent.futures import Future, ThreadPoolExecutor
from functools import partial

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QApplication, QComboBox, QLabel, QPushButton, QVBoxLayout, QWidget

from studio.core.files.errors import StudioError
from studio.core.project.model import Project
from studio.core.setup.furrow_maps import FurrowMaps
from studio.core.wrinkles.furrow_controls import (
    LABELS,
    MAP_CONTROLS,
    RANGES,
    FurrowControls,
    FurrowSettings,
)
from studio.widgets.commands import ValueCommand
from studio.widgets.document import Document
from studio.widgets.slider_row import SliderRow, fit_labels

ALL_POSES = "All poses"
REMAKE_AFTER_MS = 60  # a pause in a drag this long shows its furrows
TIPS = {"depth": "How deep the furrows run (their walls steepen, never past 35°)",
        "spacing": "How far apart neighbouring furrows lie: 2 × gives half as many lines",
        "sharpness": "How narrow each furrow is between the flat skin beside it",
        "onset": "The pose's weight below which its lines do not show (its shape still "
                 "moves); above it they grow to full at full weight. 0: from the start"}
SUFFIXES = {"onset": ""}  # a weight, not a factor


class FurrowPanel(QWidget):
    """A pose chooser, a slider row per control, and Reset."""

    _ready = Signal()  # a job making maps ended

    def __init__(self, doc: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.maps = FurrowMaps()
        # the maps are made again once the controls rest a moment: a drag's ticks, held arrow
        # keys or a turn of the wheel make them once, not once each
        self._remake_timer = QTimer(self)
        self._remake_timer.setSingleShot(True)
        self._remake_timer.setInterval(REMAKE_AFTER_MS)
        self._remake_timer.timeout.connect(self._remake)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="furrows")
        self._job: tuple[Future, Project, dict] | None = None
        self._again = False  # the controls changed while a job ran
        self._stop = [False]  # set when the panel goes: a running job ends at its next pose
        self._ready.connect(self._made)  # (emitted on the job's thread, queued to this one)
        stop_jobs = partial(_stop_jobs, self._stop, self._pool)
        self.destroyed.connect(stop_jobs)
        QApplication.instance().aboutToQuit.connect(stop_jobs)
        layout = QVBoxLayout(self)
        intro = QLabel("Shape the furrows of the wrinkled maps synthesised from the poses "
                       "(×1: as synthesised), and choose how far into each pose its lines "
                       "appear.")
        intro.setWordWrap(True)
        layout.addWidget(intro)
        self.pose = QComboBox()
        self.pose.setObjectName("furrows:pose")
        self.pose.setToolTip("The pose whose furrows the sliders shape; its own factors apply "
                             "on top of those for all poses")
        self.pose.currentIndexChanged.connect(lambda _: self._show())
        layout.addWidget(self.pose)
        self.rows: dict[str, SliderRow] = {}
        for name in RANGES:
            low, high = RANGES[name]
            row = SliderRow(LABELS[name], low, high, decimals=2,
                            suffix=SUFFIXES.get(name, " ×"))
            row.setToolTip(TIPS[name])
            row.edited.connect(lambda value, gesture, n=name: self._edit(n, value, gesture))
            self.rows[name] = row
            layout.addWidget(row)
        fit_labels(list(self.rows.values()))
        self.reset = QPushButton("Reset to defaults")
        self.reset.setToolTip("Every control of the chosen pose (or of all poses) back to "
                              "as synthesised, with no onset")
        self.reset.clicked.connect(self._reset)
        layout.addWidget(self.reset)
        self.status = QLabel()
        self.status.setWordWrap(True)
        layout.addWidget(self.status)
        layout.addStretch(1)
        doc.furrowsChanged.connect(self._changed)
        doc.projectReplaced.connect(self._adopt)
        doc.posesChanged.connect(self._fill_poses)
        doc.texturesChanged.connect(self._show)
        self._adopt()

    def _adopt(self) -> None:
        """A project opened: its maps are as its controls made them (a job still running for
        the one before is left to end; its maps are not this project's)."""
        self.maps.adopt(self.doc.project)
        self._fill_poses()

    # --- what is shown ---------------------------------------------------------------------
    def chosen(self) -> str | None:
        """The pose the sliders shape; None: all poses."""
        return self.pose.currentData()

    def _fill_poses(self) -> None:
        """All poses, then each pose in the face's order (the onset reaches every pose's
        wrinkles); the chosen one kept when it is still there."""
        chosen = self.chosen()
        self.pose.blockSignals(True)
        self.pose.clear()
        self.pose.addItem(ALL_POSES, None)
        for pose in self.doc.project.poses:
            self.pose.addItem(pose.name, pose.name)
        self.pose.setCurrentIndex(max(self.pose.findData(chosen), 0))
        self.pose.blockSignals(False)
        self._show()

    def _show(self) -> None:
        furrows = self.doc.project.furrows
        controls = furrows.controls(self.chosen())
        for name, row in self.rows.items():
            row.set_value(getattr(controls, name))
        maps = self._live_maps()
        enabled = bool(maps)
        for name in MAP_CONTROLS:
            self.rows[name].setEnabled(enabled)
        has_poses = bool(self.doc.project.poses)
        for widget in (self.pose, self.rows["onset"], self.reset):
            widget.setEnabled(has_poses)
        if not furrows.maps_of(self.chosen()) and furrows.maps:
            self.status.setText("No synthesised map holds this pose's furrows: its onset "
                                "still times the lines of every technique.")
        elif not furrows.maps:
            self.status.setText("No wrinkled map here was synthesised from the poses (New "
                                "from Files or wrinkle-studio new --auto synthesises them for "
                                "a face that came without one): the onset still times the "
                                "lines of every technique.")
        elif not enabled:
            self.status.setText("The synthesised maps were replaced since: the controls leave "
                                "them as they are.")
        else:
            self.status.setText("Shapes the wrinkled map" + ("s " if len(maps) > 1 else " ")
                                + ", ".join(f"“{m}”" for m in maps) + ".")

    def _live_maps(self) -> list[str]:
        """The maps the chosen pose's controls shape that are still as synthesised."""
        project = self.doc.project
        wanted = project.furrows.maps_of(self.chosen())
        return [name for name in wanted if self.maps.is_synthesised(project, name)]

    # --- edits -----------------------------------------------------------------------------
    def _edit(self, name: str, value: float, gesture: int | None) -> None:
        pose = self.chosen()
        current = self.doc.project.furrows.controls(pose)
        controls = FurrowControls(**{**current.to_dict(), name: float(value)})
        label = LABELS[name].lower()
        push_furrows(self.doc, self.doc.project.furrows.with_controls(pose, controls),
                     f"Furrow {label} of {pose or 'all poses'}",
                     None if gesture is None else ("furrows", pose, name, gesture))

    def _reset(self) -> None:
        pose = self.chosen()
        push_furrows(self.doc, self.doc.project.furrows.with_controls(pose, FurrowControls()),
                     f"Reset the furrows of {pose or 'all poses'}", None)

    def _changed(self) -> None:
        """Show the controls now; make the maps again once they rest (``REMAKE_AFTER_MS``)."""
        self._show()
        self._remake_timer.start()

    def _remake(self) -> None:
        """Make the maps whose poses' controls changed, off the GUI thread: laying a map's
        furrows out at a new spacing takes seconds on a large head (all poses': the whole
        synthesis), and the person keeps dragging meanwhile. One job at a time; a change
        during it starts another when it ends."""
        if self._job is not None:
            self._again = True
            return
        project = self.doc.project
        pending = self.maps.pending(project)
        if not pending:
            return
        stop = self._stop
        job = self._pool.submit(self.maps.make, project, project.furrows, list(pending),
                                lambda: stop[0])
        self._job = (job, project, pending)
        job.add_done_callback(partial(_announce, self._ready, stop))

    def _made(self) -> None:
        """A job ended (back on the GUI thread): its maps into the project it was made for."""
        if self._job is None:
            return
        (job, project, pending), self._job = self._job, None
        try:
            made = job.result()
        except StudioError as exc:
            self.window().show_error("Cannot make the furrows again", exc)
            return
        if made and project is self.doc.project and self.maps.apply(
                project, {n: (image, pending[n]) for n, image in made.items()}):
            self.doc.texturesChanged.emit()
        if self._again:
            self._again = False
            self._remake()


def push_furrows(doc: Document, settings: FurrowSettings, text: str, merge_key) -> None:
    """The project's furrow settings replaced as an undo step (merged by ``merge_key``:
    one step per slider drag); nothing when they are the same."""
    def read() -> FurrowSettings:
        return doc.project.furrows

    def apply(value: FurrowSettings) -> None:
        doc.project.furrows = value
        doc.furrowsChanged.emit()
        doc.activationsChanged.emit()  # the onsets reach technique 1's activations

    if _same(read(), settings):
        return
    doc.undo_stack.push(ValueCommand(text, read, apply, settings, merge_key))


def _same(a: FurrowSettings, b: FurrowSettings) -> bool:
    return a.all == b.all and a.poses == b.poses and a.maps == b.maps


def _announce(ready, stop: list[bool], _job: Future) -> None:
    """A job ended: tell the panel, unless it is gone (its signal with it)."""
    if not stop[0]:
        with contextlib.suppress(RuntimeError):  # deleted between the check and the emit
            ready.emit()


def _stop_jobs(stop: list[bool], pool: ThreadPoolExecutor) -> None:
    """The panel is gone: a running job stops at its next pose, and no other starts."""
    stop[0] = True
    pool.shutdown(wait=False, cancel_futures=True)


def install_furrow_controls(window) -> FurrowPanel:
    """The "Furrows" dock in the right-hand column, and Maps ▸ Furrow Controls to raise it."""
    panel = FurrowPanel(window.doc)
    window._add_dock("Furrows", panel, Qt.DockWidgetArea.RightDockWidgetArea)
    dock = window.docks["Furrows"]
    action = window.menus["Maps"].addAction("Furrow Controls")
    action.setStatusTip("Depth, spacing and sharpness of the synthesised furrows, and each "
                        "pose's onset")
    action.triggered.connect(lambda: (dock.show(), dock.raise_()))
    window.furrow_panel = panel
    return panel
