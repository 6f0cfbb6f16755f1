"""The workspace on a 1440×900 window, driven with real events (issue 28): the viewport gets
most of the window and Reset Layout brings that back; the timeline shows what was sequenced and
keeps the playhead on screen; F looks at the face from its front; Save As starts where the
project's files are; technique 2's vectors follow the task; the UV canvas outlines what is not
skin."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QRect, Qt
from PySide6.QtWidgets import QFileDialog, QTabBar

from studio.core.animation.timeline import Timeline
from studio.widgets.app_settings import settings
from studio.widgets.main_window import TIMELINE_HEIGHT
from studio.widgets.paint.uv_canvas import outline_edges
from tests.gui_helpers import viewport_image, viewport_marks


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1440, 900)


@pytest.fixture(autouse=True)
def forget_layout():
    """The windows here raise other tabs and move docks; what they save on closing must not
    become the next test module's layout."""
    yield
    s = settings()
    for key in ("window/geometry", "window/state"):
        s.remove(key)


@pytest.fixture
def opened(open_window, qtbot):
    """Opens a window on a project and waits for its layout: docks take their sizes a moment
    after the window shows."""
    def open_(project):
        window = open_window(project)
        timeline = window.docks["Timeline"]
        qtbot.waitUntil(lambda: timeline.height() <= TIMELINE_HEIGHT + 8)
        return window

    return open_


@pytest.fixture
def fresh(opened, sample):
    """The sample face in a window opened with no remembered layout (as on a first start)."""
    s = settings()
    for key in ("window/geometry", "window/state"):
        s.remove(key)
    return opened(sample)


@pytest.fixture
def window(opened, sample):
    return opened(sample)


def viewport_share(window) -> float:
    vp = window.viewport
    return vp.width() * vp.height() / (window.width() * window.height())


def click_tab(qtbot, window, title: str) -> None:
    """Click a dock's tab in the right-hand column, as a user would."""
    on_screen = [bar for bar in window.findChildren(QTabBar) if bar.isVisible()
                 and window.rect().intersects(QRect(bar.mapTo(window, QPoint()), bar.size()))]
    for bar in on_screen:  # (the main window keeps old tab bars around, off screen)
        for i in range(bar.count()):
            if bar.tabText(i) == title:
                qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(i).center())
                return
    raise AssertionError(f"no tab {title!r}")


def test_the_viewport_has_most_of_a_fresh_window_and_reset_layout_restores_it(fresh, qtbot):
    window = fresh
    assert (window.width(), window.height()) == (1440, 900)
    assert viewport_share(window) >= 0.5
    image = viewport_image(window)
    x, y = viewport_marks(window)["nose tip"]
    assert np.abs(image[y, x].astype(int) - image[5, 5].astype(int)).sum() > 40  # the face
    right = Qt.DockWidgetArea.RightDockWidgetArea
    for title in ("Poses", "Shading", "Areas", "Wrinkle vectors", "UV Paint"):
        assert window.dockWidgetArea(window.docks[title]) == right
    # the user drags the column wide and floats the timeline; Reset Layout brings it back
    window.resizeDocks([window.docks["Poses"]], [700], Qt.Orientation.Horizontal)
    window.docks["Timeline"].setFloating(True)
    qtbot.waitUntil(lambda: viewport_share(window) < 0.5 or window.docks["Timeline"].isFloating())
    reset = next(a for a in window.menus["View"].actions() if a.text() == "Reset &Layout")
    reset.trigger()
    qtbot.waitUntil(lambda: not window.docks["Timeline"].isFloating())
    qtbot.waitUntil(lambda: viewport_share(window) >= 0.5)
    assert window.docks["Timeline"].isVisible()


def test_sequencing_fits_the_time_axis_and_the_playhead_stays_on_screen(opened, sample, qtbot):
    sample.timeline = Timeline()  # frames 0 to 96, no keys
    window = opened(sample)
    panel = window.timeline_panel
    qtbot.mouseClick(panel.sequence, Qt.MouseButton.LeftButton)
    timeline = window.doc.project.timeline
    last = max(k.frame for t in timeline.tracks for k in t.keys)
    assert timeline.end >= last > 96  # five poses, 1.5 s each: past the old range
    lo, hi = panel.track_box.viewRange()[0]
    assert lo <= timeline.start and hi >= last  # all of it shown, not 0–96
    shown = panel.visible_rows()  # whole rows from the top, each tall enough to click a weight
    assert len(shown) >= 2 and shown == panel.poses[:len(shown)]
    # the curve plot has room in the default layout
    assert panel.curves.isVisible() and panel.curves.getViewBox().height() >= 40
    # zoomed in on the start, the End key moves the playhead off the shown range: the view
    # pages so that the playhead stays on screen
    panel.tracks.setXRange(0, 20, padding=0)
    qtbot.mouseClick(panel.buttons["end"], Qt.MouseButton.LeftButton)
    assert window.doc.frame == timeline.end
    lo, hi = panel.track_box.viewRange()[0]
    assert lo <= timeline.end <= hi
    assert hi - lo == pytest.approx(20)  # paged, not re-zoomed
    # a scrub started on the playhead where it now is moves it
    middle = panel.view.mapFromScene(panel.track_box.sceneBoundingRect().center())
    playhead_x = panel.key_widget_pos(panel.poses[0], timeline.end, 0.5).x()
    viewport = panel.view.viewport()
    qtbot.mouseMove(viewport, QPoint(playhead_x, middle.y()))  # the hand reaches it first
    qtbot.mousePress(viewport, Qt.MouseButton.LeftButton, pos=QPoint(playhead_x, middle.y()))
    for i in range(1, 11):
        qtbot.mouseMove(viewport, QPoint(playhead_x - 8 * i, middle.y()))
        qtbot.wait(5)  # a hand's pace: each move handled before the next
    qtbot.mouseRelease(viewport, Qt.MouseButton.LeftButton,
                       pos=QPoint(playhead_x - 80, middle.y()))
    assert window.doc.frame < timeline.end
    lo, hi = panel.track_box.viewRange()[0]
    assert lo <= window.doc.frame <= hi


def test_many_poses_scroll_their_rows_and_leave_the_curves_room(opened, sample):
    sample.poses = [*sample.poses, *(replace(p, name=f"{p.name} copy") for p in sample.poses)]
    names = [p.name for p in sample.poses]
    assert len(names) == 10
    window = opened(sample)
    panel = window.timeline_panel
    shown = panel.visible_rows()
    assert 2 <= len(shown) < 10 and shown == names[:len(shown)]  # from the top, whole rows
    assert panel.rows.isVisible()
    assert panel.curves.getViewBox().height() >= 40
    panel.rows.setValue(panel.rows.maximum())
    assert panel.visible_rows()[-1] == names[-1]


def test_f_frames_the_face_from_its_front_after_an_orbit(window, qtbot):
    vp = window.viewport
    start = QPoint(vp.width() // 2, vp.height() // 2)
    qtbot.mousePress(vp, Qt.MouseButton.MiddleButton, pos=start)
    for i in range(1, 9):
        qtbot.mouseMove(vp, start + QPoint(10 * i, 6 * i))
    qtbot.mouseRelease(vp, Qt.MouseButton.MiddleButton, pos=start + QPoint(80, 48))
    marks = viewport_marks(window)
    vp.setFocus()
    qtbot.keyClick(vp, Qt.Key.Key_F)
    assert (window.doc.camera.yaw, window.doc.camera.pitch) == (0.0, 0.0)
    marks = viewport_marks(window)
    centre = vp.width() * vp.devicePixelRatioF() / 2
    left, right = marks["eye corner left"][0], marks["eye corner right"][0]
    assert abs((left - centre) + (right - centre)) <= 3  # the eyes mirror about the middle
    image = viewport_image(window)
    x, y = marks["nose tip"]
    assert np.abs(image[y, x].astype(int) - image[5, 5].astype(int)).sum() > 40


def test_save_as_of_a_new_project_starts_in_its_files_folder(window, qtbot, tmp_path,
                                                             monkeypatch):
    folder = tmp_path / "character"
    folder.mkdir()
    window.doc.project.mesh.source = str(folder / "neutral.obj")
    asked: list[str] = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda parent, title, start, *a: asked.append(start)
                                     or ("", "")))
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_S,
                   Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert [Path(a).parent for a in asked] == [folder]


def test_vectors_show_for_the_current_area_while_their_panel_is_open(window, qtbot):
    tools = window.wdv_tools
    click_tab(qtbot, window, "Poses")
    qtbot.waitUntil(lambda: not tools.panel_open)
    assert len(tools.overlay._lines[0]) == 0  # another task: no needles over the face
    hidden = viewport_image(window)
    click_tab(qtbot, window, "Wrinkle vectors")
    qtbot.waitUntil(lambda: tools.panel_open)
    current = tools.current_area
    assert current is not None
    assert len(tools.overlay._lines[0]) == 2 * int(current.authored.sum())
    shown = viewport_image(window)
    assert (np.abs(shown.astype(int) - hidden.astype(int)).max(axis=2) > 30).sum() > 20
    qtbot.mouseClick(tools.panel.all_areas_check, Qt.MouseButton.LeftButton)
    areas = [a for a in window.doc.project.wdv.areas if a.enabled]
    lines, colours = tools.overlay._lines
    assert len(lines) == 2 * sum(int(a.authored.sum()) for a in areas)
    assert sorted(set(np.round(colours[1::2, 3], 3))) == [0.25, 1.0]  # others faint


def test_outline_edges_keep_only_the_border_of_a_piece():
    # two triangles sharing the edge 1–2 make a quad: its four sides, not the diagonal
    quad = np.array([[0, 1, 2], [2, 1, 3]])
    assert sorted(map(tuple, outline_edges(quad).tolist())) == [(0, 1), (0, 2), (1, 3), (2, 3)]
    assert len(outline_edges(np.zeros((0, 3), int))) == 0


def test_the_uv_canvas_draws_the_skin_wireframe_and_outlines_the_rest(opened, sample, qtbot):
    """(The canvas is drawn once its tab is in front: behind another it waits.)"""
    mesh = sample.mesh
    not_face = np.zeros(mesh.n_welded, bool)
    not_face[mesh.welded_triangles[:40].ravel()] = True  # an "eye": the first 40 triangles
    sample.not_face = not_face
    window = opened(sample)
    canvas = window.mask_tools.canvas
    assert not canvas.wire.lines  # behind the Poses tab at start: not built yet
    click_tab(qtbot, window, "UV Paint")
    qtbot.waitUntil(lambda: bool(canvas.wire.lines))
    skin = sample.skin_triangles()
    assert 0 < (~skin).sum() < len(skin)
    rest = mesh.triangles[~skin]
    assert len(canvas.outline.lines) == len(outline_edges(rest))
    assert len(canvas.outline.lines) < 3 * len(rest)  # outlined, not meshed
    inside = {tuple(e) for e in np.sort(rest[:, :2], axis=1).tolist()} - {
        tuple(e) for e in outline_edges(rest).tolist()}
    skin_edges = {tuple(e) for e in np.sort(np.concatenate(
        [mesh.triangles[skin][:, [0, 1]], mesh.triangles[skin][:, [1, 2]],
         mesh.triangles[skin][:, [2, 0]]]), axis=1).tolist()}
    assert len(canvas.wire.lines) == len(skin_edges)
    assert inside - skin_edges  # some of the eye's inner edges are drawn by neither


def test_a_panels_toolbar_button_brings_it_from_behind_another_tab(window, qtbot):
    dock = window.docks["UV Paint"]
    click_tab(qtbot, window, "Poses")
    canvas = window.mask_tools.canvas
    qtbot.waitUntil(lambda: canvas.visibleRegion().isEmpty())  # behind the Poses tab
    button = window.panels_bar.widgetForAction(dock.toggleViewAction())
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not canvas.visibleRegion().isEmpty())  # in front, not closed
    assert not dock.isHidden() and canvas.width() > 200
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)  # in front: the button closes it
    qtbot.waitUntil(dock.isHidden)
