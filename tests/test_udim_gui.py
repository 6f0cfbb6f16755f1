"""A UDIM-tiled head in the studio: the UV canvas shows its tiles, opens on the skin tile, and a
stroke painted there lands in the skin tile's mask (and its per-tile export) — driven with real
mouse and key events."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPointF, Qt
from PySide6.QtWidgets import QPushButton

from studio.core.files.images import read_image
from studio.core.formats.assemble import project_from_files
from studio.core.formats.export import export_folder
from tests.production_head import POSES, build_head


@pytest.fixture(scope="module")
def head_files(tmp_path_factory):
    head = build_head("mm")
    return head, head.write_set(tmp_path_factory.mktemp("udim"), POSES[:2])


def uv_scene_point(window, head, point: tuple[float, float]) -> QPointF:
    """The canvas (mask pixel) position of a point of the face in sample coordinates."""
    project = window.doc.project
    face = head.to_sample(project.mesh.rest)
    welded = np.argmin(np.hypot(*(face[:, :2] - point).T) + 10.0 * (face[:, 2] < 0.2))
    render = np.flatnonzero(project.mesh.weld == welded)[0]
    u, v = project.mesh.uvs[render]
    h, w = project.influence.resolution
    return QPointF(u * w, (1.0 - v) * h)


def test_the_canvas_shows_the_tiles_and_a_stroke_lands_in_the_skin_tile(
        open_window, head_files, qtbot, tmp_path):
    head, files = head_files
    project = project_from_files(files["neutral"], {p: files[p] for p in POSES[:2]},
                                 not_face=["eye_L", "eye_R", "teeth"])
    window = open_window(project)
    window.docks["UV Paint"].show()
    window.docks["UV Paint"].raise_()  # a tab in the right-hand column
    panel = window.mask_tools.panel
    add = next(b for b in panel.findChildren(QPushButton) if b.text() == "Add")
    qtbot.mouseClick(add, Qt.MouseButton.LeftButton)
    canvas = window.mask_tools.canvas
    qtbot.waitUntil(lambda: canvas.view.isVisible())

    # the tile chooser lists the three tiles (built once the canvas is on screen), the skin one
    # chosen and framed
    qtbot.waitUntil(lambda: canvas.tile.count() > 0)
    labels = [canvas.tile.itemText(i) for i in range(canvas.tile.count())]
    assert labels == ["All tiles", "1001 (skin)", "1002", "1003"]
    assert canvas.tile.currentData() == 1001
    layout = window.doc.project.uv_tiles.layout
    h, w = window.doc.project.influence.resolution
    visible = canvas.view.mapToScene(canvas.view.viewport().rect()).boundingRect()
    x, y, side = layout.cells[0]
    assert visible.contains(QPointF((x + side / 2) * w, (y + side / 2) * h))
    assert visible.width() < 0.75 * w  # the skin tile, not the whole atlas

    # choose "All tiles" from the keyboard: the whole atlas comes into view
    canvas.tile.setFocus()
    qtbot.keyClick(canvas.tile, Qt.Key.Key_Home)
    assert canvas.tile.currentData() is None
    visible = canvas.view.mapToScene(canvas.view.viewport().rect()).boundingRect()
    assert visible.width() >= w and visible.height() >= h
    qtbot.keyClick(canvas.tile, Qt.Key.Key_Down)  # back to 1001
    assert canvas.tile.currentData() == 1001

    # a stroke across the forehead, on the skin tile
    start = uv_scene_point(window, head, (-0.2, 0.45))
    end = uv_scene_point(window, head, (0.2, 0.45))
    view = canvas.view.viewport()
    points = [canvas.view.mapFromScene(start + (end - start) * (i / 12)) for i in range(13)]
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=points[0])
    for p in points[1:]:
        qtbot.mouseMove(view, p)
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=points[-1])
    mask = window.doc.project.influence.areas[-1].mask
    assert mask[int(start.y()), int(start.x())] > 0.3
    x0, y0, x1, y1 = layout.pixel_box(1001, mask.shape)
    assert mask.sum() == pytest.approx(mask[y0:y1, x0:x1].sum())  # nothing outside the tile

    # the engine export writes the skin tile's own mask, in its own 0–1 square
    export_folder(window.doc.project, tmp_path / "out")
    tile_png = next((tmp_path / "out" / "masks").glob("[0-9][0-9]_*.1001.png"))
    tile_mask = read_image(tile_png).astype(np.float32) / 65535.0
    assert tile_mask.shape == (y1 - y0, x1 - x0)
    assert tile_mask.max() > 0.3
