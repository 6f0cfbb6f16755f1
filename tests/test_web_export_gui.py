"""File ▸ Export ▸ Web Page… (issue #36's leftover): the page made from the window shows the
face as the viewport does now — its camera and its blend — not the command line's defaults."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog

from tests.test_files_gui import click_menu_path
from tests.test_web_player import page_arrays


def test_the_web_page_is_exported_from_the_file_menu_as_the_viewport_shows_it(
        window, qtbot, monkeypatch, tmp_path, dialogs) -> None:
    """Red once: with the command line's look (``ViewSettings()``) the page kept the colour
    blend while the studio drew normals blended."""
    doc = window.doc
    combo = window.shading_panel.blend
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Down)  # from the colour blend to the normal blend
    assert doc.view.blend == "normal"
    doc.camera.yaw = 25.0
    target = tmp_path / "page"
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda *_a, **_k: (str(target), "")))
    click_menu_path(qtbot, window, "File", "Export", "Web Page…")
    page = target / "index.html"
    qtbot.waitUntil(page.is_file, timeout=20000)
    assert dialogs == []
    scene, _ = page_arrays(page.read_text("utf-8"))
    assert scene["look"]["blend"] == "normal"
    assert scene["camera"]["yaw"] == pytest.approx(25.0)
    assert set(scene["areas"]) == {a.name for a in doc.project.influence.areas}
    assert "index.html" in window.statusBar().currentMessage()
