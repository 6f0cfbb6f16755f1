"""On a software renderer the viewport draws small while the user moves and full size once they
stop (issue #29): a middle-drag with real mouse events, a pose slider's change, the word for it on
the picture, and the View menu's switch, each checked on the size drawn and the pixels shown."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from studio.render.reduced import SCALES, MotionScale, scaled_size
from studio.widgets.app_settings import settings
from studio.widgets.viewport.viewport import REDUCE_KEY, Viewport
from tests.gui_helpers import viewport_image

HALF = Fraction(1, 2)
MOVING_TEXT = "drawing at 1/2 resolution while you move (software OpenGL)"


@pytest.fixture
def software_view(window, monkeypatch):
    """The window's viewport drawing as on a software renderer (this machine's llvmpipe is one;
    a GPU's would not reduce), its moving frames at half size whatever they cost."""
    vp = window.viewport
    vp.software = True
    monkeypatch.setattr(vp.motion, "record", lambda *args: None)
    vp.motion.scale = HALF
    return vp


def new_frame(vp, qtbot) -> None:
    drawn = vp.frames_rendered
    qtbot.waitUntil(lambda: vp.frames_rendered > drawn, timeout=10000)


def shown(vp) -> np.ndarray:
    """What the viewport shows now, read from its framebuffer without drawing a frame (a grab
    draws one, full size)."""
    vp.makeCurrent()
    w, h = vp.pixel_size()
    fbo = vp.ctx.detect_framebuffer(vp.defaultFramebufferObject())
    data = fbo.read(viewport=(0, 0, w, h), components=3, alignment=1)
    vp.doneCurrent()
    return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()


def detail(image: np.ndarray) -> float:
    """Mean square difference between neighbouring pixels along the rows and the columns: what
    a stretched small frame loses (an edge drawn at half size and stretched steps over two
    pixels by half as much each: half the square)."""
    pixels = image.astype(float)
    return float((np.diff(pixels, axis=0) ** 2).mean() + (np.diff(pixels, axis=1) ** 2).mean())


def test_orbiting_draws_half_size_and_letting_go_draws_full_size(window, software_view, qtbot):
    vp = software_view
    size = vp.pixel_size()
    centre = QPoint(vp.width() // 2, vp.height() // 2)
    qtbot.mousePress(vp, Qt.MouseButton.MiddleButton, pos=centre)
    for step in range(1, 4):
        qtbot.mouseMove(vp, centre + QPoint(10 * step, 0))
        new_frame(vp, qtbot)
        assert vp.last_draw_size == (round(size[0] / 2), round(size[1] / 2))
    qtbot.wait(300)  # the hand rests, the button held: still a moving view (as Blender's)
    assert vp.last_draw_size == (round(size[0] / 2), round(size[1] / 2))
    moving = shown(vp)
    # said on the picture, not in the status bar (issue #47: it replaced the messages there)
    assert vp.motion_note.isVisible() and vp.motion_note.text() == MOVING_TEXT
    assert window.statusBar().currentMessage() != MOVING_TEXT

    qtbot.mouseRelease(vp, Qt.MouseButton.MiddleButton, pos=centre + QPoint(30, 0))
    new_frame(vp, qtbot)
    assert vp.last_draw_size == size
    sharp = shown(vp)
    assert sharp.shape == moving.shape == (size[1], size[0], 3)
    # the same view (the face where it was), the moving one stretched from half as many pixels
    assert np.abs(sharp.astype(int) - moving).mean() < 3
    assert detail(moving) < 0.7 * detail(sharp)
    assert not vp.motion_note.isVisible()


class DepthProbe:
    """An overlay that records the rectangle it is drawn in and the depth under its middle
    pixel (1.0: nothing drawn there)."""

    def __init__(self) -> None:
        self.seen: list[tuple[tuple[int, int, int, int], float]] = []

    def draw(self, ctx, fbo, camera, rect) -> None:
        x, y, w, h = rect
        middle = fbo.read(viewport=(x + w // 2, y + h // 2, 1, 1), attachment=-1, dtype="f4")
        self.seen.append((rect, float(np.frombuffer(middle, np.float32)[0])))


def test_overlays_are_drawn_full_size_over_the_stretched_depth(window, software_view, qtbot):
    vp = software_view
    vp.set_samples(0)  # the still frame drawn straight into Qt's framebuffer, its depth readable
    probe = DepthProbe()
    vp.overlays.append(probe)
    w, h = vp.pixel_size()
    centre = QPoint(vp.width() // 2, vp.height() // 2)
    qtbot.mousePress(vp, Qt.MouseButton.MiddleButton, pos=centre)
    qtbot.mouseMove(vp, centre + QPoint(2, 0))
    new_frame(vp, qtbot)
    assert vp.last_draw_size == scaled_size((w, h), HALF)
    rect, depth = probe.seen[-1]
    assert rect == (0, 0, w, h)  # points and lines keep their size in pixels
    assert 0.0 < depth < 1.0  # the face is in front of the far plane there, as when still
    qtbot.mouseRelease(vp, Qt.MouseButton.MiddleButton, pos=centre + QPoint(2, 0))
    new_frame(vp, qtbot)
    rect, still_depth = probe.seen[-1]
    assert rect == (0, 0, w, h)
    assert abs(depth - still_depth) < 0.01
    vp.overlays.remove(probe)


def test_a_pose_change_draws_small_then_sharp_once_still(window, software_view, qtbot):
    vp = software_view
    size = vp.pixel_size()
    pose = window.doc.project.poses[0].name
    window.doc.set_pose_weight(pose, 0.7)
    new_frame(vp, qtbot)
    assert vp.last_draw_size == scaled_size(size, HALF)
    qtbot.waitUntil(lambda: vp.last_draw_size == size, timeout=10000)  # still: refined
    assert not vp.moving
    window.doc.set_pose_weight(pose, 0.2)
    new_frame(vp, qtbot)
    assert vp.last_draw_size == scaled_size(size, HALF)
    viewport_image(window)  # a grab (a screenshot, a test) is of the full-size view
    assert vp.last_draw_size == size and not vp.moving


def test_the_switch_turns_it_off_and_is_remembered(window, software_view, qtbot):
    vp = software_view
    switch = next(a for a in window.menus["View"].actions()
                  if a.text() == "Reduce Resolution While Moving")
    assert switch.isChecked()
    switch.trigger()  # View ▸ Reduce Resolution While Moving: off
    assert not vp.reduce_while_moving
    assert settings().value(REDUCE_KEY, type=bool) is False
    centre = QPoint(vp.width() // 2, vp.height() // 2)
    qtbot.mousePress(vp, Qt.MouseButton.MiddleButton, pos=centre)
    qtbot.mouseMove(vp, centre + QPoint(20, 0))
    new_frame(vp, qtbot)
    assert vp.last_draw_size == vp.pixel_size()  # full size while moving
    qtbot.mouseRelease(vp, Qt.MouseButton.MiddleButton, pos=centre + QPoint(20, 0))
    again = Viewport(window.doc)
    assert again.reduce_while_moving is False
    action = again.reduce_action(again)
    assert not action.isChecked()
    action.setChecked(True)
    assert again.reduce_while_moving and settings().value(REDUCE_KEY, type=bool) is True
    again.deleteLater()


def test_the_scale_is_the_largest_whose_predicted_time_fits():
    motion = MotionScale(frame_ms=50.0)
    motion.start(400.0)  # a still frame of 400 ms: 1/2 would take 100, 1/3 44
    assert motion.scale == Fraction(1, 3) and motion.label() == "1/3"
    motion.record(Fraction(1, 3), 20.0, rest_ms=26.0)  # 24 ms left to draw: 1/3 fits
    assert motion.scale == Fraction(1, 3) and motion.budget_ms == 24.0
    motion.record(Fraction(1, 3), 18.5)  # 1/2 would take 41.6: under 50, not under 40
    assert motion.scale == Fraction(1, 3)
    motion.record(Fraction(1, 3), 10.0)  # 1/2 would take 22.5: grow
    assert motion.scale == HALF
    motion.start(400.0)  # a known rate is kept from one movement to the next
    assert motion.scale == HALF
    motion.record(HALF, 5.0, rest_ms=60.0)  # more than a frame besides: 10 ms left at least
    assert motion.scale == HALF and motion.budget_ms == 10.0
    motion.record(Fraction(1, 6), 100.0)  # nothing fits: the smallest
    assert motion.scale == SCALES[-1] == Fraction(1, 6)


def test_reduced_sizes():
    assert scaled_size((1728, 972), Fraction(1, 3)) == (576, 324)
    assert scaled_size((1728, 972), HALF) == (864, 486)
    assert scaled_size((5, 3), Fraction(1, 6)) == (1, 1)


def test_a_playing_timeline_is_drawn_at_half_size_at_least(window, qtbot):
    """While the timeline plays, a slow frame is drawn at half size, not a blocky sixth: the
    player skips frames to keep time instead (seen red with the floor taken out: 1/6)."""
    from studio.render.reduced import PLAYING_FLOOR

    vp = window.viewport
    player = window.timeline_panel.player
    player.play()
    try:
        assert vp.motion.floor == PLAYING_FLOOR == HALF
        vp.motion.record(Fraction(1, 6), 400.0)  # far over the budget: the smallest allowed
        assert vp.motion.scale == HALF
    finally:
        player.stop()
    assert vp.motion.floor == SCALES[-1]  # stopped: orbiting may reduce further again
    vp.motion.record(HALF, 400.0)
    assert vp.motion.scale == SCALES[-1]
