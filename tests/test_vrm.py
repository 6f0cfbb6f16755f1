"""A VRM avatar (``.vrm``), imported as a new user would: ``new --gltf avatar.vrm --auto``.

The avatar is built here the way Blender's VRM exporter writes one, in none of the studio's
conventions: VRM 0.x, facing −Z (Y up, metres), one face mesh holding the skin (with two hair
balls on its crown, in the same primitive), eye quads (a material of their own), morph targets
named by their maker (``brows_up``, ``angled_eyebrows``, ``smile``, ``blink_left``, ``ah``,
``squint_left``) beside a toggle (``HideHairBalls``, which shrinks the hair balls away); the VRM
extension's expressions bind them (joy, angry, a custom "Surprised", blink_l, a). A body and a
hair mesh without morph targets stand beside it. The same avatar as VRM 1.0 (``VRMC_vrm``,
facing +Z) maps its expressions the same way.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.project.reader import load_project
from studio.core.sample.mesh import EYE_X, EYE_Y, blob
from tests.gltf_avatar import GlbDoc, _box
from tests.production_head import _sphere, build_head
from tests.test_full_body import judge_renders

HEIGHT = 1.4  # metres: where the head stands
# morph target → the production head's poses it is made of ("blink" is made here)
TARGETS = {"brows_up": ("browInnerUp",), "angled_eyebrows": ("browDown_L", "browDown_R"),
           "smile": ("mouthSmile_L", "mouthSmile_R"), "blink_left": ("blink",),
           "ah": ("jawOpen",), "squint_left": ("eyeSquint_L",), "HideHairBalls": ()}
# VRM 0.x groups: (presetName, name, bound target)
GROUPS_0 = [("joy", "Joy", "smile"), ("angry", "Angry", "angled_eyebrows"),
            ("unknown", "Surprised", "brows_up"), ("blink_l", "Blink_L", "blink_left"),
            ("a", "A", "ah")]
# VRM 1.0 expressions: (preset or custom, name, bound target)
EXPRESSIONS_1 = [("preset", "happy", "smile"), ("preset", "angry", "angled_eyebrows"),
                 ("preset", "surprised", "brows_up"), ("preset", "blinkLeft", "blink_left"),
                 ("preset", "aa", "ah")]
JUDGED_0 = {"brow raise": {"Surprised": 1.0}, "frown": {"angry": 1.0}, "smile": {"happy": 1.0},
            "squint": {"squint_left": 1.0}}
BALLS = ((0.35, 0.92, -0.05), (-0.35, 0.92, -0.05))  # sample units: on the crown


def build_vrm(path: Path, version: str = "0.x", vertices: int = 2172,
              skin_colour: tuple[int, int, int] = (200, 150, 130)) -> Path:
    """The avatar (see the module's docstring) as a .vrm of that VRM version, its skin's
    texture of ``skin_colour``."""
    head = build_head("m", vertices=vertices, up="y")
    skin = head.parts[0]
    # VRM 0.x faces −Z: the sample's front (+z) turned half round about Y; VRM 1.0 faces +Z
    turn = np.diag([-1.0, 1.0, -1.0]) if version == "0.x" else np.eye(3)

    def world(points):
        return (np.asarray(points, float) @ turn.T) * 0.1 + [0.0, HEIGHT, 0.0]

    x, y = head.face_xy[:, 0], head.face_xy[:, 1]
    blink = skin.rest.copy()
    blink[:, 1] -= 0.05 * blob(x, y, EYE_X, EYE_Y + 0.05, 0.1, 0.04) * (skin.rest[:, 2] > 0.2)
    skin.poses["blink"] = blink
    balls = [_sphere(np.array(c), 0.06, 6, 8) for c in BALLS]
    ball_pos = np.concatenate([b[0] for b in balls])
    ball_tris = np.concatenate([balls[0][1], balls[1][1] + len(balls[0][0])])
    ball_centres = np.repeat(np.array(BALLS), [len(b[0]) for b in balls], axis=0)
    n_skin = len(skin.weld)
    positions = np.concatenate([world(skin.rest)[skin.weld], world(ball_pos)])
    uvs = np.concatenate([skin.uvs, np.concatenate([b[2] for b in balls]) * 0.05 + 0.9])
    tris = np.concatenate([skin.triangles, ball_tris + n_skin])
    eyes = []
    for side in (1.0, -1.0):
        cx = side * EYE_X
        eyes.append([[cx - 0.09, EYE_Y - 0.05, 0.56], [cx + 0.09, EYE_Y - 0.05, 0.56],
                     [cx + 0.09, EYE_Y + 0.05, 0.56], [cx - 0.09, EYE_Y + 0.05, 0.56]])
    eye_pos = world(np.concatenate(eyes))
    eye_tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    if version == "0.x":
        eye_tris = eye_tris[:, ::-1]  # still facing the avatar's front once turned
    eye_uvs = np.tile([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], (2, 1))

    d = GlbDoc()
    skin_mat = d.material("Face_00_SKIN", skin_colour)
    eye_mat = d.material("EyeIris_00_EYE", (60, 90, 160))
    cloth = d.material("Body_00_CLOTH", (40, 60, 90))
    skin_targets, eye_targets = [], []
    for name, poses in TARGETS.items():
        moved = skin.rest.copy()
        for pose in poses:
            moved += skin.poses[pose] - skin.rest
        delta = (world(moved) - world(skin.rest))[skin.weld]
        ball_delta = ((world(ball_centres) - world(ball_pos)) if name == "HideHairBalls"
                      else np.zeros_like(ball_pos))
        skin_targets.append({"POSITION": d.data(np.concatenate([delta, ball_delta])
                                                .astype(np.float32))})
        eye_targets.append({"POSITION": d.zeros(len(eye_pos))})

    def flip_v(uv):
        return np.column_stack([uv[:, 0], 1.0 - uv[:, 1]]).astype(np.float32)

    face = {"name": "Face", "extras": {"targetNames": list(TARGETS)}, "primitives": [
        {"attributes": {"POSITION": d.data(positions.astype(np.float32)),
                        "TEXCOORD_0": d.data(flip_v(uvs))},
         "indices": d.data(tris.astype(np.uint32).ravel()), "material": skin_mat,
         "targets": skin_targets},
        {"attributes": {"POSITION": d.data(eye_pos.astype(np.float32)),
                        "TEXCOORD_0": d.data(flip_v(eye_uvs))},
         "indices": d.data(eye_tris.astype(np.uint32).ravel()), "material": eye_mat,
         "targets": eye_targets}]}
    meshes = [face]
    for name, centre, size in (("Body", (0.0, 0.8, 0.0), (0.4, 1.0, 0.25)),
                               ("Hair", (0.0, HEIGHT + 0.08, 0.0), (0.2, 0.08, 0.22))):
        pos, box_tris, box_uv = _box(centre, size)
        meshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": d.data(pos.astype(np.float32)),
                           "TEXCOORD_0": d.data(box_uv.astype(np.float32))},
            "indices": d.data(box_tris.astype(np.uint16).ravel()), "material": cloth}]})
    d.doc["meshes"] = meshes
    d.doc["nodes"] = [{"name": "Face", "mesh": 0}, {"name": "Body", "mesh": 1},
                      {"name": "Hair", "mesh": 2}, {"name": "Root", "children": [0, 1, 2]}]
    d.doc["scenes"] = [{"nodes": [3]}]
    d.doc["scene"] = 0
    index = {name: k for k, name in enumerate(TARGETS)}
    if version == "0.x":
        groups = [{"name": name, "presetName": preset, "isBinary": False,
                   "binds": [{"mesh": 0, "index": index[target], "weight": 100}],
                   "materialValues": []} for preset, name, target in GROUPS_0]
        groups.append({"name": "Broken", "presetName": "unknown",  # a leftover bind
                       "binds": [{"mesh": 7, "index": 0, "weight": 100}]})
        d.doc["extensionsUsed"] = ["VRM"]
        d.doc["extensions"] = {"VRM": {"exporterVersion": "test", "specVersion": "0.0",
                                       "blendShapeMaster": {"blendShapeGroups": groups}}}
    else:
        expressions: dict = {"preset": {}, "custom": {}}
        for kind, name, target in EXPRESSIONS_1:
            expressions[kind][name] = {"morphTargetBinds": [
                {"node": 0, "index": index[target], "weight": 1.0}], "isBinary": False}
        d.doc["extensionsUsed"] = ["VRMC_vrm"]
        d.doc["extensions"] = {"VRMC_vrm": {"specVersion": "1.0", "expressions": expressions}}
    return d.write_glb(path)


def new_auto(folder: Path, version: str, *extra: str) -> tuple[object, str]:
    vrm = build_vrm(folder / f"avatar{version}.vrm", version)
    out = io.StringIO()
    target = folder / f"avatar{version}.wrinkle"
    with redirect_stdout(out):
        assert main(["new", "--gltf", str(vrm), "--auto", "-o", str(target), *extra]) == 0
    return load_project(target), out.getvalue()


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    return new_auto(tmp_path_factory.mktemp("vrm"), "0.x")


@pytest.mark.core
def test_the_expressions_become_named_poses_and_the_toggle_is_no_wrinkle(imported) -> None:
    project, out = imported
    names = [p.name for p in project.poses]
    assert names[:5] == ["happy", "angry", "Surprised", "blinkLeft", "aa"], names
    assert "squint_left" in names  # a morph no expression binds stays, under its own name
    assert "smile" not in names and "Broken" not in names
    assert "VRM 0.x: faces -Z, Y up; 5 expressions as key poses" in out
    assert "toggles, not set up as wrinkles: HideHairBalls" in out
    assert "HideHairBalls" not in {a.name for a in project.influence.areas}
    assert "HideHairBalls" not in {a.pose for a in project.wdv.areas}
    assert "left out (no morph targets): Body, Hair" in out
    # the hair balls and the eye quads are not skin
    centres = np.array(BALLS) * [-0.1, 0.1, -0.1] + [0.0, HEIGHT, 0.0]  # turned to face -Z
    near = np.linalg.norm(project.mesh.rest[:, None] - centres, axis=2).min(axis=1)
    balls = np.abs(near - 0.006) < 1e-4  # on a ball's surface
    assert balls.sum() > 60  # both balls, welded
    assert project.not_face[balls].all()


@pytest.mark.core
def test_vrm_0_faces_minus_z_and_1_0_faces_plus_z(imported, tmp_path) -> None:
    from studio.core.setup.face_frame import face_frame

    project, out = imported
    frame = face_frame(project)
    assert np.allclose(frame.up, (0, 1, 0)) and np.allclose(frame.front, (0, 0, -1))
    assert "front -Z (as given)" in out
    assert abs(frame.centre[1] - HEIGHT) < 0.05
    other, out1 = new_auto(tmp_path, "1.0")
    assert [p.name for p in other.poses][:5] == ["happy", "angry", "surprised", "blinkLeft", "aa"]
    assert np.allclose(face_frame(other).front, (0, 0, 1))
    assert "VRM 1.0: faces +Z" in out1


def test_brow_raise_frown_and_smile_show_from_the_front_and_not_on_the_eyes(imported
                                                                            ) -> None:
    judge_renders(imported[0], JUDGED_0)


@pytest.mark.core
@pytest.mark.parametrize("damage", [{"blendShapeMaster": {"blendShapeGroups": [5]}},
                                    {"blendShapeMaster": {"blendShapeGroups": [
                                        {"presetName": "joy", "binds": 7}]}}])
def test_a_damaged_vrm_extension_is_one_line_naming_the_file(tmp_path, capsys, damage) -> None:
    import json
    import struct

    path = build_vrm(tmp_path / "a.vrm")
    data = path.read_bytes()
    length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + length])
    doc["extensions"]["VRM"] = damage
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 20 + len(text) + len(rest))
                     + struct.pack("<II", len(text), 0x4E4F534A) + text + rest)
    code = main(["new", "--gltf", str(path), "-o", str(tmp_path / "a.wrinkle")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "a.vrm" in err and "the VRM extension is malformed" in err


@pytest.mark.core
def test_a_vrm_renamed_glb_is_still_read_as_vrm(tmp_path, capsys) -> None:
    """The issue renamed its .vrm to .glb to get it read: the extension is found in the JSON."""
    path = build_vrm(tmp_path / "a.vrm").rename(tmp_path / "renamed.glb")
    assert main(["new", "--gltf", str(path), "-o", str(tmp_path / "r.wrinkle")]) == 0
    out = capsys.readouterr().out
    assert "VRM 0.x: faces -Z, Y up; 5 expressions" in out and "front -Z (as given)" in out
