"""The Tools menu driven like a user: Auto Setup from Poses, the automatic (strain) wrinkles turned
into a mask or WDV area, and a synthesised wrinkled normal map — each one undo step that
changes what the viewport shows, and undoes back to the same picture."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QApplication, QDialogButtonBox, QProgressDialog

from studio.core.wrinkles.influence import InfluenceSetup
from studio.core.wrinkles.textures import MAX_WRINKLE_MAPS, FaceTextures, flat_normal_map
from studio.core.wrinkles.wdv import WdvSetup
from studio.widgets.maps.auto_tools import SynthDialog
from tests.gui_helpers import viewport_image, viewport_marks
from tests.regions import region_difference


def trigger(window, text: str) -> None:
    """Choose an item of the Tools menu."""
    (action,) = [a for a in window.auto_menu.actions() if a.text() == text]
    action.trigger()


def as_imported(project, flat_map: bool = False):
    """The sample face as an import arrives: key poses, no areas of either technique, and with
    ``flat_map`` no wrinkled map either (a flat placeholder)."""
    project.influence = InfluenceSetup()
    project.wdv = WdvSetup()
    if flat_map:
        t = project.textures
        project.textures = FaceTextures(t.diffuse, t.normal_neutral, flat_normal_map(64))
    return project


def open_plain(open_window, project):
    window = open_window(project)
    window.wdv_tools.overlay.visible = False  # judge the shading, not the vectors drawn over it
    return window


@pytest.fixture
def fresh(open_window, sample):
    return open_plain(open_window, as_imported(sample))


def test_the_tools_menu_is_in_the_menu_bar(fresh):
    titles = [a.text().replace("&", "") for a in fresh.menuBar().actions()]
    assert "Tools" in titles and titles.index("Tools") < titles.index("Help")
    assert [a.text() for a in fresh.auto_menu.actions() if a.text()] == [
        "Auto Setup from Poses", "Convert Automatic Wrinkles to Mask",
        "Convert Automatic Wrinkles to WDV Area", "Synthesise Wrinkled Normal Map…"]


def test_auto_setup_gives_both_techniques_wrinkles_in_one_undo_step(fresh, dialogs):
    doc = fresh.doc
    doc.set_pose_weight("surprise", 1.0)
    marks = viewport_marks(fresh)
    before = {}
    for technique in ("t1", "t2"):
        doc.set_view(technique=technique)
        before[technique] = viewport_image(fresh)
    steps = doc.undo_stack.count()
    trigger(fresh, "Auto Setup from Poses")
    poses = [p.name for p in doc.project.poses]
    assert [a.name for a in doc.project.wdv.areas] == poses
    assert [a.name for a in doc.project.influence.areas] == poses
    assert doc.project.influence.links == {p: {p: 1.0} for p in poses}
    assert doc.undo_stack.count() == steps + 1 and dialogs == []  # every pose gave both
    # the panels show them
    assert fresh.wdv_tools.panel.area_list.count() == len(poses)
    assert len(fresh.mask_tools.panel.rows) == len(poses)
    # surprise now wrinkles the forehead with either technique
    after = {}
    for technique in ("t1", "t2"):
        doc.set_view(technique=technique)
        after[technique] = viewport_image(fresh)
        assert region_difference(before[technique], after[technique], marks["forehead"]) > 2.0
    # one undo removes everything it added, and the picture is the one before
    doc.undo_stack.undo()
    assert doc.project.wdv.areas == [] and doc.project.influence.areas == []
    assert doc.project.influence.links == {}
    assert fresh.wdv_tools.panel.area_list.count() == 0
    assert np.array_equal(viewport_image(fresh), before["t2"])
    doc.undo_stack.redo()
    assert [a.name for a in doc.project.influence.areas] == poses
    assert np.array_equal(viewport_image(fresh), after["t2"])


def test_auto_setup_holds_a_frown_s_placed_lines_as_new_auto_does(fresh, dialogs):
    """The menu's set-up is ``new --auto``'s: a frown's WDV area holds the vertices
    of the lines anatomy places between the brows (``wrinkle_synth.placed_lines``), so a
    synthesised map's lines show whole. Red once: the menu called ``suggest_setup`` without
    them, and the area missed some of the lines' vertices."""
    from studio.core.setup.wrinkle_synth import placed_lines

    doc = fresh.doc
    placed = placed_lines(doc.project, frame=doc.face_frame())
    assert "frown" in placed
    trigger(fresh, "Auto Setup from Poses")
    for pose in placed:
        lines, _ = placed[pose]
        (area,) = [a for a in doc.project.wdv.areas if a.pose == pose]
        assert lines.any() and area.authored[lines].all(), pose


def test_auto_setup_reports_poses_that_give_nothing(fresh, dialogs):
    doc = fresh.doc
    doc.project.poses[0].positions[:] = doc.project.mesh.rest  # a pose that moves nothing
    still = doc.project.poses[0].name
    trigger(fresh, "Auto Setup from Poses")
    assert still not in [a.name for a in doc.project.wdv.areas]
    assert still not in [a.name for a in doc.project.influence.areas]
    assert len(dialogs) == 1 and still in dialogs[0][1] and "moves no skin" in dialogs[0][1]


def test_strain_becomes_an_editable_mask_that_shows_the_same_wrinkles(fresh):
    doc = fresh.doc
    doc.set_pose_weight("surprise", 1.0)
    marks = viewport_marks(fresh)
    doc.set_view(technique="strain")
    strain = viewport_image(fresh)
    doc.set_view(technique="t1")
    before = viewport_image(fresh)
    steps = doc.undo_stack.count()
    trigger(fresh, "Convert Automatic Wrinkles to Mask")
    (area,) = doc.project.influence.areas
    assert area.name == "surprise strain"
    assert doc.project.influence.links == {"surprise": {"surprise strain": 1.0}}
    assert doc.activations()[0] == pytest.approx(1.0)
    assert doc.undo_stack.count() == steps + 1
    after = viewport_image(fresh)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    # technique 1 now shows about what the automatic mode showed
    assert region_difference(strain, after, marks["forehead"]) < \
        region_difference(before, after, marks["forehead"])
    doc.undo_stack.undo()
    assert doc.project.influence.areas == [] and doc.project.influence.links == {}
    assert np.array_equal(viewport_image(fresh), before)


def test_strain_becomes_a_wdv_area(fresh):
    doc = fresh.doc
    doc.set_pose_weight("surprise", 1.0)
    doc.set_view(technique="t2")
    marks = viewport_marks(fresh)
    before = viewport_image(fresh)
    trigger(fresh, "Convert Automatic Wrinkles to WDV Area")
    (area,) = doc.project.wdv.areas
    assert (area.name, area.pose) == ("surprise strain", "surprise") and area.authored.sum() > 30
    after = viewport_image(fresh)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    doc.undo_stack.undo()
    assert doc.project.wdv.areas == []
    assert np.array_equal(viewport_image(fresh), before)


def test_converting_in_the_neutral_pose_says_why_and_changes_nothing(fresh, dialogs):
    trigger(fresh, "Convert Automatic Wrinkles to Mask")
    trigger(fresh, "Convert Automatic Wrinkles to WDV Area")
    assert [kind for kind, _ in dialogs] == ["critical", "critical"]
    assert "neutral pose" in dialogs[0][1]
    assert fresh.doc.undo_stack.count() == 0


# --- the synthesised wrinkled map ----------------------------------------------------------------

def fill_synth_dialog(qtbot, done: list, name: str | None = None, poses: set[str] | None = None,
                      size: int = 512) -> None:
    """When the dialog opens: set it up as a user would and press Synthesise."""
    def act() -> None:
        dialog = QApplication.activeModalWidget()
        assert isinstance(dialog, SynthDialog)
        done.append(dialog)
        if name is not None:
            dialog.map_name.setCurrentText(name)
        dialog.size.setCurrentIndex(dialog.size.findData(size))
        dialog.spacing.setValue(10.0)
        dialog.depth.setValue(2.0)
        for i in range(dialog.poses.count()):
            item = dialog.poses.item(i)
            if poses is not None and item.text() not in poses:
                item.setCheckState(Qt.CheckState.Unchecked)
        ok = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
        qtbot.mouseClick(ok, Qt.MouseButton.LeftButton)

    QTimer.singleShot(0, act)


def test_synthesised_map_replaces_a_flat_placeholder_and_shows_forehead_furrows(
        open_window, sample, qtbot):
    fresh = open_plain(open_window, as_imported(sample, flat_map=True))
    doc = fresh.doc
    project = doc.project
    flat = project.textures.wrinkle_maps["wrinkles"]
    doc.set_pose_weight("surprise", 1.0)
    trigger(fresh, "Auto Setup from Poses")
    doc.set_view(technique="t2")
    marks = viewport_marks(fresh)
    before = viewport_image(fresh)
    steps = doc.undo_stack.count()
    opened: list = []
    fill_synth_dialog(qtbot, opened, poses={"surprise", "frown"})
    trigger(fresh, "Synthesise Wrinkled Normal Map…")
    assert len(opened) == 1
    assert opened[0].map_name.currentText() == "wrinkles"  # the flat map was offered
    assert project.textures.wrinkle_map_names == ["wrinkles"]
    new = project.textures.wrinkle_maps["wrinkles"]
    assert new.shape == (512, 512, 3) and not (new == new[0, 0]).all()
    assert doc.undo_stack.count() == steps + 1
    after = viewport_image(fresh)
    assert region_difference(before, after, marks["forehead"]) > 2.0
    doc.undo_stack.undo()
    assert project.textures.wrinkle_maps["wrinkles"] is flat
    assert np.array_equal(viewport_image(fresh), before)


def test_synthesised_map_is_added_by_a_new_name_for_the_poses_areas(window, qtbot):
    """A new map, revealed by the areas that follow the chosen pose; one undo takes both back."""
    doc = window.doc
    project = doc.project
    textures = project.textures
    names = textures.wrinkle_map_names
    assert len(names) < MAX_WRINKLE_MAPS
    kept = dict(textures.wrinkle_maps)
    areas = [*project.influence.areas, *project.wdv.areas]
    maps_before = [a.wrinkle_map for a in areas]
    window.wdv_tools.overlay.visible = False
    doc.set_view(technique="t2")
    doc.set_pose_weight("squeeze", 1.0)
    marks = viewport_marks(window)
    before = viewport_image(window)
    opened: list = []
    fill_synth_dialog(qtbot, opened, poses={"squeeze"})
    trigger(window, "Synthesise Wrinkled Normal Map…")
    assert opened[0].map_name.currentText() == "synthesised"
    assert "Adds a new wrinkled map" in opened[0].target.text()
    assert textures.wrinkle_map_names == [*names, "synthesised"]
    assert all(textures.wrinkle_maps[n] is kept[n] for n in names)
    squeeze_areas = {a.name for a in project.wdv.areas if a.pose == "squeeze"} | set(
        project.influence.links["squeeze"])
    for area in areas:
        assert (area.wrinkle_map == "synthesised") == (area.name in squeeze_areas)
    after = viewport_image(window)
    assert region_difference(before, after, marks["eye corner left"]) > 2.0
    assert region_difference(before, after, marks["forehead"]) == 0.0
    doc.undo_stack.undo()
    assert textures.wrinkle_map_names == names
    assert [a.wrinkle_map for a in areas] == maps_before
    assert np.array_equal(viewport_image(window), before)


def test_with_four_maps_the_dialog_offers_to_replace_one(window, qtbot):
    doc = window.doc
    textures = doc.project.textures
    for i in range(MAX_WRINKLE_MAPS - len(textures.wrinkle_map_names)):
        textures.set_wrinkle_map(f"extra {i}", textures.normal_wrinkled.copy())
    names = textures.wrinkle_map_names
    kept = dict(textures.wrinkle_maps)
    target = names[1]
    opened: list = []
    fill_synth_dialog(qtbot, opened, name=target, poses={"squeeze"})
    trigger(window, "Synthesise Wrinkled Normal Map…")
    dialog = opened[0]
    assert not dialog.map_name.isEditable()
    assert [dialog.map_name.itemText(i) for i in range(dialog.map_name.count())] == names
    assert f"{MAX_WRINKLE_MAPS} wrinkled maps" in dialog.target.text()
    assert textures.wrinkle_map_names == names
    assert textures.wrinkle_maps[target] is not kept[target]
    assert all(textures.wrinkle_maps[n] is kept[n] for n in names if n != target)
    doc.undo_stack.undo()
    assert textures.wrinkle_maps[target] is kept[target]


def test_cancelling_the_synthesis_changes_nothing(window, qtbot, monkeypatch):
    monkeypatch.setattr(QProgressDialog, "wasCanceled", lambda self: True)
    names = window.doc.project.textures.wrinkle_map_names
    opened: list = []
    fill_synth_dialog(qtbot, opened)
    trigger(window, "Synthesise Wrinkled Normal Map…")
    assert len(opened) == 1
    assert window.doc.project.textures.wrinkle_map_names == names
    assert window.doc.undo_stack.count() == 0


def test_the_dialog_needs_a_name_and_a_pose(window, qtbot):
    dialog = SynthDialog(window)
    qtbot.addWidget(dialog)
    ok = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
    assert ok.isEnabled()
    for i in range(dialog.poses.count()):
        dialog.poses.item(i).setCheckState(Qt.CheckState.Unchecked)
    assert not ok.isEnabled()
    dialog.poses.item(0).setCheckState(Qt.CheckState.Checked)
    assert ok.isEnabled()
    dialog.map_name.setCurrentText("  ")
    assert not ok.isEnabled()
