"""What the glTF export gives other viewers: the tangent frame (NORMAL, TANGENT and their
morph-target deltas) and the timeline as a morph-weight animation, and how both come back."""

from __future__ import annotations

import json
import struct
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from studio.core.animation.timeline import Key, sequence_all_poses
from studio.core.files.errors import MeshError
from studio.core.formats.gltf.codec import _Gltf, load_gltf, save_gltf
from studio.core.mesh.geometry import DeformCache
from studio.core.sample.synthetic import make_test_face

pytestmark = pytest.mark.core


@pytest.fixture
def small():
    face = make_test_face(561, texture_size=64, mask_size=32)
    face.timeline = sequence_all_poses([p.name for p in face.poses])
    # a constant key at a fractional frame: exact at frames and keys all the same
    face.timeline.tracks[0].keys.append(Key(face.timeline.end - 10.5, 0.7, "constant"))
    face.timeline.tracks[0].sort()
    return face


def rewrite_glb(path: Path, change: Callable[[dict], None]) -> None:
    """Edit a GLB's JSON in place (as another tool re-exporting it might)."""
    data = path.read_bytes()
    n = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + n])
    change(doc)
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + n:]
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 20 + len(text) + len(rest))
                     + struct.pack("<II", len(text), 0x4E4F534A) + text + rest)


@pytest.mark.parametrize("frame", ["mikktspace", "thesis"])
def test_normal_and_tangent_are_written_in_the_project_s_frame_and_come_back(small, tmp_path,
                                                                             frame):
    small.view["view"] = {"tangent_frame": frame}
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    g = _Gltf(path)
    prim = g.doc["meshes"][0]["primitives"][0]
    mesh = small.mesh
    cache = DeformCache(mesh, frame)
    rest = cache.update(mesh.rest).copy()
    tangent = g.accessor(prim["attributes"]["TANGENT"])
    np.testing.assert_array_equal(tangent, rest[:, 6:10])
    assert set(np.unique(tangent[:, 3])) <= {-1.0, 1.0}
    np.testing.assert_array_equal(g.accessor(prim["attributes"]["NORMAL"]), rest[:, 3:6])
    for pose, target in zip(small.poses, prim["targets"], strict=True):  # the posed frame
        posed = cache.update(pose.positions)
        np.testing.assert_allclose(g.accessor(target["NORMAL"]) + rest[:, 3:6],
                                   posed[:, 3:6], atol=1e-6)
        np.testing.assert_allclose(g.accessor(target["TANGENT"]) + rest[:, 6:9],
                                   posed[:, 6:9], atol=1e-6)
    assert load_gltf(path).view["view"]["tangent_frame"] == frame


def test_the_frame_argument_overrides_the_project_s(small, tmp_path):
    save_gltf(small, tmp_path / "face.glb", tangent_frame="thesis")
    g = _Gltf(tmp_path / "face.glb")
    tangent = g.accessor(g.doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"])
    np.testing.assert_array_equal(tangent, DeformCache(small.mesh, "thesis").update(
        small.mesh.rest)[:, 6:10])


def test_the_timeline_is_a_weights_animation_sampled_at_every_frame_and_key(small, tmp_path):
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    g = _Gltf(path)
    (animation,) = g.doc["animations"]
    (channel,) = animation["channels"]
    assert channel["target"] == {"node": 0, "path": "weights"}
    sampler = animation["samplers"][channel["sampler"]]
    assert sampler["interpolation"] == "LINEAR"
    timeline, names = small.timeline, [p.name for p in small.poses]
    frames = g.accessor(sampler["input"]).ravel() * timeline.fps + timeline.start
    expected = np.union1d(np.arange(timeline.start, timeline.end + 1),
                          [k.frame for t in timeline.tracks for k in t.keys])
    np.testing.assert_allclose(frames, expected, atol=1e-4)
    weights = g.accessor(sampler["output"]).reshape(len(frames), len(names))
    for j, name in enumerate(names):
        np.testing.assert_allclose(weights[:, j], timeline.track(name).values_at(expected),
                                   atol=1e-6)
    # technique 1's activations per area in the animation's extras, on the same times
    studio = animation["extras"]["wrinkleStudio"]
    assert studio["activations"]["input"] == sampler["input"]
    areas = studio["activations"]["areas"]
    assert [a["name"] for a in areas] == [a.name for a in small.influence.areas]
    values = np.array([a["values"] for a in areas]).T
    for i in (0, len(expected) // 3, len(expected) - 1):
        np.testing.assert_allclose(values[i], small.influence.activations(
            timeline.weights_at(expected[i])), atol=1e-6)


def test_the_timeline_comes_back_exactly_and_from_the_animation_alone(small, tmp_path):
    """With the studio's extras the keys come back as they were; without them (another tool
    re-exported the file) the animation gives a timeline that plays the same weights at every
    frame, within float32."""
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    assert load_gltf(path).timeline.to_dict() == small.timeline.to_dict()
    rewrite_glb(path, lambda doc: doc["extras"]["wrinkleStudio"].pop("timeline"))
    back = load_gltf(path).timeline
    timeline = small.timeline
    assert (back.fps, back.start, back.end) == (timeline.fps, timeline.start, timeline.end)
    for frame in range(timeline.start, timeline.end + 1):
        got, want = back.weights_at(frame), timeline.weights_at(frame)
        assert got.keys() == want.keys()
        np.testing.assert_allclose(list(got.values()), list(want.values()), atol=1e-6)


def test_a_step_animation_imports_as_held_keys(small, tmp_path):
    path = tmp_path / "face.glb"
    save_gltf(small, path)

    def step(doc: dict) -> None:
        doc["extras"]["wrinkleStudio"].pop("timeline")
        doc["animations"][0]["samplers"][0]["interpolation"] = "STEP"

    rewrite_glb(path, step)
    track = load_gltf(path).timeline.tracks[0]
    assert {k.interpolation for k in track.keys} == {"constant"}
    assert track.value_at(track.keys[5].frame + 0.9) == pytest.approx(track.keys[5].value)


def test_no_animation_without_keys_or_poses(small, tmp_path):
    small.timeline.tracks.clear()
    save_gltf(small, tmp_path / "keyless.glb")
    assert "animations" not in _Gltf(tmp_path / "keyless.glb").doc


def to_old_layout(doc: dict) -> None:
    """The studio's VEC3 attributes as the scalars files held before them (``_WELD``,
    ``_WRINKLE_LEN_<n>``, ``_WRINKLE_CONE_<n>`` where painted, ``_NOT_FACE`` where marked),
    each a column of the VEC3's buffer view read with a stride: no byte of the binary moves."""
    attrs = doc["meshes"][0]["primitives"][0]["attributes"]

    def column(name: str, k: int) -> int:
        acc = doc["accessors"][attrs[name]]
        doc["bufferViews"][acc["bufferView"]]["byteStride"] = 12
        doc["accessors"].append({**acc, "type": "SCALAR", "byteOffset": 4 * k})
        return len(doc["accessors"]) - 1

    data = "_WELD_NOTFACE_TILE"
    attrs["_WELD"] = column(data, 0)
    attrs["_NOT_FACE"] = column(data, 1)
    del attrs[data]
    for n in range(len(doc["extras"]["wrinkleStudio"]["wdv"]["areas"])):
        sizes = f"_WRINKLE_LEN_CONE_{n}"
        attrs[f"_WRINKLE_LEN_{n}"] = column(sizes, 0)
        if n == 1:  # the painted one
            attrs[f"_WRINKLE_CONE_{n}"] = column(sizes, 1)
        del attrs[sizes]


def test_a_file_of_the_older_scalar_layout_opens_as_it_was(small, tmp_path):
    small.not_face = np.zeros(small.mesh.n_welded, bool)
    small.not_face[::7] = True
    small.wdv.areas[1].cone_angles_deg = np.linspace(0, 30, small.mesh.n_welded)
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    new = load_gltf(path)
    rewrite_glb(path, to_old_layout)
    attrs = _Gltf(path).doc["meshes"][0]["primitives"][0]["attributes"]
    assert "_WELD" in attrs and "_WELD_NOTFACE_TILE" not in attrs
    old = load_gltf(path)
    np.testing.assert_array_equal(old.mesh.weld, small.mesh.weld)
    for back in (new, old):
        np.testing.assert_array_equal(back.not_face, small.not_face)
        for got, want in zip(back.wdv.areas, small.wdv.areas, strict=True):
            np.testing.assert_array_equal(got.directions, want.directions)
            np.testing.assert_array_equal(got.lengths, want.lengths)
            if want.cone_angles_deg is None:
                assert got.cone_angles_deg is None
            else:
                np.testing.assert_allclose(got.cone_angles_deg, want.cone_angles_deg)


def test_a_wrinkled_map_named_in_the_material_s_extras_survives_renumbered_textures(small,
                                                                                     tmp_path):
    """Another tool copies the skin's extras as they were and renumbers the textures; with
    neither the studio's extras nor its carried set-up left, the material's wrinkled map is
    found by its image's name, not by the stale index."""
    path = tmp_path / "face.glb"
    save_gltf(small, path)

    def foreign(doc: dict) -> None:
        del doc["extras"]
        prim = doc["meshes"][0]["primitives"][0]
        for name in [a for a in prim["attributes"] if a.startswith("_") or a == "TEXCOORD_1"]:
            del prim["attributes"][name]
        skin = doc["materials"][0]
        skin["normalTexture"] = {"index": 0}  # a map with no set-up in it
        skin["extras"]["wrinkleNormalTexture"]["index"] = 0  # renumbered: now the diffuse

    rewrite_glb(path, foreign)
    back = load_gltf(path)
    assert back.influence.areas == []  # read as another tool's file
    first = small.textures.wrinkle_map_names[0]
    np.testing.assert_array_equal(back.textures.normal_wrinkled,
                                  small.textures.wrinkle_maps[first])


def neutral_png(path: Path) -> tuple[bytes, int]:
    """The neutral normal map's PNG bytes in a GLB and where they start in the file."""
    g = _Gltf(path)
    view = g.doc["bufferViews"][g.doc["images"][1]["bufferView"]]
    data = path.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    start = 20 + json_length + 8 + view.get("byteOffset", 0)
    return data[start:start + view["byteLength"]], start


def test_a_damaged_or_swollen_set_up_chunk_is_refused_by_name(small, tmp_path, monkeypatch):
    path = tmp_path / "face.glb"
    save_gltf(small, path)
    rewrite_glb(path, lambda doc: doc.pop("extras"))  # as after Blender: the chunk is read
    assert load_gltf(path).influence.links == small.influence.links
    png, start = neutral_png(path)
    at = png.index(b"wrSt") + 4
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_IMAGE_BYTES", "1000")
    with pytest.raises(MeshError, match=r"set-up in the neutral normal map is damaged.*inflates"):
        load_gltf(path)
    monkeypatch.delenv("WRINKLE_STUDIO_MAX_IMAGE_BYTES")
    data = bytearray(path.read_bytes())
    data[start + at + 10] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(MeshError, match=r"damaged .*checksum"):
        load_gltf(path)


def test_the_set_up_chunk_leaves_the_image_as_it_was_for_png_readers():
    """The carried set-up is an ancillary chunk: PIL and the studio's own PNG reader decode the
    same pixels with it as without, and it gives back exactly what went in."""
    import io

    from PIL import Image

    from studio.core.files.png import decode_png, encode_png
    from studio.core.formats.gltf.carry import find_setup, with_setup

    image = (np.arange(4 * 5 * 3) % 256).astype(np.uint8).reshape(4, 5, 3)
    plain = encode_png(image)
    arrays = {"not_face": np.array([True, False, True]),
              "wdv0.directions": np.arange(9, dtype=np.float32).reshape(3, 3)}
    carried = with_setup(plain, {"name": "face", "links": {"smile": {"cheeks": 0.5}}}, arrays)
    assert find_setup(plain) is None
    extras, back = find_setup(carried)
    assert extras == {"name": "face", "links": {"smile": {"cheeks": 0.5}}}
    assert list(back) == list(arrays)
    np.testing.assert_array_equal(back["not_face"], [1, 0, 1])
    np.testing.assert_array_equal(back["wdv0.directions"], arrays["wdv0.directions"])
    np.testing.assert_array_equal(decode_png(carried), image)
    with Image.open(io.BytesIO(carried)) as pil:
        np.testing.assert_array_equal(np.asarray(pil), image)
