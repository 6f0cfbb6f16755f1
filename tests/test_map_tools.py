"""Maps menu and File ▸ Export in the window: each map change is one undo step."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtWidgets import QFileDialog, QInputDialog

from studio.core.files.images import write_png
from studio.core.formats.gltf.codec import load_gltf
from tests.gui_helpers import fill_export_dialog, viewport_image, viewport_marks
from tests.regions import region_difference


def answer_open(monkeypatch, path):
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: (str(path),
                                                                                     "")))


def test_wrinkled_normals_from_a_height_map_then_undo(window, monkeypatch, tmp_path):
    height = np.zeros((256, 256), np.uint8)
    height[:, ::8] = 255  # vertical ridges everywhere
    write_png(tmp_path / "height.png", height)
    answer_open(monkeypatch, tmp_path / "height.png")
    monkeypatch.setattr(QInputDialog, "getDouble", staticmethod(lambda *a, **k: (2.0, True)))
    window.doc.set_view(technique="t1")
    window.doc.set_area_activation(0, 1.0)
    marks = viewport_marks(window)
    before = viewport_image(window)
    old = window.doc.project.textures.normal_wrinkled
    window.map_tools.from_height()
    new = window.doc.project.textures.normal_wrinkled
    assert new.shape == (256, 256, 3) and not np.array_equal(new[:, :, 0], new[:, 1:2, 0])
    assert region_difference(before, viewport_image(window), marks["forehead right"]) > 4.0
    window.doc.undo_stack.undo()
    assert window.doc.project.textures.normal_wrinkled is old
    assert np.array_equal(viewport_image(window), before)


def test_flip_green_is_undoable(window):
    old = window.doc.project.textures.normal_wrinkled.copy()
    window.map_tools.flip("normal_wrinkled")
    flipped = window.doc.project.textures.normal_wrinkled
    assert np.array_equal(flipped[:, :, 1], 255 - old[:, :, 1])
    assert np.array_equal(flipped[:, :, [0, 2]], old[:, :, [0, 2]])
    window.doc.undo_stack.undo()
    assert np.array_equal(window.doc.project.textures.normal_wrinkled, old)


def test_a_bad_image_is_reported_by_name(window, monkeypatch, tmp_path, dialogs):
    bad = tmp_path / "notanimage.png"
    bad.write_bytes(b"hello")
    answer_open(monkeypatch, bad)
    window.map_tools.replace("diffuse")
    assert len(dialogs) == 1 and "notanimage.png" in dialogs[0][1]
    assert window.doc.undo_stack.count() == 0


@pytest.mark.parametrize("kind", ["gltf", "folder"])
def test_export_from_the_file_menu(window, monkeypatch, tmp_path, kind, qtbot):
    if kind == "gltf":
        monkeypatch.setattr(QFileDialog, "getSaveFileName",
                            staticmethod(lambda *a, **k: (str(tmp_path / "out.glb"), "")))
        window.map_tools.export_gltf()
        glb = tmp_path / "out.glb"
    else:
        fill_export_dialog(qtbot, [], tmp_path / "engine", [])  # the studio's own layout
        window.map_tools.export_folder()
        glb = tmp_path / "engine" / "face.glb"
        assert (tmp_path / "engine" / "wrinkles.json").exists()
    assert load_gltf(glb).mesh.n_welded == window.doc.project.mesh.n_welded


def test_wrinkled_maps_are_added_renamed_and_removed_with_their_areas(window, monkeypatch,
                                                                      tmp_path):
    doc, tools = window.doc, window.map_tools
    textures = doc.project.textures
    first, second = textures.wrinkle_map_names
    area = next(a for a in doc.project.influence.areas if a.wrinkle_map == second)
    names = iter(["smile lines", "cheek folds"])
    monkeypatch.setattr(QInputDialog, "getText",
                        staticmethod(lambda *a, **k: (next(names), True)))
    image = np.full((64, 64, 3), (150, 120, 250), np.uint8)
    write_png(tmp_path / "smile.png", image)
    answer_open(monkeypatch, tmp_path / "smile.png")
    tools.add_wrinkled()
    assert textures.wrinkle_map_names == [first, second, "smile lines"]
    assert np.array_equal(textures.wrinkle_maps["smile lines"], image)
    tools.rename_wrinkled(second)  # -> "cheek folds": the areas that revealed it follow
    assert textures.wrinkle_map_names == [first, "cheek folds", "smile lines"]
    assert area.wrinkle_map == "cheek folds"
    tools.remove_wrinkled("cheek folds")
    assert textures.wrinkle_map_names == [first, "smile lines"] and area.wrinkle_map == ""
    for _ in range(3):
        doc.undo_stack.undo()
    assert textures.wrinkle_map_names == [first, second] and area.wrinkle_map == second


def test_the_maps_menu_lists_each_wrinkled_map(window):
    bar = window.menuBar()
    maps = next(a.menu() for a in bar.actions() if a.text().replace("&", "") == "Maps")
    maps.aboutToShow.emit()
    wrinkled = next(a.menu() for a in maps.actions()
                    if a.text().replace("&", "") == "Wrinkled Normal Maps")
    titles = [a.text() for a in wrinkled.actions() if a.menu()]
    assert titles == window.doc.project.textures.wrinkle_map_names
