"""File ▸ New from Files with a USD head (issue 49, point 5), as a person does it: the menu
item chosen in the studio window, the .usdz's path typed, Return. The head comes in as ``new
--auto`` makes it (its blend shapes and in-between as key poses, each set up), the report says
what was found, the viewport draws the file's texture, and a pose's slider dragged to full
changes the face."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QApplication

from tests.gui_helpers import drag_slider, viewport_image
from tests.test_files_gui import click_menu_path
from tests.test_new_dialog_setup import (
    from_the_command_line,
    open_dialog,
    set_auto,
    type_path,
)
from tests.usd_heads import INBETWEEN, POSES, write_usd_head

pytest.importorskip("pxr")


@pytest.fixture(scope="module")
def usdz(tmp_path_factory) -> Path:
    return write_usd_head(tmp_path_factory.mktemp("usd_gui"))[".usdz"]


def test_a_usdz_head_through_new_from_files_is_set_up_and_drawn_with_its_texture(
        open_window, sample, qtbot, usdz, tmp_path, dialogs) -> None:
    cli, _ = from_the_command_line(["--mesh", str(usdz), "--auto"], tmp_path / "cli.wrinkle")
    window = open_window(sample)
    seen = []

    def fill() -> None:
        dialog = QApplication.activeModalWidget()
        seen.append(type(dialog).__name__)
        set_auto(qtbot, dialog, True)
        type_path(qtbot, dialog, usdz)
        qtbot.keyClick(dialog.mesh.edit, Qt.Key.Key_Return)  # Create

    QTimer.singleShot(0, fill)
    click_menu_path(qtbot, window, "File", "New from Files…")
    assert seen == ["NewProjectDialog"]
    assert [kind for kind, _ in dialogs] == ["information"], dialogs
    said = dialogs[0][1]
    assert "USD stage: 2 meshes; the face: HeadMesh" in said
    assert "axes: the stage's upAxis Z, turned to Y up" in said
    project = window.doc.project
    shape, weight, _ = INBETWEEN
    between = f"{shape} at {weight:g}"
    assert project.pose_names == cli.pose_names == ["neutral", POSES[0], shape, between,
                                                    POSES[2]]
    assert {a.pose for a in project.wdv.areas} == {a.pose for a in cli.wdv.areas} == {
        *POSES, between}
    np.testing.assert_allclose(project.mesh.rest, cli.mesh.rest, atol=1e-5)
    # drawn: the file's texture (blue over green: a gradient no skin colour is), not plain skin
    before = _drawn(qtbot, window)
    face = np.abs(before.astype(int) - before[2, 2]).max(-1) > 12  # not the background
    red, green, blue = np.median(before[face], axis=0)
    assert face.mean() > 0.1 and blue > green, (face.mean(), red, green, blue)
    drag_slider(qtbot, window.pose_panel.pose_rows[POSES[0]].slider, 1.0)
    after = _drawn(qtbot, window)
    changed = (np.abs(after.astype(int) - before).max(-1) > 4).mean()
    assert changed > 0.01, changed


def _drawn(qtbot, window) -> np.ndarray:
    """The viewport once it has drawn what the document now holds."""
    frames = window.viewport.frames_rendered
    window.viewport.update()
    qtbot.waitUntil(lambda: window.viewport.frames_rendered > frames, timeout=20000)
    return viewport_image(window)


def test_a_usd_file_that_cannot_be_read_is_one_message_naming_it(qtbot, tmp_path,
                                                                 dialogs) -> None:
    bad = tmp_path / "broken.usdc"
    bad.write_bytes(b"PXR-USDC" + b"\xff" * 88)
    dialog = open_dialog(qtbot)
    set_auto(qtbot, dialog, False)
    type_path(qtbot, dialog, bad)
    qtbot.keyClick(dialog.mesh.edit, Qt.Key.Key_Return)  # Create
    assert dialog.project is None and dialog.isVisible()
    assert len(dialogs) == 1 and dialogs[0][0] == "critical"
    text = dialogs[0][1]
    assert text.startswith(f"{bad}: cannot read the USD file (Sdf crate file version mismatch")
    assert "\n" not in text and "pxrInternal" not in text and "Traceback" not in text
