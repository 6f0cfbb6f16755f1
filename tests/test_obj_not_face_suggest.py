"""New from Files suggests an OBJ's not-face parts the way it does a glTF's: by name, and — for
parts named nothing telling ("part_3", "Material.002") — as small closed shells (an eyeball)
and as parts every key pose only turns or shifts (lower teeth), said in a tooltip; the user's
own ticks are never overridden."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog, QPushButton

from studio.core.formats.assemble import suggest_obj_parts
from studio.widgets.new_project_dialog import NewProjectDialog

# an octahedron: a closed shell, 2 units across beside a 20-unit sheet of skin
BALL = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
BALL_FACES = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5),
              (0, 3, 5)]


def head_parts(shift: float = 0.0) -> tuple[np.ndarray, list[tuple[str, list[tuple]]]]:
    """Positions and faces by material: a 5 × 5 sheet of skin ("mat_skin"), the closed shell
    ("mat_a") and an open patch of two triangles ("mat_b"). ``shift`` is the key pose: it
    squeezes the sheet's middle column and moves the patch by that much, without turning it."""
    xs, ys = np.meshgrid(np.linspace(-10, 10, 5), np.linspace(-10, 10, 5))
    sheet = np.c_[xs.ravel(), ys.ravel(), np.zeros(25)]
    sheet[xs.ravel() == 0, 0] += shift  # skin stretches and squeezes: not rigid
    quads = [(r * 5 + c, r * 5 + c + 1, (r + 1) * 5 + c + 1, (r + 1) * 5 + c)
             for r in range(4) for c in range(4)]
    ball = BALL + np.array([0.0, 0.0, 3.0])
    patch = np.array([[0, -14, 0], [2, -14, 0], [2, -12, 0], [0, -12, 0]], float)
    patch += [0.0, shift, 0.0]
    points = np.vstack([sheet, ball, patch])
    faces = [("mat_skin", quads),
             ("mat_a", [tuple(25 + i for i in f) for f in BALL_FACES]),
             ("mat_b", [(31, 32, 33), (31, 33, 34)])]
    return points, faces


def write_obj(path: Path, shift: float = 0.0) -> Path:
    points, faces = head_parts(shift)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in points]
    lines += [f"vt {(x + 20) / 40:.6f} {(y + 20) / 40:.6f}" for x, y, _ in points]
    for material, polys in faces:
        lines.append(f"usemtl {material}")
        lines += ["f " + " ".join(f"{i + 1}/{i + 1}" for i in poly) for poly in polys]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    return write_obj(tmp_path / "head.obj"), write_obj(tmp_path / "open.obj", shift=1.5)


@pytest.mark.core
def test_shells_by_themselves_and_rigid_parts_once_a_pose_moves_them(files) -> None:
    neutral, pose = files
    assert suggest_obj_parts(neutral, "material") == {"mat_a": "small closed shell"}
    assert suggest_obj_parts(neutral, "material", {"open": pose}) == {
        "mat_a": "small closed shell", "mat_b": "moved rigidly"}
    # many poses: a spread of them is read (a real rig's 53 would hold up the dialog)
    many = {f"pose {k}": pose for k in range(30)}
    assert suggest_obj_parts(neutral, "material", many)["mat_b"] == "moved rigidly"
    # a pose file that cannot be read is Create's to report: the suggestion goes on without it
    assert suggest_obj_parts(neutral, "material", {"x": neutral.parent / "none.obj"}) == {
        "mat_a": "small closed shell"}


def _row(dialog: NewProjectDialog, name: str) -> int:
    table = dialog.parts.table
    return next(r for r in range(table.rowCount()) if table.item(r, 0).text() == name)


def test_the_dialog_ticks_what_it_finds_and_keeps_the_user_s_own_ticks(
        qtbot, files, monkeypatch) -> None:
    neutral, pose = files
    dialog = NewProjectDialog()
    qtbot.addWidget(dialog)
    dialog.show()
    parts, table = dialog.parts, dialog.parts.table
    dialog.mesh.edit.setText(str(neutral))
    assert parts.ticked(parts.NOT_FACE) == ["mat_a"]
    assert "small closed shell" in table.item(_row(dialog, "mat_a"), parts.NOT_FACE).toolTip()

    # Add key poses…: the pose moves the patch rigidly, and it is ticked too; the shell, which
    # no pose moves, is suggested to leave out (a helper), as ``new --auto`` chooses
    monkeypatch.setattr(QFileDialog, "getOpenFileNames", lambda *a, **k: ([str(pose)], ""))
    add = next(b for b in dialog.findChildren(QPushButton) if b.text() == "Add key poses…")
    qtbot.mouseClick(add, Qt.MouseButton.LeftButton)
    assert sorted(parts.ticked(parts.NOT_FACE)) == ["mat_b"]
    assert "moved rigidly" in table.item(_row(dialog, "mat_b"), parts.NOT_FACE).toolTip()
    assert parts.keep_some.isChecked() and "mat_a" not in parts.ticked(parts.KEEP)
    assert "no pose moves it" in table.item(_row(dialog, "mat_a"), parts.KEEP).toolTip()
    qtbot.mouseClick(parts.keep_all, Qt.MouseButton.LeftButton)  # the user keeps every part

    # the user unticks the patch (click its cell, Space): more poses leave their choice alone
    item = table.item(_row(dialog, "mat_b"), parts.NOT_FACE)
    qtbot.mouseClick(table.viewport(), Qt.MouseButton.LeftButton,
                     pos=table.visualItemRect(item).center())
    qtbot.keyClick(table.viewport(), Qt.Key.Key_Space)
    assert parts.ticked(parts.NOT_FACE) == []
    monkeypatch.setattr(QFileDialog, "getOpenFileNames",
                        lambda *a, **k: ([str(pose.with_name("again.obj"))], ""))
    pose.with_name("again.obj").write_bytes(pose.read_bytes())
    qtbot.mouseClick(add, Qt.MouseButton.LeftButton)
    assert dialog.poses.rowCount() == 2
    assert parts.ticked(parts.NOT_FACE) == []
    remove = next(b for b in dialog.findChildren(QPushButton) if b.text() == "Remove")
    dialog.poses.setCurrentCell(1, 0)
    qtbot.mouseClick(remove, Qt.MouseButton.LeftButton)
    assert dialog.poses.rowCount() == 1 and parts.ticked(parts.NOT_FACE) == []
