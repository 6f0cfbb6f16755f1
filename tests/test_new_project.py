"""File ▸ New from Files: a project from the user's own meshes and maps, through the dialog."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtWidgets import QDialogButtonBox

from studio.core.files.errors import MeshError
from studio.core.files.images import write_png
from studio.core.formats.assemble import project_from_files
from studio.core.mesh.meshio import save_obj
from studio.core.sample.synthetic import make_test_face
from studio.widgets.new_project_dialog import NewProjectDialog


@pytest.fixture
def face_files(tmp_path):
    """The sample face written out as OBJ files and PNG maps, as an artist would bring them."""
    project = make_test_face(561, texture_size=64, mask_size=32)
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
    other = make_test_face(1071, texture_size=16, mask_size=16)
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


# --------------------------------------------------------------------------------------------
# Parts of an OBJ: keep some, mark some as not face (dialog and command line)
# --------------------------------------------------------------------------------------------


@pytest.fixture
def head_with_eyes(tmp_path):
    """The sample face plus an "eye" (a little quad grid over its forehead) in one OBJ with two
    groups and materials, and a key pose of both: an artist's export with the eyes inside."""
    project = make_test_face(561, texture_size=64, mask_size=32)
    mesh = project.mesh
    save_obj(tmp_path / "face.obj", mesh)
    save_obj(tmp_path / "face_pose.obj", mesh, project.poses[0].positions)
    n = mesh.n_welded
    eye = "\n".join(["v 0 0.1 0.2", "v 0.05 0.1 0.2", "v 0.05 0.15 0.2", "v 0 0.15 0.2",
                     "vt 0 0", "vt 0.01 0", "vt 0.01 0.01", "vt 0 0.01"])
    vt0 = len(mesh.uvs)
    eye_face = " ".join(f"{n + i}/{vt0 + i}" for i in range(1, 5))
    for name in ("face", "face_pose"):
        text = (tmp_path / f"{name}.obj").read_text()
        head, _, faces = text.partition("\nf ")
        text = (f"{head}\n{eye}\ng skin\nusemtl skin\nf {faces}g Eye_L\nusemtl eye\n"
                f"f {eye_face}\n")
        (tmp_path / f"{name}.obj").write_text(text)
    return tmp_path, project


def test_keep_drops_the_eyes_from_the_face_and_its_poses(head_with_eyes):
    folder, original = head_with_eyes
    whole = project_from_files(folder / "face.obj", {"smile": folder / "face_pose.obj"})
    assert whole.mesh.n_welded == original.mesh.n_welded + 4
    project = project_from_files(folder / "face.obj", {"smile": folder / "face_pose.obj"},
                                 keep=["skin"])
    assert project.mesh.n_welded == original.mesh.n_welded
    np.testing.assert_allclose(project.poses[0].positions, original.poses[0].positions,
                               atol=1e-5)
    assert project.not_face is None


def test_not_face_flags_only_the_eye_vertices(head_with_eyes):
    folder, original = head_with_eyes
    project = project_from_files(folder / "face.obj", not_face=["Eye_L"])
    assert project.not_face is not None and project.not_face.sum() == 4
    assert project.not_face[-4:].all()  # the eye's v come last in the file
    assert project.skin_weights()[:original.mesh.n_welded].min() == 1.0
    with pytest.raises(MeshError, match="leaves no skin"):
        project_from_files(folder / "face.obj", not_face=["skin", "eye"])


def test_cli_keep_and_not_face(head_with_eyes, capsys):
    from studio.cli import main

    folder, original = head_with_eyes
    out = folder / "p.wrinkle"
    assert main(["new", "--mesh", str(folder / "face.obj"), "--pose",
                 f"smile={folder / 'face_pose.obj'}", "--keep", "skin", "--keep", "Eye_L",
                 "--not-face", "eye", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"{original.mesh.n_welded + 4} vertices" in printed
    assert "not face (eye): 4 vertices" in printed
    assert out.exists()


def test_cli_unknown_group_is_one_line_naming_file_and_groups(head_with_eyes, capsys):
    from studio.cli import main

    folder, _ = head_with_eyes
    code = main(["new", "--mesh", str(folder / "face.obj"), "--keep", "eyes",
                 "-o", str(folder / "p.wrinkle")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    assert "face.obj" in err and "'eyes'" in err
    assert "(the file has: eye, Eye_L, skin)" in err
    assert not (folder / "p.wrinkle").exists()


def test_the_dialog_offers_the_parts_and_applies_the_choice(qtbot, head_with_eyes, dialogs):
    from PySide6.QtCore import Qt

    folder, original = head_with_eyes
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    parts = dialog.parts
    assert parts.isHidden()
    dialog.mesh.edit.setText(str(folder / "face.obj"))
    assert not parts.isHidden()
    # Groups and materials both split this file in two; groups come first.
    assert [parts.kind.itemData(i) for i in range(parts.kind.count())] == ["group", "material"]
    rows = {parts.table.item(r, 0).text(): r for r in range(parts.table.rowCount())}
    assert rows == {"skin": 0, "Eye_L": 1}
    assert parts.table.item(rows["Eye_L"], parts.FACES).text() == "1"
    assert int(parts.table.item(rows["skin"], parts.FACES).text()) == original.mesh.n_triangles
    # The eye is offered as not face; the skin is not.
    assert parts.ticked(parts.NOT_FACE) == ["Eye_L"]
    # Keep all: the Keep ticks are greyed out.
    assert not parts.table.item(rows["skin"], parts.KEEP).flags() & Qt.ItemFlag.ItemIsEnabled
    ok = dialog.findChild(QDialogButtonBox).button(QDialogButtonBox.StandardButton.Ok)
    ok.click()
    assert dialogs == []
    assert dialog.project.mesh.n_welded == original.mesh.n_welded + 4
    assert dialog.project.not_face.sum() == 4

    # Keep only the ticked parts, without the eye, and nothing marked as not face.
    again = NewProjectDialog()
    qtbot.addWidget(again)
    again.mesh.edit.setText(str(folder / "face.obj"))
    again.add_pose("smile", str(folder / "face_pose.obj"))
    again.parts.kind.setCurrentIndex(1)  # by material: the same choice through other names
    table = again.parts.table
    assert [table.item(r, 0).text() for r in range(table.rowCount())] == ["skin", "eye"]
    again.parts.keep_some.click()
    item = table.item(1, again.parts.KEEP)
    assert item.flags() & Qt.ItemFlag.ItemIsEnabled
    item.setCheckState(Qt.CheckState.Unchecked)
    again.parts.set_ticked(again.parts.NOT_FACE, set())
    again.create()
    assert dialogs == []
    assert again.project.mesh.n_welded == original.mesh.n_welded
    assert again.project.not_face is None
    assert [p.name for p in again.project.poses] == ["smile"]


def test_the_parts_table_stays_hidden_for_a_single_part_mesh(qtbot, face_files):
    folder, _ = face_files
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.mesh.edit.setText(str(folder / "neutral.obj"))
    assert dialog.parts.isHidden() and dialog.parts.keep() is None


def test_browse_opens_beside_the_files_the_user_chose(qtbot, face_files, monkeypatch, dialogs):
    """A map's or a pose's Browse… opens in the neutral mesh's folder, and a first Browse…
    in the folder the user last chose a file in (not the home folder)."""
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QFileDialog, QPushButton

    from studio.widgets.app_settings import settings

    folder, _ = face_files
    elsewhere = folder / "textures"
    elsewhere.mkdir()
    settings().setValue("last_folder", str(elsewhere))
    asked: list[str] = []

    def chooser(chosen: str):
        def ask(_parent, _caption, start, _filter=""):
            asked.append(start)
            return chosen, ""
        return staticmethod(ask)

    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.show()
    buttons = [b for b in dialog.findChildren(QPushButton) if b.text() == "Browse…"]
    monkeypatch.setattr(QFileDialog, "getOpenFileName", chooser(str(folder / "neutral.obj")))
    qtbot.mouseClick(buttons[0], Qt.MouseButton.LeftButton)  # the neutral mesh: nothing yet
    assert asked == [str(elsewhere)] and dialog.mesh.path() == str(folder / "neutral.obj")
    monkeypatch.setattr(QFileDialog, "getOpenFileName", chooser(str(folder / "diffuse.png")))
    qtbot.mouseClick(buttons[1], Qt.MouseButton.LeftButton)  # the diffuse map
    assert asked[-1] == str(folder)
    poses: list[str] = []
    monkeypatch.setattr(QFileDialog, "getOpenFileNames", staticmethod(
        lambda _p, _c, start, _f="": (poses.append(start), ([], ""))[1]))
    add = next(b for b in dialog.findChildren(QPushButton) if b.text() == "Add key poses…")
    qtbot.mouseClick(add, Qt.MouseButton.LeftButton)
    assert poses == [str(folder)]
    assert settings().value("last_folder") == str(folder)  # remembered for the next dialog
