"""The workflow a person meets (issue #35): panels that fit their column, a wheel that scrolls
instead of editing, and linking an area the way MetaHuman's "driven by" lists do. Real clicks,
keys and wheel turns; the document and the picture checked.

Seen red, each once: with the Areas panel's old 380-pixel minimum (and its button grid), the
fit test finds a horizontal scroll bar and cut buttons; without the wheel guard, the unfocused
wheel changes Painted θ; with duplicate_area copying no links, the copy is driven by nothing;
with Auto mask revealing the first map, the squeeze's area reveals "brow"; with no Solo, no
button is found.
"""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import (
    QAbstractButton,
    QAbstractScrollArea,
    QApplication,
    QPushButton,
    QScrollArea,
)

from studio.widgets.slider_row import SliderRow
from tests.gui_helpers import bring_forward, viewport_image

RIGHT_COLUMN = ("Poses", "Shading", "Areas", "Wrinkle vectors")


def _wheel(widget, steps: int) -> None:
    """A wheel turn with the pointer over ``widget``, delivered as Qt delivers one."""
    centre = widget.rect().center()
    event = QWheelEvent(QPointF(centre), QPointF(widget.mapToGlobal(centre)), QPoint(),
                        QPoint(0, 120 * steps), Qt.MouseButton.NoButton,
                        Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(widget, event)


def _button(root, text: str) -> QPushButton:
    return next(b for b in root.findChildren(QPushButton) if b.text() == text)


@pytest.mark.parametrize("window_size", [(1440, 900), (1920, 1080)])
def test_every_panel_fits_its_column_and_no_button_is_cut(open_window, window_size, qtbot):
    from studio.widgets.main_window import sample_project

    window = open_window(sample_project())
    for title in RIGHT_COLUMN:
        dock = window.docks[title]
        dock.show()
        dock.raise_()
        qtbot.wait(100)
        for area in dock.findChildren(QAbstractScrollArea):
            if isinstance(area, QScrollArea) and area.isVisible():
                bar = area.horizontalScrollBar()
                assert not bar.isVisible() and bar.maximum() == 0, \
                    f"{title}: a horizontal scroll bar ({bar.maximum()} px too wide)"
        for row in dock.findChildren(SliderRow):
            if row.isVisible():
                assert row.slider.width() >= 100, \
                    f"{title}: the slider of {row.label.text()} is {row.slider.width()} px"
        for button in dock.findChildren(QAbstractButton):
            if button.isVisible() and button.text():
                assert button.width() >= button.sizeHint().width() - 1, \
                    f"{title}: “{button.text()}” is cut ({button.width()} < " \
                    f"{button.sizeHint().width()} px)"


def test_the_wheel_over_an_unfocused_field_scrolls_the_panel_and_changes_nothing(window, qtbot):
    doc = window.doc
    panel = window.wdv_tools.panel
    bring_forward(panel)
    window.resize(1200, 500)  # short: the panel scrolls
    qtbot.wait(100)
    field = panel.cone_paint
    panel.ensureWidgetVisible(field)
    scroll = panel.verticalScrollBar()
    scroll.setValue(scroll.minimum() + (scroll.maximum() - scroll.minimum()) // 2)
    qtbot.wait(50)
    before, at, steps = field.value(), scroll.value(), doc.undo_stack.count()
    _wheel(field, -1)  # the pointer passes over the field while scrolling down
    assert field.value() == before and doc.undo_stack.count() == steps
    assert scroll.value() > at  # the panel scrolled instead
    qtbot.mouseClick(field, Qt.MouseButton.LeftButton)  # clicked: now the wheel is its own
    _wheel(field, 1)
    assert field.value() == pytest.approx(before + field.singleStep())


def test_an_area_is_driven_by_the_poses_added_to_it_by_name(window, qtbot):
    doc = window.doc
    panel = window.mask_tools.panel
    bring_forward(panel)
    panel.select([a.name for a in doc.project.influence.areas].index("cheeks"))
    assert list(panel.link_spins) == ["squeeze"]  # only what drives it, not every pose
    doc.set_view(technique="t1")
    doc.set_pose_weight("frown", 1.0)
    qtbot.wait(200)
    before = viewport_image(window)
    line = panel.add_pose.lineEdit()
    panel.ensureWidgetVisible(panel.add_pose)
    qtbot.mouseClick(line, Qt.MouseButton.LeftButton)
    qtbot.keyClicks(line, "frown")
    qtbot.keyClick(line, Qt.Key.Key_Return)
    assert doc.project.influence.links["frown"]["cheeks"] == 1.0
    assert list(panel.link_spins) == ["squeeze", "frown"]
    assert QApplication.focusWidget() is panel.link_spins["frown"]  # on to its gain
    qtbot.waitUntil(lambda: not np.array_equal(viewport_image(window), before), timeout=5000)
    remove = panel.link_editors["frown"].remove
    qtbot.mouseClick(remove, Qt.MouseButton.LeftButton)  # ✕ unlinks
    assert "cheeks" not in doc.project.influence.links.get("frown", {})
    qtbot.waitUntil(lambda: list(panel.link_spins) == ["squeeze"], timeout=2000)
    doc.undo_stack.undo()
    assert doc.project.influence.links["frown"]["cheeks"] == 1.0


def test_duplicate_keeps_the_links_and_auto_mask_reveals_the_poses_map(window, qtbot):
    doc = window.doc
    panel = window.mask_tools.panel
    bring_forward(panel)
    names = [a.name for a in doc.project.influence.areas]
    panel.select(names.index("between brows"))
    qtbot.mouseClick(_button(panel, "Duplicate"), Qt.MouseButton.LeftButton)
    copy = doc.project.influence.areas[names.index("between brows") + 1]
    assert copy.name == "between brows copy"
    assert doc.project.influence.links["frown"][copy.name] == 1.0
    assert copy.wrinkle_map == doc.project.influence.areas[names.index("between brows")].wrinkle_map

    # the squeeze's furrows are on "eyes and cheeks", not the first map ("brow")
    combo = panel.auto_pose
    panel.ensureWidgetVisible(combo)
    qtbot.mouseClick(combo, Qt.MouseButton.LeftButton)
    view = combo.view()
    qtbot.keyClick(view, Qt.Key.Key_Home)
    for _ in range(combo.findText("squeeze")):
        qtbot.keyClick(view, Qt.Key.Key_Down)
    qtbot.keyClick(view, Qt.Key.Key_Return)
    qtbot.mouseClick(_button(panel, "Auto mask"), Qt.MouseButton.LeftButton)
    made = doc.project.influence.areas[-1]
    assert made.name == "squeeze auto" and made.wrinkle_map == "eyes and cheeks"
    assert panel.map_combo.currentText() == "eyes and cheeks"


def test_solo_shows_one_area_and_again_all(window, qtbot):
    doc = window.doc
    panel = window.mask_tools.panel
    bring_forward(panel)
    areas = doc.project.influence.areas
    panel.select(2)
    solo = _button(panel, "Solo")
    qtbot.mouseClick(solo, Qt.MouseButton.LeftButton)
    assert [a.visible for a in areas] == [i == 2 for i in range(len(areas))]
    assert [r.visible.isChecked() for r in panel.rows] == [a.visible for a in areas]
    qtbot.mouseClick(_button(panel, "Solo"), Qt.MouseButton.LeftButton)
    assert all(a.visible for a in areas)
    doc.undo_stack.undo()
    assert [a.visible for a in areas] == [i == 2 for i in range(len(areas))]


def test_the_sample_opens_on_an_expression_and_save_as_starts_outside_the_studio(
        open_window, qtbot, monkeypatch, tmp_path):
    """The first thing a person sees shows what the tool does (an expression at its height,
    not a neutral face), and Save As does not offer the studio's own install folder."""
    from PySide6.QtWidgets import QFileDialog

    from studio.paths import resource_dir
    from studio.widgets.main_window import sample_project, settings

    settings().setValue("last_folder", str(tmp_path / "somewhere.wrinkle"))
    window = open_window(sample_project())
    doc = window.doc
    assert doc.frame > doc.project.timeline.start
    assert max(doc.pose_weights.values()) == pytest.approx(1.0)
    started: list[str] = []

    def ask(parent, title, start, *args, **kwargs):
        started.append(start)
        return "", ""

    monkeypatch.setattr(QFileDialog, "getSaveFileName", staticmethod(ask))
    save_as = next(a for a in window.menus["File"].actions() if "Save As" in a.text()
                   .replace("&", ""))
    save_as.trigger()
    assert started and not str(started[0]).startswith(str(resource_dir().resolve()))
    assert started[0].startswith(str(tmp_path))


def test_getting_started_shows_at_the_first_start_only_and_help_brings_it_back(qtbot, dialogs,
                                                                               sample):
    from studio.widgets.getting_started import SEEN_KEY
    from studio.widgets.main_window import MainWindow, settings

    store = settings()  # a first start: no layout saved by an earlier window either (a
    for key in (SEEN_KEY, "window/state", "window/geometry"):  # layout restores its docks)
        store.remove(key)
    windows = []
    for _ in range(2):
        w = MainWindow(copy_of(sample))
        w.resize(1200, 800)
        w.show()
        qtbot.waitExposed(w)
        qtbot.wait(50)
        windows.append(w)
    first, second = (w.docks["Getting started"] for w in windows)
    assert first.isVisible() and not first.visibleRegion().isEmpty()  # in front of its tabs
    assert "Technique 1" in first.widget().toPlainText()
    assert second.isHidden()  # seen once: not again
    help_entry = next(a for a in windows[1].menus["Help"].actions() if "Getting" in a.text())
    help_entry.trigger()
    qtbot.waitUntil(lambda: not second.visibleRegion().isEmpty(), timeout=3000)
    for w in windows:
        w.doc.undo_stack.setClean()
        w.close()


def copy_of(project):
    import copy

    return copy.deepcopy(project)


@pytest.mark.parametrize("window_size", [(1440, 900)])
def test_the_paint_layout_puts_the_uv_canvas_and_the_face_side_by_side(window, qtbot):
    layout = next(a for a in window.menus["View"].actions() if "Paint Layout" in a.text()
                  .replace("&", ""))
    layout.trigger()
    canvas = window.mask_tools.canvas
    qtbot.waitUntil(lambda: canvas.width() >= 0.33 * window.width(), timeout=3000)
    assert window.viewport.isVisible()
    assert abs(window.viewport.width() - canvas.width()) <= 0.1 * canvas.width()
    areas = window.mask_tools.panel
    assert not areas.visibleRegion().isEmpty()  # the brush and links beside it
    reset = next(a for a in window.menus["View"].actions() if "Reset Layout" in a.text()
                 .replace("&", ""))
    reset.trigger()
    qtbot.waitUntil(lambda: window.viewport.width() >= 0.6 * window.width(), timeout=3000)


def test_an_influence_area_is_renamed_in_place_like_a_vector_area(window, qtbot, dialogs):
    """F2 (or double-click) edits the name in the list, Return keeps it, Escape drops it —
    as the Wrinkle vectors list does; no dialog. Seen red with the old Rename… dialog."""
    doc = window.doc
    panel = window.mask_tools.panel
    bring_forward(panel)
    panel.select(1)
    qtbot.mouseClick(panel.list.viewport(), Qt.MouseButton.LeftButton,
                     pos=panel.list.visualItemRect(panel.list.item(1)).center())
    qtbot.keyClick(panel.list, Qt.Key.Key_F2)
    editor = panel.rows[1].editor
    assert editor.isVisible() and QApplication.focusWidget() is editor
    qtbot.keyClicks(editor, "brow, left")
    qtbot.keyClick(editor, Qt.Key.Key_Return)
    assert doc.project.influence.areas[1].name == "brow, left" and dialogs == []
    assert panel.rows[1].name.text() == "brow, left"
    panel.rows[1].rename()  # the Rename button's way in
    editor = panel.rows[1].editor
    qtbot.keyClicks(editor, "nope")
    qtbot.keyClick(editor, Qt.Key.Key_Escape)
    assert doc.project.influence.areas[1].name == "brow, left"
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert doc.project.influence.areas[1].name != "brow, left"


def test_moving_a_pose_slider_shows_the_face_and_leaves_the_project_saved(window, qtbot,
                                                                          tmp_path):
    """Looking at an expression edits nothing (issue #35): a value typed into a pose's field
    moves the face, adds no undo step and no '*' to the title, and is still saved with the
    project like the camera. Seen red: with the weight an undo step, the project is modified."""
    from studio.core.project.reader import load_project

    doc = window.doc
    bring_forward(window.pose_panel)
    assert not doc.modified
    steps = doc.undo_stack.count()
    before = viewport_image(window)
    spin = window.pose_panel.pose_rows["frown"].spin
    qtbot.mouseClick(spin, Qt.MouseButton.LeftButton)
    spin.selectAll()
    qtbot.keyClicks(spin, "0.35")
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    assert doc.pose_weights["frown"] == pytest.approx(0.35)
    qtbot.waitUntil(lambda: not np.array_equal(viewport_image(window), before), timeout=5000)
    assert not doc.modified and doc.undo_stack.count() == steps
    assert not window.isWindowModified()  # no "*" in the title
    assert window.save_to(tmp_path / "looked.wrinkle")
    assert load_project(tmp_path / "looked.wrinkle").view["pose_weights"]["frown"] == \
        pytest.approx(0.35)
