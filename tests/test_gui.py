"""The studio window under Xvfb, driven like a user: sliders, undo, files, errors."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QPushButton

from studio.core.project.reader import load_project
from studio.core.wrinkles.wdv import WdvSetup
from studio.widgets.viewport.viewport import split_columns
from tests.gui_helpers import bring_forward, drag_slider, viewport_image, viewport_marks
from tests.regions import region_difference


def test_window_starts_on_the_sample_face(window):
    assert window.doc.project.name == "Sample face"
    assert "Sample face" in window.windowTitle()
    image = viewport_image(window)
    marks = viewport_marks(window)
    h, w = image.shape[:2]
    x, y = marks["nose tip"]
    assert 0 <= x < w and 0 <= y < h
    background = image[5, w // 2].astype(int)
    assert np.abs(image[y, x].astype(int) - background).sum() > 40
    assert window.docks["Poses"].isVisible() and window.docks["Shading"].isVisible()


def test_surprise_slider_wrinkles_the_forehead_and_back_to_neutral_restores_it(window, qtbot):
    """A pose slider is a view of the face, like the playhead: it edits nothing (no undo step,
    no unsaved change; issue #35), and Back to neutral gives the very same picture back."""
    bring_forward(window.pose_panel)  # the Poses tab, as a person would click it first
    before = viewport_image(window)
    marks = viewport_marks(window)
    drag_slider(qtbot, window.pose_panel.pose_rows["surprise"].slider, 1.0)
    assert window.doc.pose_weights["surprise"] == pytest.approx(1.0, abs=0.01)
    assert window.doc.undo_stack.count() == 0
    assert not window.isWindowModified()
    after = viewport_image(window)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    neutral = next(b for b in window.pose_panel.findChildren(QPushButton)
                   if b.text() == "Back to neutral")
    qtbot.mouseClick(neutral, Qt.MouseButton.LeftButton)
    assert window.doc.pose_weights["surprise"] == 0.0
    assert window.pose_panel.pose_rows["surprise"].slider.value() == 0
    qtbot.waitUntil(lambda: np.array_equal(viewport_image(window), before), timeout=5000)
    assert not window.isWindowModified()


def test_split_view_shows_t1_t2_and_automatic_side_by_side(window):
    window.doc.set_pose_weight("surprise", 1.0)
    combo = window.shading_panel.technique
    combo.setCurrentIndex(combo.findData("split"))
    combo.activated.emit(combo.currentIndex())
    assert window.doc.view.split
    with_t2 = viewport_image(window)
    window.doc.set_expression_factor(0.0)  # hides technique 2's wrinkles only
    without_t2 = viewport_image(window)
    (x1, w1), (x2, w2), (x3, w3) = split_columns(with_t2.shape[1])
    assert np.array_equal(with_t2[:, x1:x1 + w1], without_t2[:, x1:x1 + w1])  # t1 untouched
    assert np.array_equal(with_t2[:, x3:x3 + w3], without_t2[:, x3:x3 + w3])  # strain untouched
    middle = np.abs(with_t2[:, x2:x2 + w2].astype(int) - without_t2[:, x2:x2 + w2].astype(int))
    assert (middle.max(axis=2) > 8).sum() > 100
    labels = [lbl.text() for lbl in window.viewport._labels if lbl.isVisible()]
    assert [t.split(" ·")[0] for t in labels] == ["Technique 1", "Technique 2", "Automatic"]


def test_the_expression_factor_changes_a_uniform_not_the_wrinkle_vectors(window, monkeypatch):
    """Dragging the expression factor redraws technique 2 without repacking every vertex's
    wrinkle vectors (upload only what changed)."""
    window.doc.set_pose_weight("surprise", 1.0)
    before = viewport_image(window)
    packed = []
    real = WdvSetup.pack_slots
    monkeypatch.setattr(WdvSetup, "pack_slots",
                        lambda self, *a, **k: packed.append(1) or real(self, *a, **k))
    window.doc.set_expression_factor(0.3)
    after = viewport_image(window)
    assert not packed
    assert (np.abs(before.astype(int) - after.astype(int)).max(axis=2) > 8).sum() > 100


def test_save_then_open_gives_an_equal_document(window, tmp_path):
    window.doc.set_pose_weight("frown", 0.6)
    window.doc.set_expression_factor(0.7)
    path = tmp_path / "face.wrinkle"
    assert window.save_to(path)
    assert not window.isWindowModified()
    assert "face" in window.windowTitle()
    image = viewport_image(window)
    original = window.doc.project
    reopened = load_project(path)
    for name in ("rest", "triangles", "uvs", "weld"):
        assert np.array_equal(getattr(reopened.mesh, name), getattr(original.mesh, name))
    for a, b in zip(reopened.poses, original.poses, strict=True):
        assert a.name == b.name and np.array_equal(a.positions, b.positions)
    for name in ("diffuse", "normal_neutral", "normal_wrinkled"):
        assert np.array_equal(getattr(reopened.textures, name), getattr(original.textures, name))
    for a, b in zip(reopened.influence.areas, original.influence.areas, strict=True):
        assert a.name == b.name and np.abs(a.mask - b.mask).max() <= 1 / 65535
    assert reopened.wdv.expression_factor == pytest.approx(0.7)
    for a, b in zip(reopened.wdv.areas, original.wdv.areas, strict=True):
        assert np.array_equal(a.directions, b.directions)
    assert window.open_path(path)
    assert window.doc.pose_weights["frown"] == pytest.approx(0.6)
    assert np.array_equal(viewport_image(window), image)


def test_a_corrupt_file_shows_an_error_and_keeps_the_project(window, tmp_path, dialogs):
    bad = tmp_path / "broken.wrinkle"
    bad.write_bytes(b"PK\x03\x04 this is not really a zip")
    project = window.doc.project
    window.doc.set_pose_weight("surprise", 0.5)
    window.doc.set_expression_factor(0.5)
    assert not window.open_path(bad)
    assert len(dialogs) == 1 and dialogs[0][0] == "critical" and "broken.wrinkle" in dialogs[0][1]
    assert window.doc.project is project
    assert window.doc.pose_weights["surprise"] == 0.5
    assert window.doc.undo_stack.count() == 1


def test_expression_factor_control_is_undoable(window, qtbot):
    row = window.shading_panel.expression
    row.spin.setValue(0.25)
    assert window.doc.project.wdv.expression_factor == pytest.approx(0.25)
    window.doc.undo_stack.undo()
    assert window.doc.project.wdv.expression_factor == pytest.approx(1.0)
    assert row.value() == pytest.approx(1.0)


def test_f_frames_the_face_after_zooming(window, qtbot):
    window.viewport.setFocus()
    qtbot.keyClick(window.viewport, Qt.Key.Key_F)
    distance = window.doc.camera.distance
    window.doc.camera.zoom(3.0)
    qtbot.keyClick(window.viewport, Qt.Key.Key_F)
    assert window.doc.camera.distance == pytest.approx(distance)


def test_screenshot_command_writes_the_window(tmp_path):
    out = tmp_path / "shot.png"
    env = dict(os.environ)
    result = subprocess.run([sys.executable, "-m", "studio.cli", "--screenshot", str(out)],
                            capture_output=True, text=True, timeout=180, env=env)
    assert result.returncode == 0, result.stderr
    from PIL import Image

    image = np.asarray(Image.open(out).convert("RGB"))
    assert image.shape[0] > 400 and image.shape[1] > 600
    assert image.std() > 10  # not a blank window


def test_anti_aliasing_off_hardens_only_the_edges_and_is_remembered(window, open_window, qtbot,
                                                                    sample):
    from studio.widgets.main_window import settings

    vp = window.viewport
    assert window.anti_aliasing[4].isChecked() and vp.samples == 4
    smooth = viewport_image(window)
    try:
        frames = vp.frames_rendered
        window.anti_aliasing[0].trigger()  # View ▸ Anti-Aliasing ▸ Off
        qtbot.waitUntil(lambda: vp.frames_rendered > frames, timeout=10000)
        hard = viewport_image(window)
        changed = np.abs(hard.astype(int) - smooth.astype(int)).max(axis=2) > 8
        # edges: where the hard image itself jumps between neighbouring pixels
        grey = hard.astype(int).sum(axis=2)
        jump = np.zeros_like(changed)
        # (20: the shaded side of the face meets the dark background by a small step)
        jump[:, 1:] |= np.abs(np.diff(grey, axis=1)) > 20
        jump[1:] |= np.abs(np.diff(grey, axis=0)) > 20
        near_jump = jump.copy()
        near_jump[:, :-1] |= jump[:, 1:]
        near_jump[:-1] |= jump[1:]
        assert changed.sum() > 200  # the silhouette lost its blended pixels
        assert (changed & near_jump).sum() > 0.9 * changed.sum()  # and nothing else changed
        assert int(settings().value("viewport/samples")) == 0
        again = open_window(sample)  # a new window starts with the remembered choice
        assert again.anti_aliasing[0].isChecked() and again.viewport.samples == 0
        assert np.array_equal(viewport_image(again), hard)
        most = vp.max_samples
        assert window.anti_aliasing[8].isEnabled() == (most >= 8)
    finally:
        window.set_anti_aliasing(4)
    assert int(settings().value("viewport/samples")) == 4
