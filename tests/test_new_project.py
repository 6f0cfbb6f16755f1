"""File ▸ New from Files: a project from the user's own meshes and maps, through the dialog."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtWidgets import QDialogButtonBox

from studio.core.assemble import project_from_files
from studio.core.errors import MeshError
from studio.core.images import write_png
from studio.core.meshio import save_obj
from studio.core.sample import make_sample
from studio.widgets.new_project_dialog import NewProjectDialog


@pytest.fixture
def face_files(tmp_path):
    """The sample face written out as OBJ files and PNG maps, as an artist would bring them."""
    project = make_sample(561, texture_size=64, mask_size=32)
    save_obj(tmp_path / "neutral.obj", project.mesh)
    for pose in project.poses:
        save_obj(tmp_path / f"{pose.name}.obj", project.mesh, pose.positions)
    write_png(tmp_path / "diffuse.png", project.textures.diffuse)
    write_png(tmp_path / "wrinkles.png", project.textures.normal_wrinkled)
    return tmp_path, project


def test_project_from_files_keeps_geometry_and_maps(face_files):
    folder, original = face_files
    poses = {p.name: folder / f"{p.name}.obj" for p in original.poses}
    project = project_from_files(folder / "neutral.obj", poses, folder / "diffuse.png",
                                 None, folder / "wrinkles.png")
    assert project.name == "neutral"
    assert [p.name for p in project.poses] == [p.name for p in original.poses]
    np.testing.assert_allclose(project.mesh.rest, original.mesh.rest, atol=1e-5)
    assert project.mesh.n_triangles == original.mesh.n_triangles
    np.testing.assert_allclose(project.poses[0].positions, original.poses[0].positions, atol=1e-5)
    assert np.array_equal(project.textures.normal_wrinkled, original.textures.normal_wrinkled)
    assert (project.textures.normal_neutral == (128, 128, 255)).all()  # flat when not given


def test_a_pose_of_another_mesh_is_rejected_naming_the_file(face_files, tmp_path):
    folder, _ = face_files
    other = make_sample(1071, texture_size=16, mask_size=16)
    save_obj(tmp_path / "alien.obj", other.mesh)
    with pytest.raises(MeshError, match=r"alien\.obj"):
        project_from_files(folder / "neutral.obj", {"alien": tmp_path / "alien.obj"})


def test_the_dialog_builds_the_project(qtbot, face_files, dialogs):
    folder, _ = face_files
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.mesh.edit.setText(str(folder / "neutral.obj"))
    dialog.diffuse.edit.setText(str(folder / "diffuse.png"))
    dialog.wrinkled.edit.setText(str(folder / "wrinkles.png"))
    dialog.add_pose("surprise", str(folder / "surprise.obj"))
    dialog.findChild(QDialogButtonBox).button(QDialogButtonBox.StandardButton.Ok).click()
    assert dialogs == []
    assert dialog.project is not None and dialog.result() == dialog.DialogCode.Accepted
    assert [p.name for p in dialog.project.poses] == ["surprise"]


def test_the_dialog_reports_a_bad_file_and_stays_open(qtbot, tmp_path, dialogs):
    bad = tmp_path / "broken.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.mesh.edit.setText(str(bad))
    dialog.create()
    assert dialog.project is None
    assert len(dialogs) == 1 and "broken.obj" in dialogs[0][1]
