"""Round trips through stock Blender (bpy) that survive a person's ordinary edits between the
import and the export: a shape key renamed, the images written as JPEG or WebP, the object moved,
turned and scaled without applying it. Each case is made by Blender itself
(scripts/blender_gltf.py --rename / --images / --move) from the studio's export, and read back
by the studio (``load_gltf`` and ``new --gltf``).

Before: the renamed key made ``new`` refuse the file naming the project it was about to write;
the JPEG images lost the whole set-up without a word; the transform was dropped silently."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.animation.timeline import sequence_all_poses
from studio.core.formats.gltf.codec import load_gltf, save_gltf
from studio.core.formats.gltf.renames import pose_renames
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face
from tests.test_blender_import import blender

RENAMED = ("brow_raise_left", "browRaise")
EDITS = {"rename": ("--rename", "=".join(RENAMED)), "jpeg": ("--images", "JPEG"),
         "webp": ("--images", "WEBP"), "move": ("--move",)}


def face() -> Project:
    project = make_test_face(561, texture_size=64, mask_size=64)
    project.timeline = sequence_all_poses([p.name for p in project.poses])
    return project


@pytest.fixture(scope="module")
def edited(tmp_path_factory) -> tuple[Project, dict[str, Path]]:
    """The studio's export as it reads back, and Blender's re-export after each edit."""
    folder = tmp_path_factory.mktemp("edits")
    save_gltf(face(), folder / "face.glb")
    files = {}
    for name, args in EDITS.items():
        files[name] = folder / f"{name}.glb"
        blender(folder / "face.glb", "--export", files[name], *args)
    return load_gltf(folder / "face.glb"), files


def new_project(path: Path, out: Path) -> tuple[int, str]:
    printed = io.StringIO()
    with redirect_stdout(printed):
        code = main(["new", "--gltf", str(path), "-o", str(out)])
    return code, printed.getvalue()


def test_a_renamed_shape_key_keeps_its_links_areas_and_track(edited, tmp_path):
    project, files = edited
    report: list[str] = []
    back = load_gltf(files["rename"], report=report)
    old, new = RENAMED
    assert [p.name for p in back.poses] == [new if p.name == old else p.name
                                            for p in project.poses]
    assert back.influence.links[new] == project.influence.links[old]
    assert old not in back.influence.links
    assert [a.pose for a in back.wdv.areas] == [a.pose for a in project.wdv.areas]
    assert [t.pose for t in back.timeline.tracks] == [new if t.pose == old else t.pose
                                                      for t in project.timeline.tracks]
    renames = [line for line in report if "renamed" in line]
    assert renames == [f"shape key '{new}' is the set-up's '{old}' (renamed since the export; "
                       "matched by its place among the shape keys)"]
    code, printed = new_project(files["rename"], tmp_path / "face.wrinkle")
    assert code == 0
    assert renames[0] in printed
    assert load_project(tmp_path / "face.wrinkle").influence.links[new] == \
        project.influence.links[old]


@pytest.mark.parametrize("kind", ["jpeg", "webp"])
def test_images_written_as_jpeg_or_webp_keep_what_survived_and_say_what_was_lost(edited, kind):
    """JPEG keeps every mask (lossy); Blender's WebP export writes the masks' materials without
    their 16-bit grey images, so the areas go too, and the line says so."""
    project, files = edited
    report: list[str] = []
    back = load_gltf(files[kind], report=report)
    np.testing.assert_array_equal(back.mesh.weld, project.mesh.weld)  # TEXCOORD_1's welding
    assert back.textures.wrinkle_map_names == project.textures.wrinkle_map_names
    assert back.influence.links == {} and back.wdv.areas == []
    lost = [line for line in report if "lost" in line]
    assert len(lost) == 1
    said = {"jpeg": ["as JPEG", "8 areas from their masks", "lost: the links, response curves "
                     "and technique-2 areas"],
            "webp": ["as WebP", "0 areas from their masks", "lost: the links, response curves, "
                     "8 areas (the other tool wrote their masks' materials without their "
                     "images) and technique-2 areas"]}[kind]
    for part in [*said, "the welding from TEXCOORD_1", "2 wrinkled maps", "Auto Setup"]:
        assert part in lost[0]
    if kind == "webp":
        assert back.influence.areas == []
        return
    assert [a.name for a in back.influence.areas] == [a.name for a in project.influence.areas]
    for got, want in zip(back.influence.areas, project.influence.areas, strict=True):
        assert np.abs(got.mask - want.mask).mean() < 0.02  # the re-encoded mask
        assert np.abs(got.mask - want.mask).max() < 0.25


def test_a_transform_left_unapplied_is_applied_to_the_face_and_said(edited, tmp_path):
    project, files = edited
    report: list[str] = []
    back = load_gltf(files["move"], report=report)
    # Blender's location (0.05, -0.02, 0.1), Z turn 0.3 and scale 1.5, in glTF's Y-up axes
    turn = 0.3
    rotation = np.array([[np.cos(turn), 0, np.sin(turn)], [0, 1, 0],
                         [-np.sin(turn), 0, np.cos(turn)]])
    move = np.array([0.05, 0.1, 0.02])

    def placed(points: np.ndarray) -> np.ndarray:
        return 1.5 * points.astype(np.float64) @ rotation.T + move

    np.testing.assert_allclose(back.mesh.rest, placed(project.mesh.rest), atol=1e-5)
    for got, want in zip(back.poses, project.poses, strict=True):
        np.testing.assert_allclose(got.positions, placed(want.positions), atol=1e-5)
    assert len(back.influence.areas) == len(project.influence.areas)  # the set-up kept
    assert ("the face was moved, turned or scaled in another tool without applying it: its "
            "node's transform is applied to the vertices and key poses") in report


@pytest.mark.core
def test_keys_match_by_name_then_by_place():
    setup = ["a", "b", "c"]
    assert pose_renames(setup, ["a", "b", "c"], {"a", "c"}) == {}
    assert pose_renames(setup, ["a", "B", "c"], {"b"}) == {"b": "B"}
    assert pose_renames(setup, ["c", "a", "b"], {"a"}) == {}  # reordered, not renamed
    # one key deleted, another renamed: the renamed one paired with the spare key
    assert pose_renames(setup, ["a", "C"], {"b", "c"}) == {"b": "C", "c": None}
    # a file written before the export listed its keys: a missing name is gone
    assert pose_renames(None, ["a", "x"], {"b"}) == {"b": None}
