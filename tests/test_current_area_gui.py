"""The current technique-2 area lives in the document: what the Wrinkle vectors panel, Create
and the Shading panel's cone slider act on — kept through undo and redo (issue 19's bugs)."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt


def click_row(qtbot, panel, row: int) -> None:
    rect = panel.area_list.visualItemRect(panel.area_list.item(row))
    qtbot.mouseClick(panel.area_list.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())


def test_add_then_undo_then_redo_keeps_the_new_area_current(window, qtbot):
    doc, panel = window.doc, window.wdv_tools.panel
    window.docks["Wrinkle vectors"].show()
    window.docks["Wrinkle vectors"].raise_()
    qtbot.waitUntil(panel.add_button.isVisible)
    before = [a.name for a in doc.project.wdv.areas]
    click_row(qtbot, panel, 1)  # "eye corners"
    assert window.wdv_tools.current_area.name == before[1]
    qtbot.mouseClick(panel.add_button, Qt.MouseButton.LeftButton)
    added = doc.project.wdv.areas[-1]
    assert window.wdv_tools.current_area is added
    assert panel.create_button.text() == f"Create for “{added.name}”"
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert [a.name for a in doc.project.wdv.areas] == before
    assert window.wdv_tools.current_area.name == before[1]  # what was current before the add
    qtbot.keyClick(window, Qt.Key.Key_Z,
                   Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert window.wdv_tools.current_area is added  # not the first area: Create must not rewrite it
    assert panel.create_button.text() == f"Create for “{added.name}”"
    assert panel.area_list.currentRow() == len(before)


def test_the_cone_slider_shows_and_sets_the_current_area_only(window, qtbot):
    doc, panel = window.doc, window.wdv_tools.panel
    areas = doc.project.wdv.areas
    for area in areas:
        area.cone_angle_deg = 20.0
    areas[2].cone_angle_deg = 35.0
    window.docks["Wrinkle vectors"].show()
    window.docks["Wrinkle vectors"].raise_()
    qtbot.waitUntil(panel.add_button.isVisible)
    click_row(qtbot, panel, 2)
    shading = window.shading_panel
    window.docks["Shading"].show()
    window.docks["Shading"].raise_()
    qtbot.waitUntil(shading.cone.slider.isVisible)
    assert shading.cone.value() == 35.0  # the current area's angle, not the first's
    slider = shading.cone.slider
    groove = slider.rect().center()
    groove.setX(slider.width() - 3)  # a click on the groove, clear of the handle at 35°
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=groove)
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=groove)
    changed = areas[2].cone_angle_deg
    assert changed != 35.0
    assert [a.cone_angle_deg for a in areas[:2]] == [20.0, 20.0]  # the others keep theirs
    window.docks["Wrinkle vectors"].raise_()
    qtbot.waitUntil(panel.add_button.isVisible)
    click_row(qtbot, panel, 0)
    assert shading.cone.value() == 20.0
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert areas[2].cone_angle_deg == 35.0


def test_an_exported_animation_is_drawn_like_the_viewport(window, qtbot, tmp_path):
    """The blend mode and the relief chosen in the Shading panel reach the exported frames
    (the export dialog once copied only the technique and the light)."""
    from PIL import Image

    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings
    from studio.widgets.export_dialog import ExportOptions, export_animation

    shading = window.shading_panel
    window.docks["Shading"].show()
    window.docks["Shading"].raise_()
    qtbot.waitUntil(shading.blend.isVisible)
    for combo, key in ((shading.blend, "normal"), (shading.relief, "parallax")):
        combo.setFocus()
        while combo.currentData() != key:
            qtbot.keyClick(combo, Qt.Key.Key_Down)
    view = window.doc.view
    assert (view.blend, view.relief) == ("normal", "parallax")
    timeline = window.doc.project.timeline
    frame = max(range(timeline.start, timeline.end + 1),  # the surprise pose at its strongest
                key=lambda f: timeline.weights_at(f).get("surprise", 0.0))
    folder = tmp_path / "frames"
    assert export_animation(window, ExportOptions("frames", folder, 320, 240, "t2", frame,
                                                  frame, 1))
    exported = np.asarray(Image.open(folder / f"frame_{frame:04d}.png").convert("RGB"))

    weights = timeline.weights_at(frame)
    viewport = window.viewport
    viewport.makeCurrent()  # in the viewport's context, as the export renders
    try:
        studio = OffscreenStudio(window.doc.project, 320, 240, ctx=viewport.ctx)
        studio.camera = window.doc.camera
        common = dict(technique="t2", light_dir=view.light_dir(),
                      relief_depth=view.relief_depth)
        expected = studio.render(RenderSettings(blend="normal", relief="parallax", **common),
                                 weights)
        plain = studio.render(RenderSettings(**common), weights)
        studio.release()
    finally:
        viewport.doneCurrent()
    assert np.abs(plain.astype(int) - expected).max() >= 4  # the settings do show
    assert np.abs(exported.astype(int) - expected).max() <= 2
