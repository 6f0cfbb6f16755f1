"""File ▸ Export ▸ Folder for a Game Engine…, driven with real key presses and clicks: the layout
chosen in the dialog is the one written, each entry shows its sampler cost, and a layout the
engine cannot hold is refused in a dialog with nothing written."""

from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import Qt

from studio.core.engines.export import SHEET
from studio.core.engines.layouts import LAYOUTS
from studio.core.wrinkles.influence import InfluenceArea
from tests.gui_helpers import fill_export_dialog


def test_choosing_a_layout_in_the_dialog_writes_that_layout(window, qtbot, tmp_path, dialogs):
    seen: list = []
    fill_export_dialog(qtbot, seen, tmp_path / "mh", [Qt.Key.Key_Up] * 4)  # up to MetaHuman
    window.map_tools.export_folder()
    entries = seen[0]
    assert [e.split(" — ")[0] for e in entries] == [layout.label for layout in LAYOUTS.values()]
    assert entries[0].endswith("— 13 samplers")  # 10 region masks and 3 wrinkle maps
    sheet = json.loads((tmp_path / "mh" / SHEET).read_text())
    assert sheet["layout"] == "metahuman"
    assert (tmp_path / "mh" / "masks" / "T_head_wm1_msk_01.png").is_file()
    assert dialogs == []
    assert "13 samplers" in window.statusBar().currentMessage()


def test_a_layout_the_engine_cannot_hold_is_a_dialog(open_window, sample, qtbot, tmp_path,
                                                     dialogs):
    sample.influence.areas += [InfluenceArea(f"extra {i}", np.zeros(sample.influence.resolution,
                                                                     np.float32))
                               for i in range(61 - len(sample.influence.areas))]
    window = open_window(sample)
    seen: list = []
    fill_export_dialog(qtbot, seen, tmp_path / "out", [])  # the studio's own, preselected
    window.map_tools.export_folder()
    assert "(too many samplers: 18 of 16)" in seen[0][-1]
    assert [kind for kind, _ in dialogs] == ["critical"]
    assert "the studio layout needs 18 samplers" in dialogs[0][1]
    assert not (tmp_path / "out").exists()


def test_o3de_over_its_mask_limit_offers_to_merge_the_weakest(open_window, qtbot, tmp_path,
                                                               dialogs):
    from tests.test_engine_merge import seventeen_masks

    window = open_window(seventeen_masks())
    seen: list = []
    fill_export_dialog(qtbot, seen, tmp_path / "o3de", [Qt.Key.Key_Up] * 2)  # studio → o3de
    window.map_tools.export_folder()
    o3de = next(e for e in seen[0] if e.startswith(LAYOUTS["o3de"].label))
    assert "(too many wrinkle masks: 17 of 16; the 1 weakest can be merged)" in o3de
    [(kind, text)] = dialogs
    assert kind == "question" and "Merge the 1 weakest?" in text
    assert "the mask of 'cheekPuff'" in text and "into 'mouthSmile_R'" in text
    sheet = json.loads((tmp_path / "o3de" / SHEET).read_text())
    assert sheet["layout"] == "o3de" and [m["mask"] for m in sheet["merged"]] == ["cheekPuff"]
    assert "1 weakest masks merged" in window.statusBar().currentMessage()
