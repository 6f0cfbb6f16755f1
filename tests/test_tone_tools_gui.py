"""Each wrinkled map's cavity and colour maps in the Maps menu (issue 46, point 1): replaced
from an image, exported to paint over, removed, kept through a rename; each one undo step, the
viewport's skin look showing the change."""

from __future__ import annotations

import numpy as np
from PySide6.QtWidgets import QFileDialog, QMenu

from studio.core.files.images import load_rgb, read_image, write_png
from tests.gui_helpers import viewport_image, viewport_marks
from tests.regions import patch

RED = (150, 60, 60)  # a colour map's tint: more red, much less green and blue (128: none)


def map_menu(window, name: str) -> QMenu:
    """Maps ▸ Wrinkled Normal Maps ▸ ``name``, as the menu shows it when opened."""
    bar = window.menuBar()
    maps = next(a.menu() for a in bar.actions() if a.text().replace("&", "") == "Maps")
    maps.aboutToShow.emit()
    wrinkled = next(a.menu() for a in maps.actions()
                    if a.text().replace("&", "") == "Wrinkled Normal Maps")
    return next(a.menu() for a in wrinkled.actions() if a.text() == name)


def click(window, name: str, entry: str) -> None:
    menu = map_menu(window, name)
    action = next((a for a in menu.actions() if a.text() == entry), None)
    assert action is not None, [a.text() for a in menu.actions()]
    action.trigger()


def entries(window, name: str) -> list[str]:
    return [a.text() for a in map_menu(window, name).actions() if a.text()]


def redness(image: np.ndarray, centre) -> float:
    rgb = patch(image, centre, 6).reshape(-1, image.shape[-1])[:, :3].astype(float)
    return float((rgb[:, 0] / np.maximum(rgb[:, 1], 1.0)).mean())


def test_a_colour_map_replaced_from_an_image_tints_the_skin_look_and_undoes(
        window, monkeypatch, tmp_path):
    doc = window.doc
    name = doc.project.textures.wrinkle_map_names[0]
    area = next(i for i, a in enumerate(doc.project.influence.areas) if a.wrinkle_map in
                ("", name))
    doc.set_view(technique="t1", look="skin")
    doc.set_area_activation(area, 1.0)
    mark = viewport_marks(window)["forehead right"]
    before = viewport_image(window)
    assert "Export Colour Map…" not in entries(window, name)  # the sample has none yet
    tint = np.empty((64, 64, 3), np.uint8)
    tint[...] = RED
    write_png(tmp_path / "flush.png", tint)
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        staticmethod(lambda *a, **k: (str(tmp_path / "flush.png"), "")))
    click(window, name, "Replace Colour Map…")
    assert np.array_equal(doc.project.textures.colour_maps[name], tint)
    after = viewport_image(window)
    assert redness(after, mark) > redness(before, mark) + 0.15
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda *a, **k: (str(tmp_path / "out"), "")))
    click(window, name, "Export Colour Map…")
    assert np.array_equal(load_rgb(tmp_path / "out.png"), tint)
    doc.undo_stack.undo()
    assert name not in doc.project.textures.colour_maps
    assert np.array_equal(viewport_image(window), before)


def test_a_cavity_map_is_replaced_removed_and_kept_through_a_rename(window, monkeypatch,
                                                                   tmp_path):
    doc = window.doc
    name = doc.project.textures.wrinkle_map_names[0]
    deep = np.full((32, 32), 90, np.uint8)
    write_png(tmp_path / "cavity.png", np.dstack([deep] * 3))  # an editor saved it as RGB
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        staticmethod(lambda *a, **k: (str(tmp_path / "cavity.png"), "")))
    click(window, name, "Replace Cavity Map…")
    assert np.array_equal(doc.project.textures.cavity_maps[name], deep)
    from PySide6.QtWidgets import QInputDialog
    monkeypatch.setattr(QInputDialog, "getText",
                        staticmethod(lambda *a, **k: ("deep folds", True)))
    click(window, name, "Rename…")
    assert np.array_equal(doc.project.textures.cavity_maps["deep folds"], deep)
    assert name not in doc.project.textures.cavity_maps
    click(window, "deep folds", "Remove Cavity Map")
    assert not doc.project.textures.has_tone
    assert "Export Cavity Map…" not in entries(window, "deep folds")
    doc.undo_stack.undo()
    doc.undo_stack.undo()  # the rename: the cavity map goes back with the name
    assert np.array_equal(doc.project.textures.cavity_maps[name], deep)
    assert read_image(tmp_path / "cavity.png").shape == (32, 32, 3)
