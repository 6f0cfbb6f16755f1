"""File ▸ Export Animation…: the timeline rendered to PNG frames, a GIF or a video.

Why on the viewport's context: a second (standalone) OpenGL context in the GUI process would stop
Qt's viewport from drawing, so the export renders offscreen with the viewport's own context,
making it current for each frame only, and lets the progress dialog run the event loop between
frames (so Cancel works and the window stays alive).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLineEdit,
    QProgressDialog,
    QPushButton,
    QSpinBox,
    QWidget,
)

from studio.core.files.errors import StudioError
from studio.core.wrinkles.techniques import TECHNIQUE_LIST
from studio.render.animation import (
    AnimationWriter,
    animation_weights,
    check_animation_budget,
    video_available,
)
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import render_settings
from studio.widgets.dialog_buttons import action_buttons

FORMATS = {"frames": "PNG frames (a folder)", "gif": "Animated GIF", "video": "MP4 video"}
# the authored techniques and none: what an artist exports (the automatic one is a preview)
EXPORT_TECHNIQUES = [t for t in TECHNIQUE_LIST if t.authored or t.key == "none"]


@dataclass
class ExportOptions:
    kind: str  # frames | gif | video
    path: Path  # a folder for frames, else the file
    width: int = 800
    height: int = 600
    technique: str = "t2"
    start: int = 0
    end: int = 96  # included
    step: int = 1

    @property
    def frames(self) -> list[int]:
        return list(range(self.start, self.end + 1, self.step))


class ExportDialog(QDialog):
    def __init__(self, window, parent: QWidget | None = None) -> None:
        super().__init__(parent or window)
        self.setWindowTitle("Export Animation")
        self.window_ = window
        doc = window.doc
        timeline = doc.project.timeline
        form = QFormLayout(self)
        self.kind = QComboBox()
        for kind, text in FORMATS.items():
            self.kind.addItem(text if kind != "video" or video_available()
                              else f"{text} (needs imageio-ffmpeg)", kind)
        if not video_available():
            self.kind.model().item(2).setEnabled(False)
        self.kind.setCurrentIndex(1)
        self.kind.currentIndexChanged.connect(self._kind_changed)
        form.addRow("Format", self.kind)
        self.path = QLineEdit()
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row = QHBoxLayout()
        row.addWidget(self.path, 1)
        row.addWidget(browse)
        form.addRow("Save to", row)
        self.width_ = QSpinBox()
        self.height_ = QSpinBox()
        for spin, value in ((self.width_, 800), (self.height_, 600)):
            spin.setRange(16, 8192)
            spin.setValue(value)
        size = QHBoxLayout()
        size.addWidget(self.width_)
        size.addWidget(self.height_)
        form.addRow("Size (W × H)", size)
        self.technique = QComboBox()
        for technique in EXPORT_TECHNIQUES:
            self.technique.addItem(technique.label, technique.key)
        index = self.technique.findData(doc.view.technique)
        self.technique.setCurrentIndex(max(index, 0))
        form.addRow("Wrinkles", self.technique)
        self.start, self.end, self.step = QSpinBox(), QSpinBox(), QSpinBox()
        for spin in (self.start, self.end):
            spin.setRange(-100000, 100000)
        self.step.setRange(1, 1000)
        self.start.setValue(timeline.start)
        self.end.setValue(timeline.end)
        frames = QHBoxLayout()
        for spin, label in ((self.start, "from"), (self.end, "to"), (self.step, "every")):
            spin.setPrefix(f"{label} ")
            frames.addWidget(spin)
        form.addRow("Frames", frames)
        self.buttons = action_buttons(self, "Export", self._accept)
        form.addRow(self.buttons)
        self._kind_changed()

    def _default_path(self, kind: str) -> str:
        doc = self.window_.doc
        folder = doc.path.parent if doc.path else Path.cwd()
        stem = doc.display_name.replace(" ", "_")
        return str(folder / {"frames": f"{stem}_frames", "gif": f"{stem}.gif",
                             "video": f"{stem}.mp4"}[kind])

    def _kind_changed(self) -> None:
        kind = self.kind.currentData()
        current = self.path.text()
        if not current or current in {self._default_path(k) for k in FORMATS}:
            self.path.setText(self._default_path(kind))

    def _browse(self) -> None:
        kind = self.kind.currentData()
        if kind == "frames":
            name = QFileDialog.getExistingDirectory(self, "Folder for the frames",
                                                    self.path.text())
        else:
            pattern = "GIF images (*.gif)" if kind == "gif" else "MP4 videos (*.mp4)"
            name, _ = QFileDialog.getSaveFileName(self, "Export animation", self.path.text(),
                                                  pattern)
        if name:
            self.path.setText(name)

    def options(self) -> ExportOptions:
        return ExportOptions(self.kind.currentData(), Path(self.path.text()),
                             self.width_.value(), self.height_.value(),
                             self.technique.currentData(), self.start.value(), self.end.value(),
                             self.step.value())

    def _accept(self) -> None:
        o = self.options()
        if o.end < o.start or not self.path.text().strip():
            self.path.setFocus()
            return
        self.accept()


def export_animation(window, options: ExportOptions) -> bool:
    """Render the frames with a progress dialog; False if cancelled. Raises StudioError."""
    doc, viewport = window.doc, window.viewport
    project = doc.project
    frames = options.frames
    check_animation_budget(len(frames), (options.width, options.height),
                           options.kind == "gif")
    weights = animation_weights(project, frames)
    if options.kind == "frames":
        pattern, gif, video = str(options.path / "frame_%04d.png"), None, None
    else:
        pattern = None
        gif = str(options.path) if options.kind == "gif" else None
        video = str(options.path) if options.kind == "video" else None
    if viewport.ctx is None:
        raise StudioError("the viewport has no OpenGL context to render with")
    writer = AnimationWriter(project.timeline.fps, pattern, gif, video,
                             (options.width, options.height), options.step,
                             [doc.path] if doc.path else [])
    # everything the viewport shows (blend, relief, light, debug view), with the chosen technique
    # (a relief this context cannot draw was already turned into parallax by the viewport)
    settings = render_settings(doc.view, technique=options.technique)
    progress = QProgressDialog("Rendering the animation…", "Cancel", 0, len(frames), window)
    progress.setWindowTitle("Export Animation")
    progress.setWindowModality(Qt.WindowModality.WindowModal)
    progress.setMinimumDuration(0)
    progress.setValue(0)
    viewport.makeCurrent()
    try:
        studio = OffscreenStudio(project, options.width, options.height, ctx=viewport.ctx)
        studio.camera = copy.deepcopy(doc.camera)  # what the artist is looking at
    finally:
        viewport.doneCurrent()
    cancelled = False
    try:
        for i, frame in enumerate(frames):
            if progress.wasCanceled():
                cancelled = True
                break
            viewport.makeCurrent()
            try:
                image = studio.render(settings, weights[i])
            finally:
                viewport.doneCurrent()
            try:
                writer.add(frame, image)
            except BaseException:
                writer.abort()
                raise
            progress.setLabelText(f"Rendering frame {frame} ({i + 1} of {len(frames)})…")
            progress.setValue(i + 1)
    finally:
        viewport.makeCurrent()
        studio.release()
        viewport.doneCurrent()
        progress.close()
    if cancelled:
        writer.abort()
        return False  # the frames written so far stay; the GIF or video is not written
    writer.close(options.step)
    return True


def open_export_dialog(window) -> None:
    """The menu action: ask, export, and say where it went."""
    if not window.doc.project.timeline.has_keys:
        from PySide6.QtWidgets import QMessageBox

        QMessageBox.information(window, "Export Animation",
                                "The timeline has no keys yet: add keys in the Timeline panel "
                                "(or press “Sequence all poses”) first.")
        return
    window.timeline_panel.player.stop()
    dialog = ExportDialog(window)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return
    options = dialog.options()
    try:
        done = export_animation(window, options)
    except StudioError as exc:
        window.show_error("Cannot export the animation", exc)
        return
    window.statusBar().showMessage(
        f"Exported {len(options.frames)} frames to {options.path}" if done
        else "Export cancelled", 8000)
