"""glTF in and out: morph targets become key poses, a studio export imports back losslessly,
and the command line makes and exports projects."""

from __future__ import annotations

import base64
import json
import struct

import numpy as np
import pytest

from studio.cli import main
from studio.core.files.errors import StudioError
from studio.core.files.images import read_image
from studio.core.formats.gltf.codec import load_gltf, save_gltf
from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face

pytestmark = pytest.mark.core


@pytest.fixture(scope="module")
def small():
    return make_test_face(561, texture_size=64, mask_size=32)


def test_studio_glb_round_trips_everything(small, tmp_path):
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    back = load_gltf(path)
    assert back.name == small.name
    assert np.array_equal(back.mesh.weld, small.mesh.weld)
    assert np.array_equal(back.mesh.triangles, small.mesh.triangles)
    np.testing.assert_array_equal(back.mesh.rest, small.mesh.rest)
    np.testing.assert_allclose(back.mesh.uvs, small.mesh.uvs, atol=1e-7)
    assert [p.name for p in back.poses] == [p.name for p in small.poses]
    for a, b in zip(back.poses, small.poses, strict=True):
        np.testing.assert_allclose(a.positions, b.positions, atol=1e-6)
    for name in ("diffuse", "normal_neutral", "normal_wrinkled"):
        assert np.array_equal(getattr(back.textures, name), getattr(small.textures, name))
    assert [a.name for a in back.influence.areas] == [a.name for a in small.influence.areas]
    for a, b in zip(back.influence.areas, small.influence.areas, strict=True):
        assert np.abs(a.mask - b.mask).max() <= 1 / 65535 and a.colour == b.colour
    assert back.influence.links == small.influence.links
    for a, b in zip(back.wdv.areas, small.wdv.areas, strict=True):
        assert (a.name, a.pose, a.cone_angle_deg) == (b.name, b.pose, b.cone_angle_deg)
        assert np.array_equal(a.directions, b.directions)
        assert np.array_equal(a.lengths, b.lengths)
    assert back.timeline.to_dict() == small.timeline.to_dict()


def test_glb_keeps_several_wrinkled_maps_cones_and_not_face(small, tmp_path):
    face = make_test_face(561, texture_size=64, mask_size=32)
    assert len(face.textures.wrinkle_maps) == 2  # the sample reveals two maps
    cones = np.zeros(face.mesh.n_welded, np.float32)
    cones[::7] = 8.0
    face.wdv.areas[1].cone_angles_deg = cones
    face.not_face = np.arange(face.mesh.n_welded) % 5 == 0
    save_gltf(face, tmp_path / "face.glb")
    back = load_gltf(tmp_path / "face.glb")
    assert back.textures.wrinkle_map_names == face.textures.wrinkle_map_names
    for name, image in face.textures.wrinkle_maps.items():
        assert np.array_equal(back.textures.wrinkle_maps[name], image)
    assert [a.wrinkle_map for a in back.influence.areas] == \
        [a.wrinkle_map for a in face.influence.areas]
    assert [a.wrinkle_map for a in back.wdv.areas] == [a.wrinkle_map for a in face.wdv.areas]
    np.testing.assert_array_equal(back.wdv.areas[1].cone_angles_deg, cones)
    assert back.wdv.areas[0].cone_angles_deg is None
    np.testing.assert_array_equal(back.not_face, face.not_face)


def test_the_glb_is_valid_for_other_readers(small, tmp_path):
    import trimesh

    path = tmp_path / "face.glb"
    save_gltf(small, path)
    scene = trimesh.load(str(path), process=False)
    mesh = next(iter(scene.geometry.values()))
    assert len(mesh.faces) == small.mesh.n_triangles
    doc = json.loads(path.read_bytes()[20:20 + struct.unpack_from("<I", path.read_bytes(),
                                                                  12)[0]])
    attrs = doc["meshes"][0]["primitives"][0]["attributes"]
    assert {"_WRINKLE_DIR_0", "_WRINKLE_LEN_CONE_0", "POSITION", "TEXCOORD_0"} <= set(attrs)
    assert doc["meshes"][0]["extras"]["targetNames"] == [p.name for p in small.poses]


def handmade_gltf(path, target_names=("smile", "frown")):
    """Two triangles sharing an edge, with two morph targets, buffers as data URIs."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    uv = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], np.float32)
    idx = np.array([0, 1, 2, 1, 3, 2], np.uint16)
    smile = np.zeros_like(pos)
    smile[3] = [0, 0, 0.5]
    frown = np.zeros_like(pos)
    frown[0] = [0, -0.25, 0]
    chunks = [pos, uv, idx, smile, frown]
    blob, views = b"", []
    for c in chunks:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": c.nbytes})
        blob += c.tobytes() + b"\0" * (-c.nbytes % 4)
    acc = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0]},
           {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
           {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
           {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3"},
           {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3"}]
    doc = {"asset": {"version": "2.0"}, "accessors": acc, "bufferViews": views,
           "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                        + base64.b64encode(blob).decode()}],
           "meshes": [{"extras": {"targetNames": list(target_names)}, "primitives": [
               {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                "targets": [{"POSITION": 3}, {"POSITION": 4}]}]}]}
    path.write_text(json.dumps(doc))
    return path


def test_morph_targets_become_named_key_poses(tmp_path):
    project = load_gltf(handmade_gltf(tmp_path / "face.gltf"))
    assert [p.name for p in project.poses] == ["smile", "frown"]
    assert project.mesh.n_welded == 4 and project.mesh.n_triangles == 2
    np.testing.assert_allclose(project.poses[0].positions[3], [1, 1, 0.5])
    np.testing.assert_allclose(project.poses[1].positions[0], [0, -0.25, 0])
    np.testing.assert_allclose(project.mesh.uvs[2], [0, 0])  # glTF's v points down


@pytest.mark.parametrize(("damage", "needle"), [
    (lambda d: d[:30], "truncated"),
    (lambda d: b"glTF" + struct.pack("<II", 2, 2 ** 31) + d[12:], "truncated"),
    (lambda d: b"glTF" + struct.pack("<II", 7, len(d)) + d[12:], "not version 2"),
    (lambda d: b"{not json", "not a glTF"),
])
def test_damaged_files_give_one_clear_error(small, tmp_path, damage, needle):
    good = tmp_path / "good.glb"
    save_gltf(small, good)
    bad = tmp_path / "bad.glb"
    bad.write_bytes(damage(good.read_bytes()))
    with pytest.raises(StudioError) as info:
        load_gltf(bad)
    assert needle in str(info.value) and "bad.glb" in str(info.value)


def test_missing_uvs_are_made_and_sparse_accessors_are_named(tmp_path):
    path = handmade_gltf(tmp_path / "face.gltf")
    doc = json.loads(path.read_text())
    del doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]
    path.write_text(json.dumps(doc))
    report: list[str] = []
    load_gltf(path, report=report)  # UVs made by xatlas (issue #37), and said
    assert any("made them with xatlas" in line for line in report)
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 1
    doc["accessors"][3]["sparse"] = {"count": 1}
    path.write_text(json.dumps(doc))
    with pytest.raises(StudioError, match="sparse"):
        load_gltf(path)


def test_buffer_outside_the_folder_is_refused(tmp_path):
    path = handmade_gltf(tmp_path / "face.gltf")
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = "../../etc/passwd"
    path.write_text(json.dumps(doc))
    with pytest.raises(StudioError, match="outside"):
        load_gltf(path)


def test_new_from_gltf_then_render_and_export(small, tmp_path, capsys):
    glb = tmp_path / "face.glb"
    save_gltf(small, glb)
    project_path = tmp_path / "face.wrinkle"
    assert main(["new", "--gltf", str(glb), "-o", str(project_path)]) == 0
    project = load_project(project_path)
    assert [p.name for p in project.poses] == [p.name for p in small.poses]
    assert main(["render", str(project_path), "--technique", "t2", "--pose", "surprise",
                 "--size", "160x120", "-o", str(tmp_path / "r.png")]) == 0
    out = tmp_path / "engine"
    assert main(["export", str(project_path), "--folder", str(out)]) == 0
    links = json.loads((out / "wrinkles.json").read_text())
    assert links["pose_links"] == small.influence.links
    assert [a["name"] for a in links["areas"]] == [a.name for a in small.influence.areas]
    first = read_image(out / links["areas"][0]["mask"])
    assert first.dtype == np.uint16
    assert np.abs(first / 65535.0 - small.influence.areas[0].mask).max() <= 1 / 65535
    packed = read_image(out / "masks" / "packed_01.png")
    assert packed.shape[2] == 4  # areas 5..8 in R, G, B, A
    np.testing.assert_allclose(packed[:, :, 3] / 255.0, small.influence.areas[7].mask,
                               atol=1 / 255)
    assert (out / "shaders" / "face.frag").read_text().startswith("#version")
    assert load_gltf(out / "face.glb").mesh.n_welded == small.mesh.n_welded
    # exporting again into the same folder replaces its files, as an artist re-exporting expects
    (out / "wrinkles.json").write_text("{}")
    assert main(["export", str(project_path), "--folder", str(out)]) == 0
    assert json.loads((out / "wrinkles.json").read_text())["pose_links"] == small.influence.links
    # but a file where the folder should be is refused, untouched
    assert main(["export", str(project_path), "--folder", str(tmp_path / "r.png")]) == 2
    assert "not a folder" in capsys.readouterr().err


def test_new_with_a_bad_pose_argument_is_one_line(tmp_path, capsys):
    code = None
    with pytest.raises(SystemExit) as info:
        code = main(["new", "--mesh", "a.obj", "--pose", "nofile", "-o", str(tmp_path / "x")])
    assert code is None and info.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
