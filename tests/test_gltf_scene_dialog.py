"""File ▸ New from Files with an avatar .glb: its meshes and materials listed with what was
found already ticked (the face's meshes kept, eyes and teeth not face), changed by checkbox."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt

from studio.core.formats.gltf.codec import load_gltf
from studio.widgets.new_project_dialog import NewProjectDialog
from tests.gltf_avatar import MESHES, build_avatar


def test_the_dialog_lists_the_avatar_s_meshes_with_the_face_found(qtbot, tmp_path, dialogs):
    glb = build_avatar(tmp_path / "avatar.glb")
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.auto.setChecked(False)
    dialog.mesh.edit.setText(str(glb))
    parts = dialog.parts
    assert not parts.isHidden()
    assert [parts.kind.itemData(i) for i in range(parts.kind.count())] == ["mesh", "material"]
    rows = [parts.table.item(r, 0).text() for r in range(parts.table.rowCount())]
    assert sorted(rows) == sorted(MESHES)
    assert parts.keep_some.isChecked()
    assert sorted(parts.ticked(parts.KEEP)) == ["EyeLeft", "EyeRight", "Head", "Teeth"]
    assert sorted(parts.ticked(parts.NOT_FACE)) == ["EyeLeft", "EyeRight", "Teeth"]
    parts.kind.setCurrentIndex(1)
    assert sorted(parts.ticked(parts.NOT_FACE)) == ["EyeMaterial", "TeethMaterial"]
    parts.kind.setCurrentIndex(0)
    dialog.create()
    assert dialogs == []
    found = load_gltf(glb)
    assert dialog.project.mesh.n_welded == found.mesh.n_welded
    assert np.array_equal(dialog.project.not_face, found.not_face)

    # the teeth unticked as not face, the hair kept: as the user chose
    again = NewProjectDialog()
    qtbot.addWidget(again)
    again.auto.setChecked(False)
    again.mesh.edit.setText(str(glb))
    table, parts = again.parts.table, again.parts
    row = {table.item(r, 0).text(): r for r in range(table.rowCount())}
    table.item(row["Teeth"], parts.NOT_FACE).setCheckState(Qt.CheckState.Unchecked)
    table.item(row["Hair"], parts.KEEP).setCheckState(Qt.CheckState.Checked)
    again.create()
    assert dialogs == []
    chosen = load_gltf(glb, keep=["EyeLeft", "EyeRight", "Head", "Teeth", "Hair"],
                       not_face=["EyeLeft", "EyeRight"])
    assert again.project.mesh.n_welded == chosen.mesh.n_welded == found.mesh.n_welded + 8
    assert np.array_equal(again.project.not_face, chosen.not_face)
