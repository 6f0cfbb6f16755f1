"""A file the studio exported, brought in again with ``new --auto`` (issue #36's leftover): the
set-up it carries is kept as it was, not made a second time beside itself ("browInnerUp_L 2")."""

from __future__ import annotations

import io
from contextlib import redirect_stdout

from studio.cli import main
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project


def test_new_auto_on_an_exported_set_up_keeps_it_and_adds_no_copies(sample, tmp_path) -> None:
    """Red once: with every pose handed to ``auto_start`` (new_setup.py before), the areas came
    back twice, the copies named "… 2"."""
    save_project(sample, tmp_path / "face.wrinkle")
    assert main(["export", str(tmp_path / "face.wrinkle"), "--gltf",
                 str(tmp_path / "face.glb")]) == 0
    printed = io.StringIO()
    with redirect_stdout(printed):
        assert main(["new", "--gltf", str(tmp_path / "face.glb"), "--auto",
                     "-o", str(tmp_path / "again.wrinkle")]) == 0
    again = load_project(tmp_path / "again.wrinkle")
    names = [a.name for a in again.influence.areas]
    assert names == [a.name for a in sample.influence.areas]
    assert [a.name for a in again.wdv.areas] == [a.name for a in sample.wdv.areas]
    driving = {p for p, gains in sample.influence.links.items() if gains}
    driving |= {a.pose for a in sample.wdv.areas}
    assert f"already set up in the file, kept: {', '.join(sorted(driving))}" in printed.getvalue()
