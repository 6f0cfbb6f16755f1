"""The .wrinkle project file: exact round trips, atomic saves, and refusal of every bad input.

Each corrupt input must give a ProjectError that names the file; nothing else may escape."""

from __future__ import annotations

import errno
import io
import json
import os
import struct
import time
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import Key, Timeline, Track
from studio.core.files import png
from studio.core.files.errors import ProjectError
from studio.core.files.png import PngError, decode_png, encode_png, read_png
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project import migrations as project_migrations
from studio.core.project import reader as project_reader
from studio.core.project import writer as project_writer
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.project.schema import FORMAT_VERSION
from studio.core.project.writer import save_project
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.textures import FaceTextures
from studio.core.wrinkles.wdv import WdvArea, WdvSetup

pytestmark = pytest.mark.core

MASK_H, MASK_W = 48, 64


# --------------------------------------------------------------------------- fixtures


def make_project(seed: int = 0) -> Project:
    """Five welded positions, six render vertices: vertex 2 is split along a UV seam."""
    rng = np.random.default_rng(seed)
    rest = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [1.5, 1, 0.1], [1, 2, 0.2]], np.float32)
    triangles = np.array([[0, 1, 2], [1, 3, 5], [5, 3, 4]], np.int32)
    uvs = np.array([[0, 0], [0.5, 0], [0.25, 0.5], [0.75, 0.5], [0.5, 1], [0.9, 0.5]], np.float32)
    weld = np.array([0, 1, 2, 3, 4, 2], np.int32)
    mesh = FaceMesh(rest, triangles, uvs, weld, source="face.obj")
    smile = KeyPose("smile", rest + rng.normal(0, 0.05, rest.shape).astype(np.float32))
    frown = KeyPose("frown", rest - np.float32(0.02))
    textures = FaceTextures(
        diffuse=rng.integers(0, 256, (40, 30, 3), dtype=np.uint8),
        normal_neutral=np.broadcast_to(np.array([128, 128, 255], np.uint8), (16, 16, 3)),
        normal_wrinkled=rng.integers(0, 65536, (32, 24, 3), dtype=np.uint16))
    masks = [rng.random((MASK_H, MASK_W), dtype=np.float32) for _ in range(3)]
    masks[1][:, :10] = 0.0
    masks[2][...] = 1.0
    influence = InfluenceSetup(
        [InfluenceArea("forehead right", masks[0], (250, 10, 20), 0.25, True),
         InfluenceArea("cheek/left", masks[1], (0, 200, 0), 0.0, False),
         InfluenceArea("brow", masks[2])],
        {"smile": {"cheek/left": 0.8, "forehead right": 0.5}, "frown": {"brow": 1.0}})
    moving = np.array([1, 3, 4])
    wdv = WdvSetup([
        WdvArea("crow's feet", "smile", *_wdv(rest, smile.positions, moving), (0, 170, 255), 25.0),
        WdvArea("brow", "frown", *_wdv(rest, frown.positions, np.arange(5)), enabled=False),
    ], expression_factor=1.5, scale_free=False)
    view = {"camera": {"yaw": 10.5, "pitch": -3, "distance": 2.25}, "wireframe": True,
            "background": [0.1, 0.2, 0.3], "label": "Olá ☺"}
    timeline = Timeline([Track("smile", [Key(0, 0.0), Key(12, 1.0, "linear"), Key(30, 0.0)]),
                         Track("frown", [Key(6.5, 0.25, "constant")])], fps=30.0, end=48)
    return Project("Test face", mesh, [smile, frown], textures, influence=influence, wdv=wdv,
                   timeline=timeline, view=view)


def _wdv(rest: np.ndarray, target: np.ndarray, selected: np.ndarray) -> tuple[np.ndarray, ...]:
    delta = target - rest
    length = np.linalg.norm(delta, axis=1)
    use = np.isin(np.arange(len(rest)), selected)
    directions = np.where(use[:, None], delta / length[:, None], 0).astype(np.float32)
    return directions, np.where(use, length, 0).astype(np.float32)


@pytest.fixture
def project() -> Project:
    return make_project()


@pytest.fixture
def saved(tmp_path: Path, project: Project) -> Path:
    path = tmp_path / "face.wrinkle"
    save_project(project, path)
    return path


def members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as archive:
        return {name: archive.read(name) for name in archive.namelist()}


def write_members(path: Path, content: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in content.items():
            archive.writestr(name, data)
    return path


def rewrite(src: Path, dst: Path, **changes: Any) -> Path:
    """Copy of ``src`` with members replaced (bytes), dropped (None) or project.json edited."""
    content = members(src)
    edit = changes.pop("doc", None)
    if edit is not None:
        doc = json.loads(content["project.json"])
        edit(doc)
        content["project.json"] = json.dumps(doc).encode()
    for name, data in changes.pop("files", {}).items():
        if data is None:
            del content[name]
        else:
            content[name] = data
    assert not changes
    return write_members(dst, content)


def npy(array: np.ndarray, **kwargs: Any) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array, **kwargs)
    return buffer.getvalue()


def assert_loads_or_refuses(path: Path) -> None:
    try:
        load_project(path)
    except ProjectError as exc:
        assert str(path) in str(exc)


# --------------------------------------------------------------------------- round trip


def test_round_trip_keeps_every_array_and_setting(saved: Path, project: Project) -> None:
    loaded = load_project(saved)
    assert loaded.name == project.name
    for key in ("rest", "triangles", "uvs", "weld"):
        a, b = getattr(project.mesh, key), getattr(loaded.mesh, key)
        assert b.dtype == a.dtype and np.array_equal(a, b), key
    assert loaded.mesh.source == "face.obj"
    assert [p.name for p in loaded.poses] == ["smile", "frown"]
    for a, b in zip(project.poses, loaded.poses, strict=True):
        assert b.positions.dtype == np.float32 and np.array_equal(a.positions, b.positions)
    for key in ("diffuse", "normal_neutral", "normal_wrinkled"):
        a, b = getattr(project.textures, key), getattr(loaded.textures, key)
        assert b.dtype == a.dtype and np.array_equal(a, b), key
    assert loaded.textures.normal_wrinkled.dtype == np.uint16
    assert len(loaded.influence.areas) == 3
    for a, b in zip(project.influence.areas, loaded.influence.areas, strict=True):
        assert (b.name, b.colour, b.activation, b.visible) == \
            (a.name, a.colour, a.activation, a.visible)
        assert b.mask.dtype == np.float32 and b.mask.shape == (MASK_H, MASK_W)
        assert np.abs(b.mask - a.mask).max() <= 1 / 65535
    assert loaded.influence.areas[1].mask[:, :10].max() == 0.0
    assert loaded.influence.areas[2].mask.min() == 1.0
    assert loaded.influence.links == project.influence.links
    assert (loaded.wdv.expression_factor, loaded.wdv.scale_free) == (1.5, False)
    for a, b in zip(project.wdv.areas, loaded.wdv.areas, strict=True):
        assert (b.name, b.pose, b.colour, b.cone_angle_deg, b.enabled) == \
            (a.name, a.pose, a.colour, a.cone_angle_deg, a.enabled)
        assert b.directions.dtype == np.float32 and np.array_equal(a.directions, b.directions)
        assert b.lengths.dtype == np.float32 and np.array_equal(a.lengths, b.lengths)
    assert loaded.view == project.view
    assert isinstance(loaded.timeline, Timeline)
    assert loaded.timeline.to_dict() == project.timeline.to_dict()
    assert loaded.timeline.weights_at(9.0) == project.timeline.weights_at(9.0)
    assert loaded.extra == {}


def with_beyond_thesis_fields(project: Project) -> Project:
    """Two wrinkled maps named by areas, painted cone angles and not-face vertices (format 2)."""
    smile_lines = np.full((20, 20, 3), (140, 110, 250), np.uint8)
    project.textures.set_wrinkle_map("smile lines", smile_lines)
    project.influence.areas[1].wrinkle_map = "smile lines"
    project.wdv.areas[0].wrinkle_map = "smile lines"
    project.wdv.areas[0].cone_angles_deg = np.array([0, 5, 0, 12.5, 90], np.float32)
    project.not_face = np.array([False, False, True, False, True])
    return project


def test_several_wrinkled_maps_cones_and_not_face_round_trip(tmp_path: Path,
                                                            project: Project) -> None:
    with_beyond_thesis_fields(project)
    save_project(project, tmp_path / "maps.wrinkle")
    loaded = load_project(tmp_path / "maps.wrinkle")
    assert loaded.textures.wrinkle_map_names == ["wrinkles", "smile lines"]
    for name, image in project.textures.wrinkle_maps.items():
        assert np.array_equal(loaded.textures.wrinkle_maps[name], image)
    assert [a.wrinkle_map for a in loaded.influence.areas] == ["", "smile lines", ""]
    assert [a.wrinkle_map for a in loaded.wdv.areas] == ["smile lines", ""]
    np.testing.assert_array_equal(loaded.wdv.areas[0].cone_angles_deg, [0, 5, 0, 12.5, 90])
    assert loaded.wdv.areas[1].cone_angles_deg is None
    np.testing.assert_array_equal(loaded.not_face, [False, False, True, False, True])


def test_a_version_1_file_loads_with_one_map_and_no_flags(tmp_path: Path, saved: Path) -> None:
    def as_version_1(doc: dict) -> None:
        doc["version"] = 1
        del doc["wrinkle_maps"]
        for area in doc["influence"]["areas"] + doc["wdv"]["areas"]:
            del area["wrinkle_map"]

    loaded = load_project(rewrite(saved, tmp_path / "v1.wrinkle", doc=as_version_1))
    assert loaded.textures.wrinkle_map_names == ["wrinkles"]
    assert loaded.not_face is None and loaded.wdv.areas[0].cone_angles_deg is None


def test_an_area_naming_a_missing_wrinkled_map_is_refused(tmp_path: Path,
                                                         project: Project) -> None:
    project.influence.areas[0].wrinkle_map = "gone"
    with pytest.raises(ProjectError, match="wrinkled map 'gone'"):
        save_project(project, tmp_path / "bad.wrinkle")


def test_a_second_round_trip_is_exact(tmp_path: Path, saved: Path) -> None:
    first = load_project(saved)
    save_project(first, tmp_path / "again.wrinkle")
    second = load_project(tmp_path / "again.wrinkle")
    for a, b in zip(first.influence.areas, second.influence.areas, strict=True):
        assert np.array_equal(a.mask, b.mask)
    assert members(saved).keys() == members(tmp_path / "again.wrinkle").keys()


def test_the_file_is_a_zip_of_ordinary_pngs_and_npy_arrays(saved: Path,
                                                           project: Project) -> None:
    content = members(saved)
    assert next(iter(content)) == "project.json"
    assert set(content) == {
        "project.json", "mesh/rest.npy", "mesh/triangles.npy", "mesh/uvs.npy", "mesh/weld.npy",
        "poses/00.npy", "poses/01.npy", "textures/diffuse.png", "textures/normal_neutral.png",
        "textures/normal_wrinkled.png", "masks/00_forehead_right.png", "masks/01_cheek_left.png",
        "masks/02_brow.png", "wdv/00_directions.npy", "wdv/00_lengths.npy",
        "wdv/01_directions.npy", "wdv/01_lengths.npy"}
    doc = json.loads(content["project.json"])
    assert doc["format"] == "wrinkle-studio-project" and doc["version"] == FORMAT_VERSION
    assert doc["poses"] == ["smile", "frown"]
    assert doc["influence"]["areas"][0]["mask"] == "masks/00_forehead_right.png"
    assert doc["wdv"]["areas"][1]["pose"] == "frown"
    with zipfile.ZipFile(saved) as archive:
        assert archive.testzip() is None
        kinds = {i.filename: i.compress_type for i in archive.infolist()}
    assert kinds["mesh/rest.npy"] == zipfile.ZIP_DEFLATED
    assert np.array_equal(np.load(io.BytesIO(content["poses/01.npy"])),
                          project.poses[1].positions)
    # any image editor can open them: Pillow reads every PNG member
    diffuse = Image.open(io.BytesIO(content["textures/diffuse.png"]))
    assert diffuse.mode == "RGB" and np.array_equal(np.asarray(diffuse), project.textures.diffuse)
    wrinkled = Image.open(io.BytesIO(content["textures/normal_wrinkled.png"]))
    assert wrinkled.size == (24, 32)  # Pillow shows 16-bit RGB at 8 bits: the high bytes
    assert np.array_equal(np.asarray(wrinkled), project.textures.normal_wrinkled >> 8)
    for i, area in enumerate(project.influence.areas):
        name = next(n for n in content if n.startswith(f"masks/{i:02d}"))
        mask = Image.open(io.BytesIO(content[name]))
        assert mask.mode.startswith("I") and mask.size == (MASK_W, MASK_H)
        values = np.asarray(mask).astype(np.float64) / 65535
        assert np.abs(values - area.mask).max() <= 0.5 / 65535 + 1e-7


def test_unknown_top_level_keys_survive(tmp_path: Path, saved: Path) -> None:
    def add(doc: dict) -> None:
        doc["future_thing"] = [1, 2, {"a": None}]

    path = rewrite(saved, tmp_path / "extra.wrinkle", doc=add)
    loaded = load_project(path)
    assert loaded.extra == {"future_thing": [1, 2, {"a": None}]}
    save_project(loaded, tmp_path / "resaved.wrinkle")
    doc = json.loads(members(tmp_path / "resaved.wrinkle")["project.json"])
    assert doc["future_thing"] == [1, 2, {"a": None}]
    assert doc["timeline"] == loaded.timeline.to_dict()


def test_a_file_without_timeline_or_view_gets_empty_ones(tmp_path: Path, saved: Path) -> None:
    def drop(doc: dict) -> None:
        del doc["timeline"], doc["view"]

    loaded = load_project(rewrite(saved, tmp_path / "plain.wrinkle", doc=drop))
    assert loaded.timeline.tracks == [] and loaded.view == {}


def test_eight_bit_masks_from_an_image_editor_are_read(tmp_path: Path, saved: Path) -> None:
    grey = (np.arange(MASK_H * MASK_W) % 256).astype(np.uint8).reshape(MASK_H, MASK_W)
    buffer = io.BytesIO()
    Image.fromarray(grey).save(buffer, "PNG")
    path = rewrite(saved, tmp_path / "edited.wrinkle",
                   files={"masks/02_brow.png": buffer.getvalue()})
    mask = load_project(path).influence.areas[2].mask
    assert mask.dtype == np.float32 and np.allclose(mask, grey / 255.0, atol=1e-7)


def test_older_files_are_migrated(monkeypatch: pytest.MonkeyPatch, saved: Path) -> None:
    def upgrade(doc: dict) -> dict:
        return {**doc, "name": doc["name"] + " (upgraded)"}

    monkeypatch.setattr(project_migrations, "FORMAT_VERSION", FORMAT_VERSION + 1)
    monkeypatch.setattr(project_migrations, "MIGRATIONS", {FORMAT_VERSION: upgrade})
    assert load_project(saved).name == "Test face (upgraded)"
    monkeypatch.setattr(project_migrations, "MIGRATIONS", {})
    with pytest.raises(ProjectError, match="no longer supported"):
        load_project(saved)


# --------------------------------------------------------------------------- atomic saving


def test_saving_replaces_the_old_file(tmp_path: Path, saved: Path, project: Project) -> None:
    project.name = "Renamed"
    save_project(project, saved)
    assert load_project(saved).name == "Renamed"
    assert sorted(os.listdir(tmp_path)) == ["face.wrinkle", "face.wrinkle.bak"]  # no temp files


def test_a_failed_replace_leaves_the_old_file(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                              saved: Path, project: Project) -> None:
    before = saved.read_bytes()

    def full(*_: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(project_writer.os, "replace", full)
    project.name = "Changed"
    with pytest.raises(ProjectError, match="disk is full") as info:
        save_project(project, saved)
    assert str(saved) in str(info.value)
    assert saved.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["face.wrinkle"]


def test_a_failure_while_writing_leaves_the_old_file(monkeypatch: pytest.MonkeyPatch,
                                                     tmp_path: Path, saved: Path,
                                                     project: Project) -> None:
    before = saved.read_bytes()
    calls = []

    def failing_npy(array: np.ndarray) -> bytes:
        calls.append(1)
        if len(calls) == 3:
            raise OSError(errno.EDQUOT, "Disk quota exceeded")
        return npy(array)

    monkeypatch.setattr(project_writer, "_npy", failing_npy)
    with pytest.raises(ProjectError, match="quota"):
        save_project(project, saved)
    assert saved.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["face.wrinkle"]


def test_a_failed_fsync_or_a_bug_leaves_no_temp_file(monkeypatch: pytest.MonkeyPatch,
                                                     tmp_path: Path, saved: Path,
                                                     project: Project) -> None:
    before = saved.read_bytes()

    def broken_fsync(_: int) -> None:
        raise OSError(errno.EIO, "Input/output error")

    with monkeypatch.context() as m:
        m.setattr(project_writer.os, "fsync", broken_fsync)
        with pytest.raises(ProjectError, match="input/output"):
            save_project(project, saved)

    def bug(_: np.ndarray) -> bytes:
        raise RuntimeError("a bug")

    monkeypatch.setattr(project_writer, "_mask_png", bug)
    with pytest.raises(RuntimeError, match="a bug"):  # bugs are not dressed up as user errors
        save_project(project, saved)
    assert saved.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["face.wrinkle"]


def test_a_read_only_folder_gives_a_clear_error(tmp_path: Path, saved: Path,
                                                project: Project) -> None:
    before = saved.read_bytes()
    tmp_path.chmod(0o555)
    try:
        try:  # root (with CAP_DAC_OVERRIDE) writes anyway: nothing to test then
            (tmp_path / "probe").touch()
        except PermissionError:
            pass
        else:
            (tmp_path / "probe").unlink()
            pytest.skip("folder permissions do not stop this user")
        with pytest.raises(ProjectError, match="permission denied") as info:
            save_project(project, saved)
        assert str(saved) in str(info.value)
    finally:
        tmp_path.chmod(0o755)
    assert saved.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["face.wrinkle"]


def test_a_missing_folder_gives_a_clear_error(tmp_path: Path, project: Project) -> None:
    target = tmp_path / "nowhere" / "face.wrinkle"
    with pytest.raises(ProjectError, match="does not exist") as info:
        save_project(project, target)
    assert str(target) in str(info.value)


def test_permissions_of_the_old_file_are_kept(tmp_path: Path, saved: Path,
                                              project: Project) -> None:
    saved.chmod(0o640)
    save_project(project, saved)
    assert saved.stat().st_mode & 0o777 == 0o640
    umask = os.umask(0o022)
    try:
        save_project(project, tmp_path / "new.wrinkle")
    finally:
        os.umask(umask)
    assert (tmp_path / "new.wrinkle").stat().st_mode & 0o777 == 0o644


def test_saving_through_a_symlink_updates_the_real_file(tmp_path: Path, saved: Path,
                                                        project: Project) -> None:
    link = tmp_path / "link.wrinkle"
    link.symlink_to(saved)
    project.name = "Via link"
    save_project(project, link)
    assert link.is_symlink() and load_project(saved).name == "Via link"


def test_a_project_load_would_refuse_is_not_saved(tmp_path: Path, project: Project) -> None:
    path = tmp_path / "bad.wrinkle"
    project.wdv.areas[0].pose = "yawn"
    with pytest.raises(ProjectError, match="'yawn', which does not exist") as info:
        save_project(project, path)
    assert str(path) in str(info.value) and not path.exists()
    project.wdv.areas[0].pose = "smile"
    project.view = {"bad": float("nan")}
    with pytest.raises(ProjectError, match="JSON"):
        save_project(project, path)
    project.view = {}
    project.influence.areas[0].mask = np.zeros((10, 10), np.float32)
    with pytest.raises(ProjectError, match="share one size"):
        save_project(project, path)
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------- refusing bad files


def _set(doc: dict, keys: str, value: Any) -> None:
    *parents, last = keys.split(".")
    for key in parents:
        doc = doc[int(key)] if isinstance(doc, list) else doc[key]
    if isinstance(doc, list):
        doc[int(last)] = value
    else:
        doc[last] = value


def _doc_edit(keys: str, value: Any) -> Callable[[dict], None]:
    return lambda doc: _set(doc, keys, value)


def _rgb_png() -> bytes:
    return encode_png(np.zeros((MASK_H, MASK_W, 3), np.uint8))


class Pickled:
    ran: list[int] = []  # noqa: RUF012

    def __reduce__(self) -> tuple:
        return (Pickled.ran.append, (1,))


BAD_EDITS: dict[str, tuple[dict[str, Any], str]] = {
    "missing member": ({"files": {"poses/01.npy": None}}, "missing 'poses/01.npy'"),
    "missing texture": ({"files": {"textures/diffuse.png": None}}, "missing"),
    "missing project.json": ({"files": {"project.json": None}}, "no project.json"),
    "bad json": ({"files": {"project.json": b"{not json"}}, "not valid JSON"),
    "json NaN": ({"files": {"project.json": b'{"format": NaN}'}}, "not valid JSON"),
    "json not an object": ({"files": {"project.json": b"[1, 2]"}}, "JSON object"),
    "json not utf-8": ({"files": {"project.json": b'{"name": "\xff"}'}}, "UTF-8"),
    "wrong format": ({"doc": _doc_edit("format", "something-else")}, "not a Wrinkle Studio"),
    "future version": ({"doc": _doc_edit("version", FORMAT_VERSION + 1)},
                       "newer Wrinkle Studio"),
    "version text": ({"doc": _doc_edit("version", "1")}, "invalid format version"),
    "traversal member": ({"files": {"../evil": b"x"}}, "unsafe name '../evil'"),
    "absolute member": ({"files": {"/etc/evil": b"x"}}, "unsafe name"),
    "drive member": ({"files": {"C:/evil": b"x"}}, "unsafe name"),
    "traversal reference": ({"doc": _doc_edit("influence.areas.0.mask", "../masks/x.png")},
                            "invalid member"),
    "wrong-shape pose": ({"files": {"poses/00.npy": npy(np.zeros((4, 3), np.float32))}},
                         r"shape \(4, 3\), expected \(5, 3\)"),
    "NaN positions": ({"files": {"poses/01.npy": npy(np.full((5, 3), np.nan, np.float32))}},
                      "non-finite"),
    "infinite rest": ({"files": {"mesh/rest.npy": npy(np.full((5, 3), np.inf, np.float32))}},
                      "non-finite"),
    "float64 rest": ({"files": {"mesh/rest.npy": npy(np.zeros((5, 3)))}}, "float64"),
    "triangle out of range": ({"files": {"mesh/triangles.npy": npy(np.full((3, 3), 9,
                                                                           np.int32))}},
                              "a face refers to a vertex that does not exist"),
    "weld out of range": ({"files": {"mesh/weld.npy": npy(np.full(6, 7, np.int32))}},
                          "does not exist"),
    "count mismatch": ({"doc": _doc_edit("mesh.welded_vertices", 6)}, "expected"),
    "count not a number": ({"doc": _doc_edit("mesh.triangles", "three")}, "whole number"),
    "pickled array": ({"files": {"wdv/00_lengths.npy": npy(np.array([Pickled()] * 5),
                                                            allow_pickle=True)}}, "object"),
    "not an npy": ({"files": {"wdv/01_directions.npy": b"\x93NUMPY garbage"}}, ".npy"),
    "truncated npy": ({"files": {"poses/00.npy": npy(np.zeros((5, 3), np.float32))[:-4]}},
                      "truncated"),
    "negative lengths": ({"files": {"wdv/00_lengths.npy": npy(np.full(5, -1, np.float32))}},
                         "negative"),
    "mask sizes differ": ({"files": {"masks/01_cheek_left.png":
                                     encode_png(np.zeros((10, 20), np.uint16))}},
                          "20×10 pixels, the others are 64×48"),
    "rgb mask": ({"files": {"masks/00_forehead_right.png": _rgb_png()}}, "greyscale"),
    "grey texture": ({"files": {"textures/normal_neutral.png":
                                encode_png(np.zeros((4, 4), np.uint8))}}, "RGB image"),
    "not a png": ({"files": {"textures/diffuse.png": b"GIF89a"}}, "not a PNG"),
    "damaged png": ({"files": {"masks/02_brow.png": encode_png(np.zeros((4, 4), np.uint16))
                               .replace(b"IEND", b"IEN!")}}, "cannot be read"),
    "unknown wdv pose": ({"doc": _doc_edit("wdv.areas.1.pose", "yawn")},
                         "'yawn', which does not exist"),
    "unknown link pose": ({"doc": _doc_edit("influence.links.yawn", {"brow": 1.0})},
                          "'yawn', which does not exist"),
    "unknown link area": ({"doc": _doc_edit("influence.links.smile", {"chin": 1.0})},
                          "'chin', which does not exist"),
    "neutral pose name": ({"doc": _doc_edit("poses.1", "neutral")}, "reserved"),
    "duplicate pose": ({"doc": _doc_edit("poses.1", "smile")}, "same name"),
    "duplicate area": ({"doc": _doc_edit("influence.areas.1.name", "brow")}, "two influence"),
    "bad colour": ({"doc": _doc_edit("wdv.areas.0.colour", [0, 300, 0])}, "0 to 255"),
    "bad bool": ({"doc": _doc_edit("influence.areas.0.visible", "yes")}, "true or false"),
    "cone angle": ({"doc": _doc_edit("wdv.areas.0.cone_angle_deg", 400)}, "180"),
    "huge number": ({"files": {"project.json": b'{"format": 1e999}'}}, "too large"),
    "timeline unknown pose": ({"doc": _doc_edit("timeline.tracks.0.pose", "yawn")},
                              "'yawn', which does not exist"),
    "timeline NaN frame": ({"doc": _doc_edit("timeline.tracks.0.keys.0.0", "nan")},
                           "finite number"),
    "timeline inf end": ({"doc": _doc_edit("timeline.end", "inf")}, "timeline is malformed"),
    "timeline bad key": ({"doc": _doc_edit("timeline.tracks.1.keys.0", [1, 2])},
                         "timeline is malformed"),
    "timeline bad mode": ({"doc": _doc_edit("timeline.tracks.1.keys.0.2", "bouncy")},
                          "timeline is malformed"),
    "timeline not object": ({"doc": _doc_edit("timeline", [])}, "timeline must be"),
    "view not an object": ({"doc": _doc_edit("view", [1])}, "view must be a JSON object"),
    "missing field": ({"doc": lambda d: d["wdv"].pop("scale_free")}, "lacks wdv.scale_free"),
}


@pytest.mark.parametrize("case", list(BAD_EDITS))
def test_damaged_projects_are_refused(tmp_path: Path, saved: Path, case: str) -> None:
    changes, message = BAD_EDITS[case]
    path = rewrite(saved, tmp_path / "bad.wrinkle", **changes)
    with pytest.raises(ProjectError, match=message) as info:
        load_project(path)
    assert str(path) in str(info.value)
    assert info.value.path == path
    assert Pickled.ran == []


def test_not_a_zip_truncated_or_empty(tmp_path: Path, saved: Path) -> None:
    cases = {"text.wrinkle": (b"hello, I am not a project", "not a zip archive"),
             "empty.wrinkle": (b"", "not a zip archive"),
             "half.wrinkle": (saved.read_bytes()[: saved.stat().st_size // 2], "truncated")}
    for name, (data, message) in cases.items():
        path = tmp_path / name
        path.write_bytes(data)
        with pytest.raises(ProjectError, match=message) as info:
            load_project(path)
        assert str(path) in str(info.value)
    with pytest.raises(ProjectError, match="does not exist"):
        load_project(tmp_path / "absent.wrinkle")
    with pytest.raises(ProjectError, match="folder"):
        load_project(tmp_path)


def _declare_size(data: bytes, member: str, size: int) -> bytes:
    """The archive with ``member``'s uncompressed size in the central directory set to ``size``."""
    pos = data.index(b"PK\x01\x02")
    while True:
        name_len = struct.unpack("<H", data[pos + 28:pos + 30])[0]
        if data[pos + 46:pos + 46 + name_len] == member.encode():
            return data[:pos + 24] + struct.pack("<I", size) + data[pos + 28:]
        pos = data.index(b"PK\x01\x02", pos + 4)


def test_a_fake_huge_declared_size_is_refused_before_reading(tmp_path: Path,
                                                             saved: Path) -> None:
    path = tmp_path / "bomb.wrinkle"
    path.write_bytes(_declare_size(saved.read_bytes(), "mesh/rest.npy", 0xF000_0000))
    with pytest.raises(ProjectError, match="limit for one member") as info:
        load_project(path)
    assert str(path) in str(info.value)


def test_the_total_size_is_capped(monkeypatch: pytest.MonkeyPatch, saved: Path) -> None:
    monkeypatch.setattr(project_reader, "MAX_TOTAL_BYTES", 1000)
    with pytest.raises(ProjectError, match="GiB limit"):
        load_project(saved)


def test_duplicate_and_encrypted_members_are_refused(tmp_path: Path, saved: Path) -> None:
    path = tmp_path / "dup.wrinkle"
    path.write_bytes(saved.read_bytes())
    with pytest.warns(UserWarning), zipfile.ZipFile(path, "a") as archive:
        archive.writestr("poses/00.npy", b"again")
    with pytest.raises(ProjectError, match=r"two members named 'poses/00\.npy'"):
        load_project(path)
    data = bytearray(saved.read_bytes())
    pos = data.index(b"PK\x01\x02")
    data[pos + 8] |= 1  # the encrypted flag in the central directory
    path.write_bytes(bytes(data))
    with pytest.raises(ProjectError, match="encrypted"):
        load_project(path)


# --------------------------------------------------------------------------- fuzzing


def test_random_byte_flips_load_or_raise_project_error(tmp_path: Path, saved: Path) -> None:
    rng = np.random.default_rng(1234)
    original = np.frombuffer(saved.read_bytes(), np.uint8)
    path = tmp_path / "flipped.wrinkle"
    outcomes = {"loaded": 0, "refused": 0}
    for _ in range(400):
        data = original.copy()
        where = rng.integers(0, len(data), rng.integers(1, 4))
        data[where] ^= rng.integers(1, 256, len(where)).astype(np.uint8)
        if rng.random() < 0.2:
            data = data[: rng.integers(0, len(data))]
        path.write_bytes(data.tobytes())
        try:
            load_project(path)
            outcomes["loaded"] += 1
        except ProjectError as exc:
            assert str(path) in str(exc)
            outcomes["refused"] += 1
    assert outcomes["refused"] > 0


def test_damaged_members_inside_a_valid_zip_are_refused(tmp_path: Path, saved: Path) -> None:
    """Corruption that the zip CRC cannot catch: bytes changed before zipping."""
    rng = np.random.default_rng(99)
    content = members(saved)
    path = tmp_path / "member.wrinkle"
    for name in content:
        for _ in range(12):
            data = np.frombuffer(content[name], np.uint8).copy()
            if rng.random() < 0.3:
                data = data[: rng.integers(0, len(data))]
            elif len(data):
                where = rng.integers(0, min(len(data), 160) if rng.random() < 0.6 else len(data),
                                     rng.integers(1, 4))
                data[where] = rng.integers(0, 256, len(where)).astype(np.uint8)
            write_members(path, {**content, name: data.tobytes()})
            assert_loads_or_refuses(path)


def _paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    found = [prefix] if prefix else []
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            found += _paths(item, (*prefix, i))
    return found


def test_every_json_field_replaced_with_junk_is_refused_or_accepted(tmp_path: Path,
                                                                    saved: Path) -> None:
    content = members(saved)
    doc = json.loads(content["project.json"])
    path = tmp_path / "junk.wrinkle"
    junk = [None, -1, 0, 10**30, 1.5, True, "", "x", "../x", [], [1, 2, 3], {}, {"a": 1}]
    for keys in _paths(doc):
        for value in [*junk, "DELETE"]:
            edited = json.loads(content["project.json"])
            parent = edited
            for key in keys[:-1]:
                parent = parent[key]
            if value == "DELETE":
                del parent[keys[-1]]
            else:
                parent[keys[-1]] = value
            write_members(path, {**content, "project.json": json.dumps(edited).encode()})
            assert_loads_or_refuses(path)


# --------------------------------------------------------------------------- the PNG codec


def _reference_png(image: np.ndarray, filters: list[int], interlace: bool = False) -> bytes:
    """A PNG written with the given row filters (cycled), to test every decoder path."""
    image = image if image.ndim == 3 else image[:, :, None]
    h, w, c = image.shape
    depth = 16 if image.dtype == np.uint16 else 8
    bpp = c * depth // 8
    colour = {1: 0, 2: 4, 3: 2, 4: 6}[c]
    big = image.astype(">u2") if depth == 16 else image
    passes = png._ADAM7 if interlace else ((0, 0, 1, 1),)
    out, row_index = [], 0
    for x0, y0, dx, dy in passes:
        sub = big[y0::dy, x0::dx]
        if sub.size == 0:
            continue
        rows = np.ascontiguousarray(sub).view(np.uint8).reshape(sub.shape[0], -1).astype(int)
        above = np.vstack([np.zeros((1, rows.shape[1]), int), rows[:-1]])
        left = np.hstack([np.zeros((rows.shape[0], bpp), int), rows[:, :-bpp]])
        corner = np.hstack([np.zeros((rows.shape[0], bpp), int), above[:, :-bpp]])
        p = left + above - corner
        pa, pb, pc = abs(p - left), abs(p - above), abs(p - corner)
        paeth = np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, above, corner))
        preds = [0 * rows, left, above, (left + above) // 2, paeth]
        kinds = np.array([filters[(row_index + i) % len(filters)] for i in range(len(rows))])
        row_index += len(rows)
        chosen = np.choose(kinds[:, None], preds)
        filtered = ((rows - chosen) % 256).astype(np.uint8)
        out.append(np.hstack([kinds[:, None].astype(np.uint8), filtered]).tobytes())
    header = struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, int(interlace))
    return b"".join((png.SIGNATURE, png._chunk(b"IHDR", header),
                     png._chunk(b"IDAT", zlib.compress(b"".join(out))), png._chunk(b"IEND", b"")))


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("shape", [(7, 5), (9, 6, 2), (11, 13, 3), (4, 3, 4), (1, 1, 3)])
def test_png_codec_is_exact(dtype: type, shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(len(shape) * 100 + shape[0])
    image = rng.integers(0, np.iinfo(dtype).max + 1, shape, dtype=dtype)
    for data in [encode_png(image), *(_reference_png(image, [f]) for f in range(5)),
                 _reference_png(image, [0, 1, 2, 3, 4]), _reference_png(image, [4, 2], True),
                 _reference_png(image, [1, 2, 0], True)]:
        decoded = decode_png(data)
        assert decoded.dtype == dtype and np.array_equal(decoded, image)
        assert np.array_equal(read_png(data), image)


def test_pillow_reads_our_16_bit_greyscale_exactly() -> None:
    image = np.arange(0, 65536, 256, dtype=np.uint16).reshape(16, 16)
    with Image.open(io.BytesIO(encode_png(image))) as img:
        assert np.array_equal(np.asarray(img).astype(np.uint16), image)


def test_png_problems_raise_png_error() -> None:
    good = encode_png(np.zeros((4, 4, 3), np.uint16))
    bad = {"signature": b"JUNK" + good[4:], "truncated": good[:-20],
           "header crc": good[:20] + b"\xff" + good[21:], "tiny": good[:10],
           "giant": good[:16] + struct.pack(">II", 1 << 20, 1 << 20) + good[24:]}
    for name, data in bad.items():
        with pytest.raises(PngError):
            decode_png(data)
        with pytest.raises(PngError):
            read_png(data)
        assert name
    with pytest.raises(PngError):
        encode_png(np.zeros((4, 4), np.float32))


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc (Linux)")
def test_a_reused_process_id_does_not_keep_a_dead_saves_staging_file() -> None:
    """Ids wrap around on a busy machine: a thread, or a process started after the file was
    made, is not the save that made it."""
    import threading

    from studio.core.files.processes import process_alive as _process_alive

    assert _process_alive(os.getpid(), time.time())  # this process, file made just now
    assert not _process_alive(os.getpid(), time.time() - 1e7)  # file older than the process
    seen: list[bool] = []
    thread = threading.Thread(
        target=lambda: seen.append(_process_alive(threading.get_native_id(), time.time())))
    thread.start()
    thread.join()
    assert seen == [False]


@pytest.mark.parametrize("name", ["../outside.png", "masks/../../outside.png", "/etc/passwd",
                                  "masks/./00.png", "C:/evil.png", "masks\\\\00.png"])
def test_a_member_whose_name_leads_outside_the_archive_is_refused(tmp_path: Path, saved: Path,
                                                                  name: str) -> None:
    """An archive the studio did not write: a member name escaping the archive (or absolute,
    or backslashed) is refused by name, before anything is read, as is project.json naming
    one for a mask."""
    bad = rewrite(saved, tmp_path / "bad.wrinkle", files={name: b"x"})
    with pytest.raises(ProjectError, match="unsafe name"):
        project_reader.load_project(bad)

    def point_a_mask_outside(doc: dict) -> None:
        doc["influence"]["areas"][0]["mask"] = name

    named = rewrite(saved, tmp_path / "named.wrinkle", doc=point_a_mask_outside)
    with pytest.raises(ProjectError, match="invalid member"):
        project_reader.load_project(named)
