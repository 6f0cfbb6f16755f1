"""Which way a head looks from its eyes and nose (studio/core/setup/face_features.py), where
pose names, extents and normals mislead: the production test head's skin (tests/
production_head.py) turned into the axis conventions heads arrive in, its eyes as separate
parts the rig marks as not skin, as holes in the skin, or only as sockets in a closed skin;
its poses unnamed and deforming only the side of the head (so the surface the poses deform
faces sideways), a ponytail making the head longest along the wrong axis, or no poses."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.sample.mesh import EYE_X, EYE_Y
from studio.core.setup.face_features import find_face_features
from studio.core.setup.face_frame import detect_face_frame
from tests.production_head import Z_UP, build_head
from tests.test_full_body import _grid_box

pytestmark = pytest.mark.core

# sample axes (x the character's left, y up, z front) → world axes, by convention: each
# matrix's columns are where the sample's left, up and front go
CONVENTIONS = {
    "Y up, +Z front (glTF, Maya)": np.eye(3),
    "Z up, -Y front (Blender)": Z_UP,
    "Y up, -Z front (VRM 0.x)": np.diag([-1.0, 1.0, -1.0]),
    "X up, +Z front": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
    "Z up, +X front": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
}
EYES = ("parts", "holes", "sockets")
FACE_HEIGHT = 1.4  # the sample face, chin (y = -0.7) to hairline (y = 0.7), in sample units
EYE_CENTRES = np.array([[EYE_X, EYE_Y, 0.48], [-EYE_X, EYE_Y, 0.48]])  # the eyeballs' centres


def build(turn: np.ndarray, eyes: str = "parts", poses: str = "side",
          ponytail: bool = False) -> dict:
    """The head in world axes ``turn`` (metres, moved off the origin): rest positions, welded
    triangles, skin flags, unnamed poses, and the sample-space truths to compare with.

    ``eyes``: eyeball spheres marked not skin ("parts"), eye openings cut into the skin
    ("holes"), or neither ("sockets"). ``poses``: "side" — two poses that squeeze only the
    skin at the side of the head (its temple and cheek beside the ear), so that the deformed
    skin faces sideways; "none". ``ponytail``: a box 3.5 long hanging behind the head (the
    head is 2.15 tall)."""
    head = build_head("m", vertices=2172, up="y")
    skin_part, eye_l, eye_r, _ = head.parts
    rest = skin_part.rest.copy()
    tris = skin_part.weld[skin_part.triangles]
    x, y = head.face_xy[:, 0], head.face_xy[:, 1]
    if eyes == "holes":  # drop the skin over each eye: an opening the eyelids ring
        inside = ((np.abs(x)[tris] - EYE_X) / 0.11) ** 2 + ((y[tris] - EYE_Y) / 0.06) ** 2 < 1
        tris = tris[~(inside.any(axis=1) & (rest[tris, 2] > 0.2).all(axis=1))]
    skin = np.ones(len(rest), bool)
    parts = [eye_l, eye_r] if eyes == "parts" else []
    extra = [(p.rest, p.triangles, False) for p in parts]
    if ponytail:
        box, box_tris, _ = _grid_box((0.0, 0.3, -2.6), (0.3, 0.3, 3.5), 2, (0, 0), (1, 1))
        extra.append((box, box_tris, True))
    for positions, part_tris, is_skin in extra:
        tris = np.vstack([tris, part_tris + len(rest)])
        rest = np.vstack([rest, positions])
        skin = np.concatenate([skin, np.full(len(positions), is_skin)])
    moved = []
    if poses == "side":  # squeeze the skin by the left ear up-and-down, then front-to-back
        side = np.zeros(len(rest))
        side[:len(x)] = np.exp(-0.5 * (((rest[:len(x), 0] - 0.7) / 0.15) ** 2
                                       + (rest[:len(x), 1] / 0.25) ** 2))
        for along in (1, 2):
            pose = rest.copy()
            pose[:, along] -= 0.25 * side * (rest[:, along] - rest[:len(x), along][
                np.argmax(side)])
            moved.append(pose)
    offset = np.array([0.35, -0.2, 1.55])

    def world(points: np.ndarray) -> np.ndarray:
        return points @ turn.T + offset

    return {"rest": world(rest), "tris": tris, "skin": skin,
            "poses": [world(p) for p in moved], "names": [f"shape.{i:03d}" for i in
                                                            range(len(moved))],
            "turn": turn, "to_sample": lambda p: (np.asarray(p) - offset) @ turn,
            "nose": _nose_tip(skin_part.rest), "socket_floor": _socket_floor(head),
            "up": turn @ [0.0, 1.0, 0.0],
            "front": turn @ [0.0, 0.0, 1.0]}


def _nose_tip(rest: np.ndarray) -> np.ndarray:
    """Where the builder's nose tip is: its skin's most forward point (sample space)."""
    return rest[int(np.argmax(rest[:, 2]))]


def _socket_floor(head) -> np.ndarray:
    """(2, 3) where the builder hollowed the sockets: the skin over the eyes' centres (the
    sockets' blob sits 0.01 above the eyeballs; sample space, left eye first)."""
    skin = head.parts[0]
    xy = head.face_xy
    front = skin.rest[:, 2] > 0.2
    return np.array([skin.rest[int(np.argmin(np.where(
        front, np.hypot(xy[:, 0] - side * EYE_X, xy[:, 1] - EYE_Y - 0.01), np.inf)))]
        for side in (1.0, -1.0)])


def frame_of(head: dict):
    return detect_face_frame(head["rest"], head["tris"], head["poses"], head["names"],
                             head["skin"])


@pytest.mark.parametrize("eyes", EYES)
@pytest.mark.parametrize("convention", CONVENTIONS)
def test_unnamed_poses_at_the_side_of_the_head_do_not_turn_it(convention: str, eyes: str):
    """Poses named nothing that deform only the skin beside an ear: the deformed skin faces
    sideways, so its normals made the side the front. The eyes above the nose tip and the
    nose ahead of them give the head's own up and front, and the frame says so."""
    head = build(CONVENTIONS[convention], eyes)
    frame = frame_of(head)
    np.testing.assert_allclose(frame.up, head["up"], atol=1e-9, err_msg=frame.how)
    np.testing.assert_allclose(frame.front, head["front"], atol=1e-9, err_msg=frame.how)
    assert "the nose ahead of the eyes" in frame.how


@pytest.mark.parametrize(("convention", "ponytail"), [
    ("Y up, +Z front (glTF, Maya)", True), ("Z up, -Y front (Blender)", True),
    ("Y up, -Z front (VRM 0.x)", False), ("X up, +Z front", False),
    ("Z up, +X front", False)])
def test_without_poses_the_eyes_and_nose_beat_extents_and_conventions(convention: str,
                                                                      ponytail: bool):
    """No poses: up was the longer of the Y and Z extents (a ponytail behind the head makes
    that its depth) and front the convention for that up (−Z and +X fronts are neither). The
    eyes and nose give both; the frame says the eyes decided."""
    head = build(CONVENTIONS[convention], "parts", poses="none", ponytail=ponytail)
    frame = frame_of(head)
    np.testing.assert_allclose(frame.up, head["up"], atol=1e-9, err_msg=frame.how)
    np.testing.assert_allclose(frame.front, head["front"], atol=1e-9, err_msg=frame.how)
    assert "the eyes above the nose" in frame.how and "the nose ahead of the eyes" in frame.how


@pytest.mark.parametrize("convention", ["Y up, -Z front (VRM 0.x)", "Z up, +X front"])
def test_a_face_wound_inside_out_still_faces_its_nose(convention: str):
    """Every triangle wound inward and the poses at the side: the front is still the way
    the nose points, not the side or the back."""
    head = build(CONVENTIONS[convention], "sockets")
    head["tris"] = head["tris"][:, ::-1]
    frame = frame_of(head)
    np.testing.assert_allclose(frame.front, head["front"], atol=1e-9, err_msg=frame.how)
    np.testing.assert_allclose(frame.up, head["up"], atol=1e-9, err_msg=frame.how)


@pytest.mark.parametrize(("eyes", "within"), [("parts", 0.03), ("holes", 0.05),
                                              ("sockets", 0.1)])
@pytest.mark.parametrize("convention", ["Z up, -Y front (Blender)", "X up, +Z front"])
def test_the_nose_tip_and_eyes_are_found_where_the_builder_put_them(convention: str,
                                                                    eyes: str, within: float):
    """The nose tip within 3 % of the face's height of the skin's most forward point; the
    eyes within ``within`` of it from where they are: the eyeballs' centres (parts), the
    openings' middles (holes, compared across the face: a hole has no depth), the skin at the
    bottom of the sockets (found at their deepest hollow: on this head nearer the nose, where
    the socket meets the nose's side, hence the wider margin)."""
    head = build(CONVENTIONS[convention], eyes, poses="none")
    found = find_face_features(head["rest"], head["tris"], head["skin"])
    assert found is not None
    tolerance = FACE_HEIGHT * within
    nose = head["to_sample"](found.nose)
    assert np.linalg.norm(nose - head["nose"]) < 0.03 * FACE_HEIGHT, nose
    sample_eyes = head["to_sample"](found.eyes)
    sample_eyes = sample_eyes[np.argsort(-sample_eyes[:, 0])]  # the left eye (+x) first
    truth = head["socket_floor"] if eyes == "sockets" else EYE_CENTRES
    across = slice(0, 2) if eyes == "holes" else slice(0, 3)
    gaps = np.linalg.norm(sample_eyes[:, across] - truth[:, across], axis=1)
    assert (gaps < tolerance).all(), (sample_eyes, gaps / FACE_HEIGHT)
    assert found.eyes_from == {"parts": "eye parts", "holes": "eye holes in the skin",
                               "sockets": "eye sockets"}[eyes]
    np.testing.assert_allclose(found.up, head["up"], atol=1e-9)
    np.testing.assert_allclose(found.front, head["front"], atol=1e-9)


def test_a_head_without_a_face_gives_no_features():
    """A smooth symmetric blob (no nose, no eyes): nothing is claimed, and the frame is the
    one the other evidence gives."""
    head = build(np.eye(3), "sockets", poses="none")
    # the same mesh with its features flattened: the skin pushed onto a plain ellipsoid
    rest = head["rest"] - head["rest"].mean(axis=0)
    radii = np.ptp(rest, axis=0) / 2.0
    direction = rest / np.linalg.norm(rest / radii, axis=1, keepdims=True)
    assert find_face_features(direction, head["tris"], head["skin"]) is None
