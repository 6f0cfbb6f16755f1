"""The live 3D viewport: the foundation's renderer inside a QOpenGLWidget.

Document signals only set dirty flags and schedule a repaint; ``paintGL`` applies them, so GL work
happens in the widget's context and each change re-uploads only what it touched. Navigation
follows Blender: middle-drag orbits, Shift+middle pans, Ctrl+middle and the wheel zoom; on a
laptop Alt+left orbits and Alt+Shift+left pans. F frames the face; numpad 1/3/7 give front,
side and top views.

On a software renderer, frames drawn while the user moves (navigation, a camera or pose change:
scrubbing, a pose slider, playback) are drawn at a reduced size chosen to hold 20 frames a
second, single-sampled, and stretched over the viewport; ``SETTLE_MS`` after the last movement
(a navigation drag: when the button is let go) the frame is drawn full size again. View ▸ Reduce
Resolution While Moving turns it off (remembered).
"""

from __future__ import annotations

import time

import moderngl
from PySide6.QtCore import QObject, QPoint, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QImage, QMouseEvent, QWheelEvent
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import QLabel, QWidget

from studio.core.files.errors import RenderError
from studio.core.wrinkles.techniques import SPLIT, TECHNIQUES
from studio.render.gl_info import describe_gl, gl_version, is_software
from studio.render.reduced import (
    PLAYING_FLOOR,
    SCALES,
    MotionScale,
    ReducedTarget,
    scaled_size,
)
from studio.render.renderer import FaceRenderer
from studio.render.scene import ProjectScene
from studio.render.settings import render_settings
from studio.render.viewport_targets import MsaaTarget, attach_to_current_context
from studio.widgets.app_settings import settings
from studio.widgets.document import Document
from studio.widgets.viewport.technique_switch import TechniqueSwitch
from studio.widgets.viewport.viewport_model import (
    WHEEL_ZOOM,
    camera_move,
    navigation,
    numpad_view,
    reduced_note,
    split_columns,
)

ANTI_ALIASING = (0, 2, 4, 8)  # samples per pixel offered (View ▸ Anti-Aliasing); 0: off
DEFAULT_SAMPLES = 4
LABEL_STYLE = ("color: #d8d8d8; background: rgba(20,20,24,150); padding: 3px 7px;"
               "border-radius: 3px;")
SETTLE_MS = 200  # still this long after the last movement: draw full size again
REPORT_MS = 500  # while moving, frame times are reported (frameRendered) this often
# the time between frames besides the drawing (Qt composing the window) is the least of the
# last GAPS moving frames' gaps: a pause of the hand lengthens a gap, never shortens one
GAPS = 8
REDUCE_KEY = "viewport/reduce_while_moving"
BUTTONS = {Qt.MouseButton.LeftButton: "left", Qt.MouseButton.MiddleButton: "middle"}
NUMPAD = {Qt.Key.Key_1: "1", Qt.Key.Key_3: "3", Qt.Key.Key_7: "7"}


class Viewport(QOpenGLWidget):
    # milliseconds the frame took, GPU finish included: after every still frame, and while the
    # user moves at most every REPORT_MS with the mean since (a change to the status bar makes
    # Qt compose the whole window again: on a software renderer as long as a reduced frame)
    frameRendered = Signal(float)
    glFailed = Signal(str)

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = document
        self.ctx: moderngl.Context | None = None
        self.gl_description: str | None = None  # the OpenGL in use (describe_gl), once up
        self.scene: ProjectScene | None = None
        self.tool = None  # an authoring tool: press/move/release(viewport, event) on left button
        # drawn after the face each frame: objects with draw(ctx, fbo, camera, viewport_rect)
        self.overlays: list = []
        self._pending: set[str] = set()
        self._mask_regions: list[tuple[int, int, int, int, int]] = []
        self._drag: tuple[str, QPoint] | None = None
        self.frames_rendered = 0
        self._relief_refused = False  # the fallback from displace to parallax was announced
        self.samples = DEFAULT_SAMPLES  # anti-aliasing: samples per pixel (0 or 1: off)
        self._msaa = MsaaTarget()  # drawn into, then resolved into Qt's
        # reduced drawing while moving (software renderers; see the module's docstring)
        self.software = False  # the context draws on the CPU (set once OpenGL is up)
        self.reduce_while_moving = settings().value(REDUCE_KEY, True, type=bool)
        self.motion = MotionScale()
        self.moving = False
        self.last_draw_size: tuple[int, int] = (0, 0)  # pixels the last frame was drawn at
        self._reduced: ReducedTarget | None = None
        self._preview: int | None = None  # the area painted on the UV canvas (set_mask_preview)
        self._still_ms = 0.0  # the last full-size frame's time
        self._moved_at = 0.0  # perf_counter when the current movement started
        self._said: str | None = None  # the status bar message about reduced drawing
        self._unreported: list[float] = []  # moving frames' times not yet reported
        self._painted: tuple[float, float] | None = None  # the last frame's start and end
        self._gaps: list[float] = []  # ms from one moving frame's end to the next one's start
        self._reported = 0.0  # perf_counter of the last frameRendered
        self._settle = QTimer(self, singleShot=True, interval=SETTLE_MS)
        self._settle.timeout.connect(self._still)
        self.setMinimumSize(320, 240)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(True)
        # the single view's label is a switch (a click offers the techniques, as Blender's
        # viewport header does); the split view's panes are labelled, not switched
        self.technique_switch = TechniqueSwitch(document, self)
        self._labels = [self.technique_switch, *(self._make_label() for _ in SPLIT[1:])]
        # what the picture is while it is drawn reduced, said where the eye is (the status
        # bar keeps the messages a person must read: what was keyed, selected, exported)
        self.motion_note = self._make_label()
        self.motion_note.hide()
        self.tool_note = self._make_label()  # what the last gesture of a tool did (``say``)
        self.tool_note.hide()
        self._tool_note_timer = QTimer(self, singleShot=True)
        self._tool_note_timer.timeout.connect(self.tool_note.hide)
        self._connect()

    def _make_label(self) -> QLabel:
        label = QLabel(self)
        label.setStyleSheet(LABEL_STYLE)
        label.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        return label

    def _connect(self) -> None:
        d = self.doc
        d.projectReplaced.connect(lambda: self._invalidate("project"))
        d.posesChanged.connect(lambda: self._invalidate("project"))
        d.texturesChanged.connect(lambda: self._invalidate("textures"))
        d.poseWeightsChanged.connect(lambda: self._invalidate("pose"))
        d.activationsChanged.connect(lambda: self._invalidate("activations"))
        d.areasChanged.connect(lambda: self._invalidate("areas"))
        d.masksChanged.connect(lambda: self._invalidate("masks"))
        d.maskRegionChanged.connect(self._mask_region_changed)
        d.wdvChanged.connect(lambda: self._invalidate("wdv"))
        d.wdvSettingsChanged.connect(lambda: self._invalidate("wdv settings"))
        d.furrowsChanged.connect(lambda: self._invalidate("onsets"))  # the poses' onsets
        d.viewChanged.connect(self._update_labels)
        d.viewChanged.connect(self.update)
        d.cameraChanged.connect(self._moved)
        d.poseWeightsChanged.connect(self._moved)  # a scrub, a slider drag, playback

    def _invalidate(self, what: str) -> None:
        self._pending.add(what)
        self.update()

    def _mask_region_changed(self, layer: int, x: int, y: int, w: int, h: int) -> None:
        """A brush dab: upload just that rectangle of that layer at the next frame."""
        self._mask_regions.append((layer, x, y, w, h))
        self.update()

    # --- GL ------------------------------------------------------------------------------------
    def initializeGL(self) -> None:
        try:
            self.ctx = attach_to_current_context()
        except RenderError as exc:
            self.ctx = None
            self.glFailed.emit(str(exc))
            return
        self.renderer = FaceRenderer(self.ctx)
        self.gl_description = describe_gl(self.ctx)
        self.software = is_software(self.ctx)
        self._pending = {"project"}
        self._update_labels()
        self.show_status(self.gl_description, 8000)

    def show_status(self, text: str, ms: int = 0) -> None:
        """A message in the window's status bar (the viewport alone in a test: nowhere)."""
        bar = getattr(self.window(), "statusBar", None)
        if bar is not None:
            QTimer.singleShot(0, lambda: bar().showMessage(text, ms))

    def say(self, text: str, ms: int) -> None:
        """Words on the picture's bottom edge for ``ms``: what a tool's gesture did, where the
        person is looking (a selection's count, say)."""
        note = self.tool_note
        note.setText(text)
        note.adjustSize()
        note.move(8, self.height() - note.height() - 8)
        note.show()
        note.raise_()
        self._tool_note_timer.start(ms)

    def _apply_pending(self) -> None:
        pending = self._pending
        if "project" in pending:
            self.scene = ProjectScene(self.renderer, self.doc.project)
            pending = {"pose"}
            self._mask_regions.clear()
        scene = self.scene
        if "textures" in pending:
            scene.reload_textures()
        if "masks" in pending:
            scene.reload_masks()
            self._mask_regions.clear()
        masks = self.doc.project.influence.areas
        for layer, x, y, w, h in self._mask_regions:
            self.renderer.update_mask_region(layer, x, y, masks[layer].mask[y:y + h, x:x + w])
        self._mask_regions.clear()
        if "areas" in pending:
            scene.reload_area_maps()
        if "pose" in pending:
            scene.set_pose_weights(self.doc.pose_weights)
        if "onsets" in pending:
            scene.reload_onsets()
        elif "pose" not in pending and pending & {"activations", "areas"}:
            scene.reload_activations()
        if scene.preview_area != self._preview:
            scene.preview_area = self._preview
            scene.reload_activations()
        if "wdv" in pending:
            scene.reload_wdv()
        elif "wdv settings" in pending:  # a uniform: the slots stay as they are
            scene.reload_wdv_settings()
        self._pending = set()

    def paintGL(self) -> None:
        if self.ctx is None:
            return
        start = time.perf_counter()
        self._apply_pending()
        # detected once per Qt framebuffer: moderngl 5 never frees a detected one (~400 B a frame)
        key = (self.ctx, self.defaultFramebufferObject(), self.width(), self.height(),
               self.devicePixelRatioF())
        if getattr(self, "_fbo_key", None) != key:
            self._fbo, self._fbo_key = self.ctx.detect_framebuffer(key[1]), key
        size = self.pixel_size()
        scale = self.motion.scale if self._reducing() else None
        self.renderer.nearest_first = scale is None
        if scale is None:
            fbo = self._draw_target(*size)
            self._draw_face(fbo, size)
            self._draw_overlays(fbo, size)
            if fbo is not self._fbo:
                self.ctx.copy_framebuffer(self._fbo, fbo)  # resolve the samples into Qt's
            self.last_draw_size = size
        else:
            if self._reduced is None:
                self._reduced = ReducedTarget(self.ctx)
            self.last_draw_size = scaled_size(size, scale)
            self._draw_face(self._reduced.framebuffer(self.last_draw_size), self.last_draw_size)
            self._reduced.upscale(self._fbo, size)
            self._draw_overlays(self._fbo, size)  # full size on the stretched depth
        self.ctx.finish()
        ms = (time.perf_counter() - start) * 1000.0
        if scale is None:
            self._still_ms = ms
            self._gaps.clear()
        else:
            if self._painted is not None and self._painted[0] >= self._moved_at:
                self._gaps = [*self._gaps[-(GAPS - 1):], (start - self._painted[1]) * 1000.0]
            self.motion.record(scale, ms, min(self._gaps, default=0.0))
        self._painted = (start, time.perf_counter())
        self._say_reduced(scale)
        self.frames_rendered += 1
        self._report(ms)

    def _report(self, ms: float) -> None:
        """``frameRendered`` for this frame: at once when still, batched while moving."""
        self._unreported.append(ms)
        now = time.perf_counter()
        if self.moving and (now - self._reported) * 1000.0 < REPORT_MS:
            return
        mean = sum(self._unreported) / len(self._unreported)
        self._unreported.clear()
        self._reported = now
        self.frameRendered.emit(mean)

    def _draw_face(self, fbo: moderngl.Framebuffer, size: tuple[int, int]) -> None:
        """The face (each split pane's) into ``fbo``'s (0, 0, *size)."""
        w, h = size
        view = self.doc.view
        if self._preview is not None:  # painting: what the mask reveals, with technique 1
            view = view.with_changes(technique="t1", split=False, debug_view="shaded")
        relief = self._relief(view.relief)
        if view.split:
            for (x, width), technique in zip(split_columns(w), SPLIT, strict=True):
                self.renderer.render(fbo, self.doc.camera,
                                     render_settings(view, technique=technique, relief=relief),
                                     viewport=(x, 0, width, h))
        else:
            self.renderer.render(fbo, self.doc.camera, render_settings(view, relief=relief),
                                 viewport=(0, 0, w, h))

    def _draw_overlays(self, fbo: moderngl.Framebuffer, size: tuple[int, int]) -> None:
        for overlay in self.overlays:
            overlay.draw(self.ctx, fbo, self.doc.camera, (0, 0, *size))

    # --- reduced resolution while moving ------------------------------------------------------
    def _reducing(self) -> bool:
        return self.moving and self.software and self.reduce_while_moving

    def _moved(self) -> None:
        """The camera or the pose changed: a moving frame, full size again once still."""
        if not self.moving:
            self.moving = True
            self._moved_at = time.perf_counter()
            self.motion.start(self._still_ms)
        self._settle.start()
        self.update()

    def _still(self) -> None:
        """No movement for ``SETTLE_MS``: full size again, unless a navigation drag is still
        held (as in Blender, the view stays reduced until the button is let go)."""
        if self._drag is None:
            self._settled()

    def _settled(self, redraw: bool = True) -> None:
        """The movement ended: the next frame is full size."""
        self._settle.stop()
        if self.moving:
            self.moving = False
            if redraw:
                self.update()

    def grabFramebuffer(self) -> QImage:
        """The view drawn full size, even mid-movement: a grab is a picture to keep (Qt draws
        a frame for it)."""
        self._settled(redraw=False)
        return super().grabFramebuffer()

    def _say_reduced(self, scale) -> None:
        """Say on the picture, in its bottom corner, while frames are drawn reduced, and stop
        saying so with the first full-size frame. Not in the status bar: a pose change nobody's
        hand made (K keying, an undo) also draws reduced for a moment, and its words there
        replaced the message a person was reading ("Keyed …") and outlived the movement."""
        text = reduced_note(scale, scale == SCALES[0], min(self.samples, self.max_samples))
        if text == self._said:
            return
        self._said = text
        note = self.motion_note
        note.setVisible(text is not None)
        if text is not None:
            note.setText(text)
            note.adjustSize()
            note.move(self.width() - note.width() - 8, self.height() - note.height() - 8)

    def set_mask_preview(self, area: int | None) -> None:
        """While an area is painted on the UV canvas, the face shows that area alone at full
        activation with technique 1 — what the mask reveals, live under each dab — and then
        the document's own view again (a view of the work, not an edit)."""
        if area == self._preview:
            return
        self._preview = area
        self._invalidate("activations")

    def set_playing(self, playing: bool) -> None:
        """While the timeline plays, frames are drawn at half size at least (see
        ``MotionScale.floor``): a person watching an expression play looks at its wrinkles."""
        self.motion.floor = PLAYING_FLOOR if playing else SCALES[-1]
        self.motion.scale = max(self.motion.scale, self.motion.floor)

    def set_reduce_while_moving(self, on: bool) -> None:
        """View ▸ Reduce Resolution While Moving: on a software renderer, draw moving frames
        at a reduced size (remembered)."""
        self.reduce_while_moving = bool(on)
        settings().setValue(REDUCE_KEY, self.reduce_while_moving)
        self.update()

    def reduce_action(self, parent: QObject) -> QAction:
        """The View menu's checkable entry for ``set_reduce_while_moving``."""
        action = QAction("Reduce Resolution While Moving", parent, checkable=True)
        action.setChecked(self.reduce_while_moving)
        action.setToolTip("On a software renderer (no graphics card, e.g. in a virtual "
                          "machine), draw at a lower resolution while you orbit, scrub or "
                          "drag a slider, and sharp again when you stop")
        action.toggled.connect(self.set_reduce_while_moving)
        return action

    @property
    def max_samples(self) -> int:
        """The most samples per pixel this driver can draw (0 before OpenGL is up)."""
        return int(self.ctx.info.get("GL_MAX_SAMPLES") or 0) if self.ctx is not None else 0

    def set_samples(self, samples: int) -> None:
        """Anti-aliasing, samples per pixel (0 or 1: off); takes effect at the next frame. A
        software renderer pays for each sample: 4× costs about 2.5 × the time of off."""
        self.samples = samples
        self.update()

    def _draw_target(self, w: int, h: int) -> moderngl.Framebuffer:
        """Where this frame is drawn: Qt's framebuffer, or a multisampled one of the same size."""
        fbo = self._msaa.framebuffer(self.ctx, (w, h), min(self.samples, self.max_samples))
        return self._fbo if fbo is None else fbo

    def _relief(self, relief: str) -> str:
        """The relief to draw: without OpenGL 4.0, "displace" falls back to parallax, once
        said (the shading panel then shows parallax)."""
        if relief != "displace" or self.renderer.can_displace:
            return relief
        if not self._relief_refused:
            self._relief_refused = True
            message = (f"Displacement needs OpenGL 4.0 (tessellation shaders); this driver "
                       f"offers {gl_version(self.ctx)}. Showing parallax relief instead.")
            QTimer.singleShot(0, lambda: (self.doc.set_view(relief="parallax"),
                                          self.glFailed.emit(message)))
        return "parallax"

    def resizeGL(self, w: int, h: int) -> None:
        self._update_labels()

    def _update_labels(self) -> None:
        view = self.doc.view
        if view.split:
            for label, (x, _), technique in zip(self._labels, split_columns(self.width()), SPLIT,
                                                strict=True):
                label.setText(TECHNIQUES[technique].short)
                label.adjustSize()
                label.move(x + 8, 8)
                label.show()
        else:
            first, *rest = self._labels
            first.setText(f"{TECHNIQUES[view.technique].short} ▾")
            first.adjustSize()
            first.move(8, 8)
            first.show()
            for label in rest:
                label.hide()
        self.technique_switch.set_switching(not view.split)

    # --- navigation ----------------------------------------------------------------------------
    def _navigation_for(self, event: QMouseEvent) -> str | None:
        mods, button = event.modifiers(), event.button()
        return navigation(BUTTONS.get(button, ""), bool(mods & Qt.KeyboardModifier.ShiftModifier),
                          bool(mods & Qt.KeyboardModifier.ControlModifier),
                          bool(mods & Qt.KeyboardModifier.AltModifier))

    def mousePressEvent(self, event: QMouseEvent) -> None:
        mode = self._navigation_for(event)
        if mode:
            self._drag = (mode, event.position().toPoint())
            event.accept()
        elif self.tool is not None and event.button() == Qt.MouseButton.LeftButton:
            self.tool.press(self, event)
        else:
            super().mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._drag is None:
            if self.tool is not None:
                self.tool.move(self, event)
            return
        mode, last = self._drag
        pos = event.position().toPoint()
        dx, dy = pos.x() - last.x(), pos.y() - last.y()
        self._drag = (mode, pos)
        move, args = camera_move(mode, dx, dy, self.height())
        getattr(self.doc.camera, move)(*args)
        self.doc.cameraChanged.emit()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if self._drag is not None:
            self._drag = None
            self._settled()  # the hand stopped: sharp at once
        elif self.tool is not None and event.button() == Qt.MouseButton.LeftButton:
            self.tool.release(self, event)

    def set_tool(self, tool) -> None:
        """Give left-button gestures to an authoring tool (None: navigation only)."""
        if self.tool is not None and hasattr(self.tool, "deactivate"):
            self.tool.deactivate(self)
        self.tool = tool
        self.setCursor(Qt.CursorShape.CrossCursor if tool else Qt.CursorShape.ArrowCursor)
        self.update()

    def pixel_size(self) -> tuple[int, int]:
        """The framebuffer size in device pixels (what the camera projects to)."""
        ratio = self.devicePixelRatioF()
        return round(self.width() * ratio), round(self.height() * ratio)

    def wheelEvent(self, event: QWheelEvent) -> None:
        steps = event.angleDelta().y() / 120.0
        self.doc.camera.zoom(WHEEL_ZOOM ** steps)
        self.doc.cameraChanged.emit()

    def keyPressEvent(self, event) -> None:
        key = event.key()
        keypad = bool(event.modifiers() & Qt.KeyboardModifier.KeypadModifier)
        view = numpad_view(NUMPAD.get(key, ""), bool(
            event.modifiers() & Qt.KeyboardModifier.ControlModifier)) if keypad else None
        if key in (Qt.Key.Key_F, Qt.Key.Key_Home) or (keypad and key == Qt.Key.Key_Period):
            shift = event.modifiers() & Qt.KeyboardModifier.ShiftModifier
            (self.doc.frame_all if shift and key == Qt.Key.Key_Home else self.doc.frame_face)()
        elif view is not None:
            self.doc.camera.yaw, self.doc.camera.pitch = view
            self.doc.cameraChanged.emit()
        else:
            super().keyPressEvent(event)
