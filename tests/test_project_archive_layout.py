"""What a saved project file holds, as another tool (or a person with unzip) sees it.

PNG members are stored (already compressed; deflating them again only costs time), the rest
deflated; every member readable by its owner's group and others (0644, so a shared drive does
not hide them); project.json indented and written in UTF-8 as it is (an area named in German
reads as German, not as escapes); the previous version kept as NAME.bak, even where the disk
cannot hard-link it. Each is checked on a small hand-made face.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

from studio.core.project.reader import load_project
from studio.core.project.writer import backup_path, save_project
from studio.core.wrinkles.influence import InfluenceArea
from tests.test_auto_setup import grid_mesh, grid_project, squeezed

pytestmark = pytest.mark.core


def small_project():
    project = grid_project(squeeze=squeezed(grid_mesh().rest))
    mask = np.linspace(0.0, 1.0, 256, dtype=np.float32).reshape(16, 16)
    project.influence.areas.append(InfluenceArea("Stirn für", mask))
    return project


def test_members_are_stored_or_deflated_and_readable_by_everyone(tmp_path: Path) -> None:
    path = tmp_path / "face.wrinkle"
    save_project(small_project(), path)
    with zipfile.ZipFile(path) as archive:
        infos = archive.infolist()
    assert {i.filename for i in infos if i.filename.endswith(".png")}  # the case has PNGs
    for info in infos:
        packed = zipfile.ZIP_STORED if info.filename.endswith(".png") else zipfile.ZIP_DEFLATED
        assert info.compress_type == packed, info.filename
        assert info.external_attr >> 16 == 0o644, info.filename


def test_project_json_is_indented_utf8_text(tmp_path: Path) -> None:
    path = tmp_path / "face.wrinkle"
    save_project(small_project(), path)
    with zipfile.ZipFile(path) as archive:
        raw = archive.read("project.json")
    assert raw.startswith(b'{\n "format": "wrinkle-studio-project",\n')
    assert "Stirn für".encode() in raw and b"\\u00fc" not in raw
    doc = json.loads(raw.decode("utf-8"))
    assert doc["wdv"]["scale_free"] is True
    again = load_project(path)
    assert again.influence.areas[0].name == "Stirn für"
    assert np.allclose(
        again.influence.areas[0].mask, small_project().influence.areas[0].mask, atol=1 / 65535
    )


def test_the_previous_version_is_kept_as_a_backup(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "face.wrinkle"
    project = small_project()
    save_project(project, path)
    first = path.read_bytes()
    project.name = "second"
    save_project(project, path)
    assert backup_path(path) == tmp_path / "face.wrinkle.bak"
    assert backup_path(path).read_bytes() == first
    second = path.read_bytes()

    def no_links(*args: object) -> None:
        raise OSError("hard links not supported")

    monkeypatch.setattr(os, "link", no_links)  # a FAT or network drive: copied instead
    project.name = "third"
    save_project(project, path)
    assert backup_path(path).read_bytes() == second
    assert not list(tmp_path.glob(".*staging"))
    project.name = "fourth"
    save_project(project, path, backup=False)
    assert backup_path(path).read_bytes() == second  # no backup asked for: the old one stays
