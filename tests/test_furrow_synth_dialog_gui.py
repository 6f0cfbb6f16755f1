"""The Synthesise dialog's maps reach the Furrows panel (issue 45, point 6): a map synthesised
from the brow raise through Tools ▸ Synthesise Wrinkled Normal Map… is recorded as the set-up's
maps are, so Depth typed for that pose and Return makes it again (deeper furrows on the
forehead the viewport draws), Ctrl+Z takes it back to the map as the dialog made it, and the
record is saved with the project."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt

from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from tests.gui_helpers import viewport_marks
from tests.regions import region_difference
from tests.test_auto_gui import as_imported, fill_synth_dialog, open_plain, trigger
from tests.test_files_gui import activate
from tests.test_furrow_controls_gui import choose_pose, settled_image, type_value

CTRL = Qt.KeyboardModifier.ControlModifier
POSE = "surprise"


def test_a_map_the_dialog_synthesised_follows_the_furrow_controls(open_window, sample, qtbot,
                                                                 tmp_path):
    window = open_plain(open_window, as_imported(sample, flat_map=True))
    doc, panel = window.doc, window.furrow_panel
    trigger(window, "Auto Setup from Poses")  # areas that reveal the map
    doc.set_pose_weight(POSE, 1.0)
    opened: list = []
    fill_synth_dialog(qtbot, opened, poses={POSE})
    trigger(window, "Synthesise Wrinkled Normal Map…")
    name = opened[0].map_name.currentText()
    made = doc.project.textures.wrinkle_maps[name]
    record = doc.project.furrows.maps[name]
    assert record.poses == (POSE,) and not record.anatomy and record.over_neutral
    assert (record.spacing, record.depth) == (10.0, 2.0)  # as the dialog was filled in
    assert doc.project.furrows.maps_of(POSE) == [name]
    steps = doc.undo_stack.count()

    choose_pose(qtbot, panel, POSE)
    assert panel.rows["depth"].isEnabled()
    assert f"“{name}”" in panel.status.text()
    before = settled_image(qtbot, window)
    forehead = viewport_marks(window)["forehead"]
    type_value(qtbot, panel.rows["depth"].spin, "3")
    assert doc.undo_stack.count() == steps + 1
    qtbot.waitUntil(lambda: not np.array_equal(doc.project.textures.wrinkle_maps[name], made),
                    timeout=30000)
    assert region_difference(settled_image(qtbot, window), before, forehead) > 4.0

    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_Z, CTRL)
    qtbot.waitUntil(lambda: np.array_equal(doc.project.textures.wrinkle_maps[name], made),
                    timeout=30000)
    assert doc.project.furrows.of(POSE).depth == 1.0

    path = tmp_path / "synthesised.wrinkle"
    save_project(doc.project, path)
    assert load_project(path).furrows.maps[name] == doc.project.furrows.maps[name]


def test_undoing_the_synthesis_takes_its_record_with_it(open_window, sample, qtbot):
    window = open_plain(open_window, as_imported(sample))
    doc = window.doc
    opened: list = []
    fill_synth_dialog(qtbot, opened, poses={"frown"})
    trigger(window, "Synthesise Wrinkled Normal Map…")
    name = opened[0].map_name.currentText()
    assert name in doc.project.furrows.maps
    doc.undo_stack.undo()
    assert name not in doc.project.furrows.maps
    assert name not in doc.project.textures.wrinkle_maps
    doc.undo_stack.redo()
    assert doc.project.furrows.maps[name].poses == ("frown",)
