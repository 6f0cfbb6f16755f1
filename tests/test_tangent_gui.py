"""The tangent frame in the studio window: chosen in the shading panel, drawn by the viewport,
and written by File ▸ Export glTF."""

from __future__ import annotations

import numpy as np

from studio.core.formats.gltf.codec import _Gltf
from studio.core.mesh.geometry import DeformCache
from studio.widgets.maps.map_tools import MapTools
from tests.gui_helpers import viewport_image


def test_the_panel_s_frame_is_drawn_and_exported(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QFileDialog

    combo = window.shading_panel.tangent_frame
    assert combo.currentData() == window.doc.view.tangent_frame == "mikktspace"
    viewport_image(window)
    assert window.viewport.renderer.deform.frame == "mikktspace"
    combo.setCurrentIndex(combo.findData("thesis"))
    combo.activated.emit(combo.currentIndex())
    assert window.doc.view.tangent_frame == "thesis"
    viewport_image(window)
    assert window.viewport.renderer.deform.frame == "thesis"  # the viewport draws it
    path = tmp_path / "face.glb"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", staticmethod(
        lambda *args, **kwargs: (str(path), "")))
    MapTools(window).export_gltf()
    g = _Gltf(path)
    tangent = g.accessor(g.doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"])
    mesh = window.doc.project.mesh
    np.testing.assert_array_equal(tangent, DeformCache(mesh, "thesis").update(mesh.rest)[:, 6:10])
