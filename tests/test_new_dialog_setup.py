"""File ▸ New from Files sets a head up as ``wrinkle-studio new`` does (issue #35): the same
files through the dialog, driven as a person drives it (typing paths, picking axes with the
keyboard, clicking), give the same project as the command line — a VRM's toggles left out of
the wrinkles, a whole body's vertices beyond the head marked not face, the user's up and front
over the file's — and the dialog offers .vrm and .fbx files and says what it found."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QDialogButtonBox, QFileDialog, QPushButton

from studio.cli import main
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.widgets.new_project_dialog import NewProjectDialog
from tests.test_full_body import UNITS, build_body, write_obj
from tests.test_vrm import build_vrm

TOGGLE = "HideHairBalls"  # the VRM's toggle morph (tests/test_vrm.py)


def from_the_command_line(args: list[str], out: Path) -> tuple[Project, str]:
    """``wrinkle-studio new … -o out``: the project written and what it printed."""
    printed = io.StringIO()
    with redirect_stdout(printed):
        assert main(["new", *args, "-o", str(out)]) == 0
    return load_project(out), printed.getvalue()


def open_dialog(qtbot) -> NewProjectDialog:
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    return dialog


def button(dialog: NewProjectDialog, text: str) -> QPushButton:
    return next(b for b in dialog.findChildren(QPushButton) if b.text() == text)


def set_auto(qtbot, dialog: NewProjectDialog, on: bool) -> None:
    """Click the auto set-up check box if it is not as wanted (it remembers the last use)."""
    if dialog.auto.isChecked() != on:
        qtbot.mouseClick(dialog.auto, Qt.MouseButton.LeftButton,
                         pos=QPoint(8, dialog.auto.height() // 2))  # on its box
    assert dialog.auto.isChecked() == on


def type_path(qtbot, dialog: NewProjectDialog, path: Path) -> None:
    qtbot.mouseClick(dialog.mesh.edit, Qt.MouseButton.LeftButton)
    qtbot.keyClicks(dialog.mesh.edit, str(path))


def pick_axes(qtbot, dialog: NewProjectDialog, up: str, front: str) -> None:
    """Type each axis into its closed combo box, as a person picks an item by its name."""
    qtbot.keyClicks(dialog.up, up)
    qtbot.keyClicks(dialog.front, front)


def test_the_file_filter_offers_vrm_fbx_and_usd(qtbot, monkeypatch, dialogs) -> None:
    filters: list[str] = []

    def ask(_parent, _caption, _start, file_filter=""):
        filters.append(file_filter)
        return "", ""

    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(ask))
    dialog = open_dialog(qtbot)
    qtbot.mouseClick(button(dialog, "Browse…"), Qt.MouseButton.LeftButton)
    meshes = filters[0].split(";;")[0]
    for suffix in ("*.usd", "*.usda", "*.usdc", "*.usdz", "*.vrm", "*.fbx", "*.glb", "*.obj"):
        assert suffix in meshes, meshes
    assert dialogs == []


@pytest.fixture(scope="module")
def vrm_files(tmp_path_factory) -> tuple[Path, Project, str]:
    """The test avatar as a VRM 0.x, and what ``new --gltf avatar.vrm --auto`` made of it."""
    folder = tmp_path_factory.mktemp("vrm_dialog")
    vrm = build_vrm(folder / "avatar.vrm")
    return (vrm, *from_the_command_line(["--gltf", str(vrm), "--auto"],
                                        folder / "cli.wrinkle"))


def test_a_vrm_through_the_dialog_is_set_up_as_on_the_command_line(qtbot, vrm_files, dialogs
                                                                    ) -> None:
    vrm, cli, printed = vrm_files
    dialog = open_dialog(qtbot)
    set_auto(qtbot, dialog, True)
    type_path(qtbot, dialog, vrm)
    assert not dialog.parts.isHidden()  # a VRM's meshes are listed as a glTF's are
    qtbot.keyClick(dialog.mesh.edit, Qt.Key.Key_Return)  # Create
    assert dialogs == []
    assert dialog.result() == dialog.DialogCode.Accepted
    made = dialog.project
    assert [p.name for p in made.poses] == [p.name for p in cli.poses]
    assert made.mesh.n_welded == cli.mesh.n_welded
    assert np.array_equal(made.not_face, cli.not_face)  # the eyes and the hair balls
    assert made.view.get("up") == cli.view.get("up")
    assert made.view.get("front") == cli.view.get("front")
    # the toggle is a key pose still, but no wrinkle, on both ways
    for project in (made, cli):
        assert TOGGLE in project.pose_names
        assert TOGGLE not in {a.name for a in project.influence.areas}
        assert TOGGLE not in {a.pose for a in project.wdv.areas}
        assert {a.pose for a in project.wdv.areas}  # and the others are set up
    assert ({a.pose for a in made.wdv.areas} == {a.pose for a in cli.wdv.areas})
    # what was found is said, as the command line says it
    said = "\n".join(dialog.report)
    assert f"toggles, not set up as wrinkles: {TOGGLE}" in said
    assert f"toggles, not set up as wrinkles: {TOGGLE}" in printed
    assert "VRM 0.x: faces -Z, Y up" in said
    assert "Assumed: " in said and "front -Z (as given)" in said


@pytest.fixture(scope="module")
def body_files(tmp_path_factory) -> tuple[Path, dict[str, Path]]:
    """A whole body in one part (the full-body test's skin: a head on a torso and legs, Y up,
    facing +Z, decimetres) and its expression units as key-pose OBJs."""
    folder = tmp_path_factory.mktemp("body_dialog")
    body = build_body()[:1]
    mesh = write_obj(body, folder / "body.obj")
    return mesh, {unit: write_obj(body, folder / f"{unit}.obj", unit) for unit in UNITS}


def test_a_whole_body_through_the_dialog_is_marked_and_framed_as_on_the_command_line(
        qtbot, body_files, monkeypatch, tmp_path, dialogs) -> None:
    mesh, poses = body_files
    cli, printed = from_the_command_line(
        ["--mesh", str(mesh), "--up", "y", "--front", "z",
         *(arg for name, path in poses.items() for arg in ("--pose", f"{name}={path}"))],
        tmp_path / "cli.wrinkle")
    assert "a whole body:" in printed

    dialog = open_dialog(qtbot)
    set_auto(qtbot, dialog, False)
    type_path(qtbot, dialog, mesh)
    monkeypatch.setattr(QFileDialog, "getOpenFileNames",  # the person picks the unit files
                        staticmethod(lambda *_a, **_k: ([str(p) for p in poses.values()], "")))
    qtbot.mouseClick(button(dialog, "Add key poses…"), Qt.MouseButton.LeftButton)
    pick_axes(qtbot, dialog, "+y", "+Z")
    assert (dialog.up.currentText(), dialog.front.currentText()) == ("+Y", "+Z")
    qtbot.keyClick(dialog.front, Qt.Key.Key_Return)  # Create
    assert dialogs == []
    made = dialog.project
    assert made is not None and [p.name for p in made.poses] == list(poses)
    assert made.view.get("up") == cli.view.get("up") == "y"
    assert made.view.get("front") == cli.view.get("front") == "z"
    # the torso and legs are not face; the head is
    assert made.not_face is not None and np.array_equal(made.not_face, cli.not_face)
    assert 0 < made.not_face.sum() < made.mesh.n_welded
    head_top = made.mesh.rest[:, 1].max()
    assert not made.not_face[made.mesh.rest[:, 1] > head_top - 1.0].any()
    assert made.not_face[made.mesh.rest[:, 1] < 10.0].all()  # legs and the lower torso
    said = "\n".join(dialog.report)
    assert f"a whole body: {int(made.not_face.sum())} vertices beyond the head" in said
    assert "as given" in said


def test_a_bad_vrm_is_one_message_naming_it_and_the_dialog_stays(qtbot, tmp_path, dialogs
                                                                 ) -> None:
    bad = tmp_path / "broken.vrm"
    bad.write_bytes(b"glTF" + bytes(40))
    dialog = open_dialog(qtbot)
    type_path(qtbot, dialog, bad)
    qtbot.mouseClick(dialog.findChild(QDialogButtonBox).button(
        QDialogButtonBox.StandardButton.Ok), Qt.MouseButton.LeftButton)
    assert dialog.project is None and dialog.isVisible()
    assert len(dialogs) == 1 and dialogs[0][0] == "critical"
    assert "broken.vrm" in dialogs[0][1] and "Traceback" not in dialogs[0][1]


def test_an_fbx_through_the_dialog_brings_its_shape_keys_as_on_the_command_line(
        qtbot, tmp_path, dialogs) -> None:
    """Stock Blender's FBX of the ICT head (Z up, a helmet beside it): typed in as the neutral
    mesh, its shape keys become the key poses and its face is found, as ``new --mesh`` does."""
    pytest.importorskip("bpy")
    from tests.fbx_blender import write_fbx

    fbx = write_fbx(tmp_path / "head.fbx", up="Z", poses=["browInnerUp_L", "mouthSmile_L"])
    cli, printed = from_the_command_line(["--mesh", str(fbx)], tmp_path / "cli.wrinkle")
    dialog = open_dialog(qtbot)
    set_auto(qtbot, dialog, False)
    type_path(qtbot, dialog, fbx)
    assert dialog.parts.isHidden()  # an FBX's face is found at Create, not listed
    qtbot.keyClick(dialog.mesh.edit, Qt.Key.Key_Return)  # Create
    assert dialogs == []
    made = dialog.project
    assert made is not None
    assert [p.name for p in made.poses] == [p.name for p in cli.poses] == ["browInnerUp_L",
                                                                            "mouthSmile_L"]
    assert made.mesh.n_welded == cli.mesh.n_welded
    np.testing.assert_allclose(made.mesh.rest, cli.mesh.rest, atol=1e-5)
    assert (made.not_face is None) == (cli.not_face is None)
    assert made.not_face is None or np.array_equal(made.not_face, cli.not_face)
    said = "\n".join(dialog.report)
    assert "FBX scene:" in said and "FBX scene:" in printed


def test_a_body_s_helpers_start_unticked_and_are_left_out_as_on_the_command_line(
        qtbot, monkeypatch, tmp_path, dialogs) -> None:
    """A full body with hair cards, joint markers and helpers as OBJ groups: the parts table
    starts on "Keep only the ticked parts" with the helpers unticked (hover says why), and
    Create leaves them out, as ``new --auto`` does. Red once: with the dialog suggesting only
    not-face parts (the old ``suggest_obj_parts``), every helper stayed ticked and kept."""
    from tests.test_full_body import HELPERS

    groups = build_body()
    mesh = write_obj(groups, tmp_path / "body.obj")
    poses = {unit: write_obj(groups, tmp_path / f"{unit}.obj", unit) for unit in UNITS}
    cli, _ = from_the_command_line(
        ["--mesh", str(mesh), "--auto",
         *(arg for name, path in poses.items() for arg in ("--pose", f"{name}={path}"))],
        tmp_path / "cli.wrinkle")
    dialog = open_dialog(qtbot)
    set_auto(qtbot, dialog, True)
    monkeypatch.setattr(QFileDialog, "getOpenFileNames",  # the person picks the unit files
                        staticmethod(lambda *_a, **_k: ([str(p) for p in poses.values()], "")))
    qtbot.mouseClick(button(dialog, "Add key poses…"), Qt.MouseButton.LeftButton)
    type_path(qtbot, dialog, mesh)
    parts = dialog.parts
    assert not parts.isHidden() and parts.keep_some.isChecked()
    kept = set(parts.ticked(parts.KEEP))
    assert kept and not kept & set(HELPERS)
    for row in range(parts.table.rowCount()):
        name = parts.table.item(row, parts.NAME).text()
        if name in HELPERS:
            assert parts.table.item(row, parts.NAME).toolTip().startswith(
                "Suggested to leave out:")
    qtbot.keyClick(dialog.mesh.edit, Qt.Key.Key_Return)  # Create
    assert dialogs == []
    made = dialog.project
    assert made is not None and made.mesh.n_welded == cli.mesh.n_welded
    assert np.array_equal(made.not_face, cli.not_face)
