"""Technique-1 authoring driven like a user: areas, the UV canvas, painting on the face, images."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QPushButton

from studio.core.files.images import read_image, write_png
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import landmark_uvs
from studio.widgets.paint.edits import PaintSession, set_resolution
from tests.gui_helpers import viewport_image, viewport_marks
from tests.regions import region_difference


@pytest.fixture(autouse=True)
def default_brush():
    """Each test starts with the default brush: the brush is remembered between sessions, so
    one test's size or mirror mode must not leak into the next."""
    from studio.widgets.main_window import settings

    settings().remove("brush")
    yield
    settings().remove("brush")


def uv_pixel(window, name: str) -> tuple[float, float]:
    h, w = window.doc.project.influence.resolution
    u, v = landmark_uvs()[name]
    return float(u * w), float((1.0 - v) * h)


def canvas_point(window, x: float, y: float) -> QPoint:
    return window.mask_tools.canvas.view.mapFromScene(QPointF(x, y))


def add_area_by_click(window, qtbot) -> int:
    panel = window.mask_tools.panel
    button = next(b for b in panel.findChildren(QPushButton) if b.text() == "Add")
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    return window.mask_tools.state.active


def drag(qtbot, widget, points: list[QPoint]) -> None:
    qtbot.mousePress(widget, Qt.MouseButton.LeftButton, pos=points[0])
    for p in points[1:]:
        qtbot.mouseMove(widget, p)
    qtbot.mouseRelease(widget, Qt.MouseButton.LeftButton, pos=points[-1])


def show_t1(window) -> None:
    window.doc.set_view(technique="t1")


def test_drag_on_the_uv_canvas_paints_the_stroke_and_one_undo_removes_it(window, qtbot):
    tools = window.mask_tools
    window.docks["UV Paint"].show()
    window.docks["UV Paint"].raise_()  # a tab in the right-hand column
    n = len(window.doc.project.influence.areas)
    index = add_area_by_click(window, qtbot)
    assert index == n and len(window.doc.project.influence.areas) == n + 1
    area = window.doc.project.influence.areas[index]
    assert area.mask.max() == 0.0
    show_t1(window)
    row = tools.panel.rows[index]
    row.slider.setValue(100)  # the new area's own activation at 1
    assert window.doc.activations()[index] == pytest.approx(1.0)
    before = viewport_image(window)
    marks = viewport_marks(window)
    steps_before = window.doc.undo_stack.count()

    (x0, y0), (x1, y1) = uv_pixel(window, "forehead right"), uv_pixel(window, "forehead left")
    points = [canvas_point(window, x0 + (x1 - x0) * i / 20, y0 + (y1 - y0) * i / 20)
              for i in range(21)]
    drag(qtbot, tools.canvas.view.viewport(), points)

    mask = area.mask
    for name in ("forehead right", "forehead", "forehead left"):
        x, y = uv_pixel(window, name)
        assert mask[int(y), int(x)] > 0.3, name
    x, y = uv_pixel(window, "chin")
    assert mask[int(y), int(x)] == 0.0
    r = tools.state.brush.radius
    ys = np.nonzero(mask.max(axis=1))[0]
    assert ys.min() >= min(y0, y1) - r - 2 and ys.max() <= max(y0, y1) + r + 2  # only the stroke
    assert window.doc.undo_stack.count() == steps_before + 1  # one stroke, one step
    command = window.doc.undo_stack.command(window.doc.undo_stack.count() - 1)
    assert command.stored_pixels < mask.size  # tiles, not the whole mask twice

    after = viewport_image(window)
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert area.mask.max() == 0.0  # one undo removed the whole stroke
    undone = viewport_image(window)
    window.doc.undo_stack.redo()
    fx, fy = uv_pixel(window, "forehead")
    assert area.mask[int(fy), int(fx)] > 0.3
    assert np.array_equal(undone, before)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    assert region_difference(before, after, marks["chin"]) == 0.0


def test_a_click_on_the_face_paints_at_the_uv_under_the_cursor(window, qtbot):
    tools = window.mask_tools
    index = add_area_by_click(window, qtbot)
    area = window.doc.project.influence.areas[index]
    window.viewport.setFocus()
    qtbot.keyClick(window, Qt.Key.Key_B)  # the paint tool
    assert tools.action.isChecked() and window.viewport.tool is tools.tool
    assert window.doc.view.technique == "t1"
    marks = viewport_marks(window)
    ratio = window.viewport.devicePixelRatioF()
    px, py = marks["forehead left"]
    pos = QPoint(round(px / ratio), round(py / ratio))
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton, pos=pos)
    x, y = uv_pixel(window, "forehead left")
    assert area.mask[int(y), int(x)] > 0.3
    ys, xs = np.mgrid[0:area.mask.shape[0], 0:area.mask.shape[1]] + 0.5
    total = area.mask.sum()
    cy, cx = (area.mask * ys).sum() / total, (area.mask * xs).sum() / total
    assert abs(cy - y) <= 3 and abs(cx - x) <= 3  # the dab's centre is the landmark's UV
    r = tools.state.brush.radius
    ys, xs = np.nonzero(area.mask)
    assert np.hypot(xs + 0.5 - x, ys + 0.5 - y).max() <= r + 2  # one dab, nothing elsewhere
    assert window.doc.undo_stack.undoText().startswith("Paint")
    qtbot.keyClick(window, Qt.Key.Key_B)
    assert window.viewport.tool is None
    tools.action.setChecked(True)
    window.viewport.set_tool(None)  # another tool (or none) takes the viewport
    assert not tools.action.isChecked()


def test_a_drag_on_the_posed_face_paints_a_continuous_line(window, qtbot):
    tools = window.mask_tools
    index = add_area_by_click(window, qtbot)
    area = window.doc.project.influence.areas[index]
    window.doc.set_pose_weight("squeeze", 1.0)
    window.doc.set_area_activation(index, 1.0)  # so that the stroke shows on the face
    tools.action.setChecked(True)
    marks = viewport_marks(window)  # neutral landmarks: still on the face when posed
    ratio = window.viewport.devicePixelRatioF()
    a, b = np.array(marks["forehead right"]), np.array(marks["forehead left"])
    points = [QPoint(*np.rint((a + (b - a) * i / 15) / ratio).astype(int).tolist())
              for i in range(16)]
    unpainted, steps = area.mask.copy(), window.doc.undo_stack.count()
    before = viewport_image(window)
    drag(qtbot, window.viewport, points)
    xa, ya = uv_pixel(window, "forehead right")
    xb, yb = uv_pixel(window, "forehead left")
    for f in np.linspace(0.1, 0.9, 9):
        x, y = xa + (xb - xa) * f, ya + (yb - ya) * f
        assert area.mask[int(y) - 6:int(y) + 7, int(x)].max() > 0.2, f
    assert region_difference(before, viewport_image(window), marks["forehead"]) > 2.0
    # the whole stroke is one step: Ctrl+Z takes it all back, mask and picture
    assert window.doc.undo_stack.count() == steps + 1
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert np.array_equal(area.mask, unpainted)
    assert np.array_equal(viewport_image(window), before)


def test_export_then_import_is_lossless_at_16_bit_and_close_at_8(window, tmp_path):
    panel = window.mask_tools.panel
    panel.select(0)
    source = window.doc.project.influence.areas[0]
    assert source.mask.max() > 0.5
    path16, path8 = tmp_path / "forehead16.png", tmp_path / "forehead8.png"
    assert panel.export_active(path16, 16) and panel.export_active(path8, 8)
    assert read_image(path16).dtype == np.uint16 and read_image(path8).dtype == np.uint8
    n = len(window.doc.project.influence.areas)
    assert panel.import_files([path16, path8]) == 2
    areas = window.doc.project.influence.areas
    a16, a8 = areas[-2], areas[-1]
    assert a16.name == "forehead16" and a8.name == "forehead8"
    expected = np.rint(source.mask * 65535.0) / 65535.0
    assert np.abs(a16.mask - expected).max() < 1e-7
    assert np.abs(a8.mask - source.mask).max() <= 0.5 / 255 + 1e-6
    again = tmp_path / "again.png"
    panel.select(len(areas) - 2)
    assert panel.export_active(again, 16)
    assert again.read_bytes() == path16.read_bytes()  # exact round trip
    window.doc.undo_stack.undo()  # the import was one step
    assert len(window.doc.project.influence.areas) == n


def test_an_imported_mask_of_another_size_is_resampled_and_dark_means_strong(window, tmp_path):
    panel = window.mask_tools.panel
    image = np.full((60, 100), 255, np.uint8)
    image[:, :50] = 0  # the left half dark
    path = tmp_path / "thesis mask.png"
    write_png(path, image)
    panel.dark_strong.setChecked(True)
    folder_count = panel.import_folder(tmp_path)
    assert folder_count == 1
    area = window.doc.project.influence.areas[-1]
    h, w = window.doc.project.influence.resolution
    assert area.mask.shape == (h, w) and area.name == "thesis mask"
    assert area.mask[h // 2, : w // 2 - 4].min() == pytest.approx(1.0)
    assert area.mask[h // 2, w // 2 + 4:].max() == pytest.approx(0.0)


def test_a_bad_image_names_the_file_in_an_error(window, tmp_path, dialogs):
    bad = tmp_path / "not_a_mask.png"
    bad.write_bytes(b"\x89PNG\r\n\x1a\n broken")
    n = len(window.doc.project.influence.areas)
    assert window.mask_tools.panel.import_files([bad]) == 0
    assert len(dialogs) == 1 and dialogs[0][0] == "critical" and "not_a_mask.png" in dialogs[0][1]
    assert len(window.doc.project.influence.areas) == n


def test_area_list_edits_are_undoable(window, qtbot):
    doc = window.doc
    panel = window.mask_tools.panel
    names = [a.name for a in doc.project.influence.areas]
    panel.select(0)
    panel.duplicate()
    assert doc.project.influence.areas[1].name == f"{names[0]} copy"
    assert np.array_equal(doc.project.influence.areas[1].mask, doc.project.influence.areas[0].mask)
    panel.move(1)  # the copy goes down one
    assert doc.project.influence.areas[2].name == f"{names[0]} copy"
    from studio.widgets.paint.edits import rename_area, set_area_colour, set_area_visible
    assert rename_area(doc, 0, "brow R")
    assert doc.project.influence.links["surprise"]["brow R"] == 1.0  # links follow the name
    assert not rename_area(doc, 1, "brow R")  # taken
    box = panel.rows[0].visible  # the layer's eye: a click hides it
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=QPoint(box.width() // 2,
                                                                 box.height() // 2))
    assert not doc.project.influence.areas[0].visible
    assert not panel.rows[0].visible.isChecked()
    set_area_visible(doc, 0, False)  # already hidden: no new step
    doc.set_pose_weight("surprise", 1.0)
    assert doc.activations()[0] == 0.0
    set_area_colour(doc, 0, (1, 2, 3))
    panel.select(0)
    panel.delete()
    assert "brow R" not in [a.name for a in doc.project.influence.areas]
    assert "brow R" not in doc.project.influence.links["surprise"]
    while doc.undo_stack.canUndo():
        doc.undo_stack.undo()
    assert [a.name for a in doc.project.influence.areas] == names
    first = doc.project.influence.areas[0]
    assert first.visible and first.colour != (1, 2, 3)
    assert len(panel.rows) == len(names)


def test_links_and_auto_mask_animate_a_new_area(window, qtbot):
    doc = window.doc
    panel = window.mask_tools.panel
    panel.auto_pose.setCurrentText("squeeze")
    panel.auto_mask()
    area = doc.project.influence.areas[-1]
    assert area.name == "squeeze auto" and area.mask.max() > 0.5
    assert doc.project.influence.links["squeeze"]["squeeze auto"] == 1.0
    x, y = uv_pixel(window, "eye corner left")
    h = area.mask.shape[0]
    assert area.mask[int(y) - 12:int(y) + 12, int(x) - 12:int(x) + 12].max() > 0.05
    cx, cy = uv_pixel(window, "chin")
    assert area.mask[int(cy), int(cx)] == 0.0 and h > 0
    # drive it by the surprise too, at gain 0.5: "Add pose…", type part of the name, Return,
    # then the new link's gain
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    assert list(panel.link_spins) == ["squeeze"]  # only the poses that drive it are listed
    panel.ensureWidgetVisible(panel.add_pose)
    qtbot.mouseClick(panel.add_pose.lineEdit(), Qt.MouseButton.LeftButton)
    qtbot.keyClicks(panel.add_pose.lineEdit(), "surprise")
    qtbot.keyClick(panel.add_pose.lineEdit(), Qt.Key.Key_Return)
    assert doc.project.influence.links["surprise"]["squeeze auto"] == 1.0
    spin = panel.link_spins["surprise"]
    qtbot.keyClick(spin, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(spin, "0.5")
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    doc.set_pose_weight("surprise", 1.0)
    assert doc.activations()[-1] == pytest.approx(0.5)
    doc.undo_stack.undo()  # the weight
    doc.undo_stack.undo()  # the gain
    doc.undo_stack.undo()  # the link
    assert "squeeze auto" not in doc.project.influence.links.get("surprise", {})


def test_resolution_change_resamples_every_mask_and_undoes(window):
    doc = window.doc
    panel = window.mask_tools.panel
    old = [a.mask.copy() for a in doc.project.influence.areas]
    i = panel.resolution.findData(1024)
    panel.resolution.setCurrentIndex(i)
    panel.resolution.activated.emit(i)
    assert all(a.mask.shape == (1024, 1024) for a in doc.project.influence.areas)
    assert window.mask_tools.canvas.masks.buffer.shape[:2] == (1024, 1024)
    viewport_image(window)  # the viewport re-uploads the stack without error
    doc.undo_stack.undo()
    assert all(np.array_equal(a.mask, m) for a, m in zip(doc.project.influence.areas, old,
                                                          strict=True))


def test_painted_project_round_trips(window, qtbot, tmp_path):
    doc = window.doc
    index = add_area_by_click(window, qtbot)
    session = PaintSession(doc, index, window.mask_tools.state.brush)
    session.jump(*uv_pixel(window, "cheek left"))
    session.end()
    from studio.widgets.paint.edits import set_link
    set_link(doc, "frown", doc.project.influence.areas[index].name, 0.7)
    path = tmp_path / "painted.wrinkle"
    save_project(doc.project, path)
    reopened = load_project(path)
    for a, b in zip(reopened.influence.areas, doc.project.influence.areas, strict=True):
        assert a.name == b.name and a.colour == b.colour
        assert np.abs(a.mask - b.mask).max() <= 0.5 / 65535 + 1e-7
    assert reopened.influence.links == doc.project.influence.links


def test_overlap_view_marks_sums_over_one(window):
    doc = window.doc
    tools = window.mask_tools
    panel = tools.panel
    panel.select(0)
    panel.duplicate()  # the same mask twice: Σ = 2 wherever it is strong
    panel.overlap.setChecked(True)
    x, y = uv_pixel(window, "forehead right")
    rgba = tools.canvas.overlap_item.buffer[int(y), int(x)]
    assert rgba[3] > 100 and rgba[0] > rgba[2]  # red
    cx, cy = uv_pixel(window, "nose tip")
    assert doc.project.influence.areas[0].mask[int(cy), int(cx)] == 0.0


def test_stroke_segments_on_a_4096_mask_store_only_their_tiles(window):
    """A stroke on a 4096² mask keeps, for its undo step, only the tiles it touched (its cost
    per segment is the benchmark's to measure, not a test's)."""
    doc = window.doc
    set_resolution(doc, 4096)
    area = doc.project.influence.areas[0]
    assert area.mask.shape == (4096, 4096)
    doc.set_view(technique="t1")
    viewport_image(window)
    state = window.mask_tools.state
    state.set_brush(radius=60.0, spacing=0.2)
    before = area.mask.copy()
    session = PaintSession(doc, 0, state.brush)
    session.jump(1000, 1000)
    for i in range(1, 16):
        session.to(1000 + 12 * i, 1000 + 4 * i)  # a mouse move of ~12.6 px: about 1 dab
        window.viewport.repaint()  # the frame that uploads that rectangle (and draws)
    command = session.end()
    changed = np.argwhere(area.mask != before)
    assert len(changed) and changed.min(axis=0).tolist() >= [1000 - 61, 1000 - 61]
    assert command.stored_pixels < 0.01 * area.mask.size


def test_a_face_dab_at_a_uv_seam_also_lands_in_the_other_chart(qtbot, sample):
    from studio.core.mesh.picking import Hit
    from studio.widgets.document import Document
    from studio.widgets.paint.areas_panel import PaintState
    from studio.widgets.paint.edits import add_area
    from studio.widgets.paint.paint_tool import FacePaintTool, SeamMap

    doc = Document(sample)
    add_area(doc, "seam")
    state = PaintState()
    state.active = len(doc.project.influence.areas) - 1
    state.set_brush(radius=6.0, hardness=1.0, flow=1.0)
    mesh = doc.project.mesh
    seams = SeamMap(mesh)
    f = next(t for t in range(mesh.n_triangles) if seams.other_charts(t))
    other = seams.other_charts(f)[0]
    tri = mesh.triangles[f]
    k = next(i for i in range(3) if seams.seam_welded[mesh.weld[tri[i]]])
    positions = mesh.rest[mesh.weld].astype(np.float64)
    bary = np.full(3, 0.05)
    bary[k] = 0.9  # close to the seam vertex
    hit = Hit(f, bary @ positions[tri], bary, 1.0)
    tool = FacePaintTool(doc, state)
    tool.session = PaintSession(doc, state.active, state.brush)
    h, w = doc.project.influence.resolution
    uv = bary @ mesh.uvs[tri]
    tool.session.jump(uv[0] * w, (1 - uv[1]) * h)
    tool._seam_dabs(hit, positions)
    # the seam vertex as the other chart sees it
    welded = mesh.weld[tri[k]]
    r_other = next(r for r in mesh.triangles[other] if mesh.weld[r] == welded)
    ou = mesh.uvs[r_other]
    assert np.hypot(*(ou - mesh.uvs[tri[k]]) * w) > 3 * state.brush.radius  # really elsewhere
    mask = doc.project.influence.areas[-1].mask
    ox, oy = int(ou[0] * w), int((1 - ou[1]) * h)
    assert mask[max(oy - 8, 0):oy + 9, max(ox - 8, 0):ox + 9].max() > 0.5
    tool.session.end()
    doc.undo_stack.undo()
    assert mask.max() == 0.0  # the main dab and the seam dab were one undo step
    doc.undo_stack.cleanChanged.disconnect()


def test_tablet_pressure_scales_the_dab(qtbot, sample):
    from PySide6.QtCore import QEvent
    from PySide6.QtGui import QPointingDevice, QTabletEvent
    from PySide6.QtWidgets import QApplication

    from studio.widgets.document import Document
    from studio.widgets.paint.areas_panel import PaintState
    from studio.widgets.paint.uv_canvas import UvCanvas

    doc = Document(sample)
    state = PaintState()
    state.active = 0
    state.set_brush(hardness=1.0, flow=1.0)
    canvas = UvCanvas(doc, state)
    qtbot.addWidget(canvas)
    canvas.resize(600, 600)
    canvas.show()
    area = doc.project.influence.areas[0]
    area.mask[:] = 0.0
    target = canvas.view.viewport()
    pos = QPointF(canvas.view.mapFromScene(QPointF(256, 256)))
    for kind in (QEvent.Type.TabletPress, QEvent.Type.TabletRelease):
        QApplication.sendEvent(target, QTabletEvent(
            kind, QPointingDevice.primaryPointingDevice(), pos, target.mapToGlobal(pos), 0.3,
            0, 0, 0, 0, 0, Qt.KeyboardModifier.NoModifier, Qt.MouseButton.LeftButton,
            Qt.MouseButton.LeftButton))
    assert area.mask.max() == pytest.approx(0.3)  # flow 1 × pressure 0.3
    assert doc.undo_stack.count() == 1
    doc.undo_stack.cleanChanged.disconnect()


# --- the brush cursor in the viewport and mirror painting ----------------------------------------

def widget_point(window, pixel: tuple[float, float]) -> QPoint:
    ratio = window.viewport.devicePixelRatioF()
    return QPoint(round(pixel[0] / ratio), round(pixel[1] / ratio))


def hover(qtbot, widget, pos: QPoint) -> None:
    """Move the mouse to ``pos`` (by way of a neighbouring pixel: Qt drops a move to where the
    pointer already is, e.g. the same spot in the previous test's window)."""
    qtbot.mouseMove(widget, pos + QPoint(2, 1))
    qtbot.mouseMove(widget, pos)


def grab_viewport(window) -> np.ndarray:
    """What the user sees in the viewport: the face and whatever is drawn over it."""
    from tests.gui_helpers import qimage_to_array

    return qimage_to_array(window.viewport.grab().toImage())


def test_the_brush_cursor_follows_the_mouse_on_the_face_without_redrawing_it(window, qtbot):
    tools = window.mask_tools
    vp = window.viewport
    window.viewport.setFocus()
    qtbot.keyClick(window, Qt.Key.Key_B)
    marks = viewport_marks(window)
    vp.repaint()  # the frame the tool change asked for
    hover(qtbot, vp, QPoint(3, 3))  # the corner: background, no face
    plain = grab_viewport(window)
    frames = vp.frames_rendered
    cheek = widget_point(window, marks["cheek left"])
    for dx in (-6, -3, 0):
        qtbot.mouseMove(vp, cheek + QPoint(dx, 0))
    qtbot.wait(50)  # let any repaint the moves asked for happen
    assert vp.frames_rendered == frames  # the face was not re-rendered for the cursor
    rings = tools.tool.cursor.rings
    assert len(rings) == 1 and not rings[0].mirrored
    centre = rings[0].outer.mean(axis=0)
    assert np.hypot(*(centre - [cheek.x(), cheek.y()])) < 3  # around the mouse
    shown = grab_viewport(window)
    ratio = vp.devicePixelRatioF()
    x, y = np.rint(rings[0].outer[0] * ratio).astype(int)  # a point on the ring's edge
    edge = np.abs(shown[y - 2:y + 3, x - 2:x + 3].astype(int)
                  - plain[y - 2:y + 3, x - 2:x + 3].astype(int))
    assert edge.max() > 60  # the ring is drawn there
    far = widget_point(window, marks["chin"])
    assert np.array_equal(shown[far.y() - 5:far.y() + 5, far.x() - 5:far.x() + 5],
                          plain[far.y() - 5:far.y() + 5, far.x() - 5:far.x() + 5])

    # the cursor shows the brush's size: twice the radius, twice the ring
    width = np.ptp(rings[0].outer, axis=0).max()
    tools.panel.radius.setValue(round(2 * tools.state.brush.radius))
    wider = np.ptp(tools.tool.cursor.rings[0].outer, axis=0).max()
    assert wider == pytest.approx(2 * width, rel=0.05)

    qtbot.mouseMove(vp, QPoint(3, 3))  # off the face: hidden
    assert tools.tool.cursor.rings == []
    assert np.array_equal(grab_viewport(window), plain)
    hover(qtbot, vp, cheek)
    qtbot.keyClick(window, Qt.Key.Key_B)  # leaving the tool hides it too
    assert tools.tool.cursor.rings == []


def open_active(open_window, qtbot, project):
    """A window that has the keyboard focus (shortcuts need it), like one the user clicked."""
    window = open_window(project)
    qtbot.waitUntil(window.isActiveWindow)
    return window


def warped_sample(sample):
    """The sample face with an asymmetric UV layout (u → u^1.25): the mesh is still symmetric,
    its UVs no longer are, so only a mirror through the mesh finds the other cheek."""
    from studio.core.mesh.face_mesh import FaceMesh

    mesh = sample.mesh
    uvs = mesh.uvs.copy()
    uvs[:, 0] = uvs[:, 0] ** 1.25
    sample.mesh = FaceMesh(mesh.rest, mesh.triangles, uvs, mesh.weld)
    return sample


def warped_pixel(window, name: str) -> tuple[float, float]:
    h, w = window.doc.project.influence.resolution
    u, v = landmark_uvs()[name]
    return float(u ** 1.25 * w), float((1.0 - v) * h)


def neutral_marks(window) -> dict[str, tuple[int, int]]:
    """The landmarks' pixels, found on the sample's own UV layout (the geometry is the same)."""
    from studio.core.sample.synthetic import make_test_face
    from tests.regions import landmark_pixels

    w, h = window.viewport.pixel_size()
    return landmark_pixels(make_test_face(), window.doc.camera, w, h)


def choose_mirror(window, mode: str) -> None:
    combo = window.mask_tools.panel.mirror
    combo.setCurrentIndex(combo.findData(mode))
    assert window.mask_tools.state.mirror == mode


def painted_near(mask: np.ndarray, x: float, y: float, r: int = 3) -> float:
    return float(mask[int(y) - r:int(y) + r + 1, int(x) - r:int(x) + r + 1].max())


def test_a_click_with_mirror_through_the_mesh_paints_both_cheeks_in_one_step(
        open_window, sample, qtbot):
    window = open_active(open_window, qtbot, warped_sample(sample))
    tools = window.mask_tools
    index = add_area_by_click(window, qtbot)
    area = window.doc.project.influence.areas[index]
    choose_mirror(window, "mesh")
    window.viewport.setFocus()
    qtbot.keyClick(window, Qt.Key.Key_B)
    marks = neutral_marks(window)
    cheek = widget_point(window, marks["cheek left"])
    hover(qtbot, window.viewport, cheek)
    rings = tools.tool.cursor.rings
    assert [r.mirrored for r in rings] == [False, True]  # the mirror's ring on the right cheek
    right = widget_point(window, marks["cheek right"])
    assert np.hypot(*(rings[1].outer.mean(axis=0) - [right.x(), right.y()])) < 4
    steps = window.doc.undo_stack.count()
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton, pos=cheek)

    mask = area.mask
    assert painted_near(mask, *warped_pixel(window, "cheek left")) > 0.3
    assert painted_near(mask, *warped_pixel(window, "cheek right")) > 0.3  # the mirror image
    w = mask.shape[1]
    x, y = warped_pixel(window, "cheek left")
    assert painted_near(mask, w - x, y) == 0.0  # not where u → 1 − u would have put it
    assert window.doc.undo_stack.count() == steps + 1
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert mask.max() == 0.0  # one undo removed both dabs


def test_a_dab_on_the_uv_canvas_is_mirrored_through_the_mesh(open_window, sample, qtbot):
    window = open_active(open_window, qtbot, warped_sample(sample))
    tools = window.mask_tools
    index = add_area_by_click(window, qtbot)
    area = window.doc.project.influence.areas[index]
    choose_mirror(window, "mesh")
    window.docks["UV Paint"].show()
    window.docks["UV Paint"].raise_()  # a tab in the right-hand column, behind Areas
    view = tools.canvas.view.viewport()
    qtbot.waitUntil(lambda: not view.visibleRegion().isEmpty())
    x, y = warped_pixel(window, "forehead right")
    hover(qtbot, view, canvas_point(window, x, y))
    mirror_cursor = tools.canvas.mirror_cursor
    mx, my = warped_pixel(window, "forehead left")
    assert mirror_cursor.isVisible()
    assert np.hypot(mirror_cursor.rect().center().x() - mx,
                    mirror_cursor.rect().center().y() - my) < 4
    qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=canvas_point(window, x, y))
    assert painted_near(area.mask, x, y) > 0.3
    assert painted_near(area.mask, mx, my) > 0.3
    assert painted_near(area.mask, area.mask.shape[1] - x, y) == 0.0
    window.doc.undo_stack.undo()
    assert area.mask.max() == 0.0
    choose_mirror(window, "uv")  # the UV mirror: u → 1 − u, wherever the surface is
    qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=canvas_point(window, x, y))
    assert painted_near(area.mask, area.mask.shape[1] - x, y) > 0.3
    assert painted_near(area.mask, mx, my) == 0.0


def test_the_mirror_mode_and_brush_are_remembered_for_the_next_window(open_window, sample):
    first = open_window(copy.deepcopy(sample))
    panel = first.mask_tools.panel
    choose_mirror(first, "mesh")
    panel.radius.setValue(37)
    panel.hardness.setValue(0.8)
    second = open_window(sample)
    state = second.mask_tools.state
    assert state.mirror == "mesh" and state.brush.radius == 37.0
    assert state.brush.hardness == pytest.approx(0.8)
    combo = second.mask_tools.panel.mirror
    assert combo.currentData() == "mesh" and "mesh" in combo.currentText()
    assert second.mask_tools.panel.radius.value() == 37


def test_an_area_chooses_the_wrinkled_map_it_reveals(window, qtbot):
    """Pointing the left eye-corner area at the brow map hides its crow's feet (that map has
    none there); one undo brings them back."""
    doc, panel = window.doc, window.mask_tools.panel
    areas = doc.project.influence.areas
    index = [a.name for a in areas].index("eye corner left")
    doc.set_view(technique="t1")
    doc.set_area_activation(index, 1.0)
    panel.select(index)
    marks = viewport_marks(window)
    shown = viewport_image(window)
    combo = panel.map_combo
    brow = doc.project.textures.wrinkle_map_names[0]
    combo.setCurrentIndex(combo.findData(brow))
    combo.activated.emit(combo.currentIndex())
    qtbot.waitUntil(lambda: areas[index].wrinkle_map == brow)
    hidden = viewport_image(window)
    doc.undo_stack.undo()
    assert areas[index].wrinkle_map != brow
    assert region_difference(shown, hidden, marks["eye corner left"]) > 4.0
    assert np.array_equal(viewport_image(window), shown)


def test_while_a_stroke_is_painted_on_the_uv_canvas_the_face_shows_what_it_reveals(window,
                                                                                    qtbot):
    """Painting an area nothing drives yet (activation 0, neutral face): mid-stroke the face
    shows that area's wrinkles at full strength with technique 1, under the brush and nowhere
    else; once the stroke ends, the face is as the document says again. Seen red with the
    canvas's preview signal not connected: the face does not change mid-stroke."""
    tools = window.mask_tools
    window.docks["UV Paint"].show()
    window.docks["UV Paint"].raise_()
    index = add_area_by_click(window, qtbot)
    window.doc.set_view(technique="t2")  # another technique: the preview shows technique 1
    before = viewport_image(window)
    marks = viewport_marks(window)
    (x0, y0), (x1, y1) = uv_pixel(window, "forehead right"), uv_pixel(window, "forehead left")
    points = [canvas_point(window, x0 + (x1 - x0) * i / 20, y0 + (y1 - y0) * i / 20)
              for i in range(21)]
    surface = tools.canvas.view.viewport()
    qtbot.mousePress(surface, Qt.MouseButton.LeftButton, pos=points[0])
    for p in points[1:]:
        qtbot.mouseMove(surface, p)
    during = viewport_image(window)
    qtbot.mouseRelease(surface, Qt.MouseButton.LeftButton, pos=points[-1])
    assert window.doc.project.influence.areas[index].mask.max() > 0.3
    # painting an area goes on showing technique 1, where areas show (issue #47): a view
    # setting, said in the status bar, not an edit
    assert window.doc.view.technique == "t1"
    assert "Technique 1" in window.statusBar().currentMessage()
    assert window.doc.undo_stack.command(window.doc.undo_stack.count() - 1).text() \
        .startswith("Paint")
    assert region_difference(before, during, marks["forehead"]) > 2.0
    assert region_difference(before, during, marks["chin"]) < 0.5
    after = viewport_image(window)  # the stroke's preview over: the area at its activation 0
    assert region_difference(during, after, marks["forehead"]) > 2.0
