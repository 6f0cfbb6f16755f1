"""Issue #28: an area whose weight lands on a flat part of its wrinkled map is flagged in its
panel with the reason, and the heat of what shows is cold there while the heat of the weight
is hot — driven like a user on a hand-built face."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from studio.core.animation.poses import KeyPose
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.wdv import WdvArea, wrinkle_directions
from tests.gui_helpers import viewport_image
from tests.hand_faces import grid_face, tilted_map

SIZE = 64
REASON = "reveals a flat part of 'wrinkles 2': 100 % of its weight shows nothing"


@pytest.fixture
def flat_left(open_window):
    """'wrinkles 2' has a furrow (a tilt) on the right half only; the technique-1 area
    "forehead left" and the technique-2 area "squint left" reveal it on the left half, the
    area "forehead right" on the right half. Technique 1 shows, both areas at full
    activation."""
    right = np.zeros((SIZE, SIZE), bool)
    right[:, SIZE // 2:] = True
    project = grid_face({"wrinkles": tilted_map(SIZE, 192),
                         "wrinkles 2": tilted_map(SIZE, 192, right)})
    left_mask = (~right).astype(np.float32)
    project.influence.areas = [
        InfluenceArea("forehead left", left_mask, activation=1.0, wrinkle_map="wrinkles 2"),
        InfluenceArea("forehead right", 1.0 - left_mask, activation=1.0,
                      wrinkle_map="wrinkles 2")]
    rest = project.mesh.rest
    moved = rest[:, 0] < -1e-9
    posed = rest.copy()
    posed[moved, 1] += 0.05
    project.poses = [KeyPose("squint", posed)]
    result = wrinkle_directions(rest, posed, np.flatnonzero(moved))
    project.wdv.areas = [WdvArea("squint left", "squint", result.directions, result.lengths,
                                 wrinkle_map="wrinkles 2")]
    project.view["view"] = {"technique": "t1"}
    return open_window(project)


def click_row(qtbot, widget, row: int) -> None:
    rect = widget.visualItemRect(widget.item(row))
    qtbot.mouseClick(widget.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())


def test_the_areas_panel_flags_the_area_on_the_flat_part_with_the_reason(flat_left, qtbot):
    window = flat_left
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    panel = window.mask_tools.panel
    left, right = panel.rows
    qtbot.waitUntil(lambda: not left.flag.isHidden())  # measured once the window is up
    assert right.flag.isHidden()
    assert REASON in left.flag.toolTip()
    click_row(qtbot, panel.list, 1)
    assert panel.flat_note.isHidden()
    click_row(qtbot, panel.list, 0)
    assert not panel.flat_note.isHidden()
    assert panel.flat_note.text() == f"This area {REASON}."


def test_the_wrinkle_vectors_panel_flags_its_area_with_the_reason(flat_left, qtbot):
    window = flat_left
    window.docks["Wrinkle vectors"].show()
    window.docks["Wrinkle vectors"].raise_()
    panel = window.wdv_tools.panel
    click_row(qtbot, panel.area_list, 0)
    assert window.wdv_tools.current_area.name == "squint left"
    qtbot.waitUntil(lambda: not panel.flat_label.isHidden())  # measured once the click settles
    assert REASON in panel.flat_label.text()


def heat_at(window, x: float) -> tuple[float, float]:
    """Mean red and blue of the viewport around the grid's point (x, 0, 0)."""
    image = viewport_image(window).astype(float)
    h, w = image.shape[:2]
    pixels, _ = window.doc.camera.project(np.array([[x, 0.0, 0.0]]), w, h)
    px, py = pixels[0]
    patch = image[int(py) - 4:int(py) + 5, int(px) - 4:int(px) + 5]
    return patch[..., 0].mean(), patch[..., 2].mean()


def test_the_heat_of_what_shows_is_cold_where_the_weight_is_hot_on_a_flat_map(flat_left,
                                                                               qtbot):
    window = flat_left
    window.docks["Shading"].show()
    window.docks["Shading"].raise_()
    combo = window.shading_panel.debug_view
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    assert window.doc.view.debug_view == "heat"
    qtbot.waitUntil(lambda: heat_at(window, -0.5)[0] > heat_at(window, -0.5)[1] + 40)
    red, blue = heat_at(window, 0.5)
    assert red > blue + 40  # both halves fully weighted: hot
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    assert combo.currentText() == "Heat: what shows"
    assert window.doc.view.debug_view == "heat-shows"
    qtbot.waitUntil(lambda: heat_at(window, -0.5)[1] > heat_at(window, -0.5)[0] + 40)
    red, blue = heat_at(window, 0.5)
    assert red > blue + 40  # the furrow's half shows
