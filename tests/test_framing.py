"""The default camera frames the face (studio/core/setup/face_frame.py ``aim``): a head that
comes without key poses (a FLAME template, a sculpt) is framed on its face as the same head
with its poses is — eyes, nose and chin in the same places on the screen — not on the upper
half of its skin with the chin on the bottom edge. And a rig whose only pose opens the jaw is
framed right side up (the chin's underside looks down as much as the face looks ahead: it does
not overrule the jaw's own motion). The heads are the production test head (tests/
production_head.py) as OBJs in millimetres, Z up, far from the origin."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from studio.core.formats.assemble import project_from_files
from studio.core.mesh.camera import OrbitCamera
from studio.core.sample.mesh import EYE_X, EYE_Y
from studio.core.setup.face_frame import aim, detect_face_frame
from tests.production_head import POSES, build_head

pytestmark = pytest.mark.core

SIZE = 400  # the view, pixels square


def _landmarks(head) -> np.ndarray:
    """World positions of the eyes' centres, the nose tip and the chin (the skin's lowest
    point at the front), in the head's own convention."""
    skin = head.parts[0]
    x, y = head.face_xy[:, 0], head.face_xy[:, 1]
    front = skin.rest[:, 2] > 0.3
    nose = skin.rest[int(np.argmax(skin.rest[:, 2]))]
    chin = skin.rest[int(np.argmin(np.where(front & (np.abs(x) < 0.05), y, np.inf)))]
    eyes = np.array([[EYE_X, EYE_Y, 0.48], [-EYE_X, EYE_Y, 0.48]])
    return head.to_world(np.vstack([eyes, nose, chin]))


def _screen(tmp_path: Path, poses: tuple[str, ...]) -> tuple[np.ndarray, str]:
    head = build_head("mm", up="z")
    files = head.write_set(tmp_path / ("posed" if poses else "bare"), poses)
    project = project_from_files(files["neutral"], {p: files[p] for p in poses}, report=[])
    camera = OrbitCamera()
    frame = aim(camera, project)
    pixels, _ = camera.project(_landmarks(head), SIZE, SIZE)
    return pixels, frame.how


def test_a_head_without_poses_is_framed_on_its_face_as_with_them(tmp_path: Path):
    """Eyes, nose tip and chin within 4 % of the view of where the posed head puts them, the
    chin well inside the bottom edge. Red before: the upper half of the skin was framed, the
    chin below the bottom edge."""
    posed, _ = _screen(tmp_path, POSES)
    bare, how = _screen(tmp_path, ())
    assert np.abs(bare - posed).max() < 0.04 * SIZE, (bare, posed, how)
    chin_y = bare[3, 1]
    assert chin_y < 0.95 * SIZE, how
    assert "boxed around its eyes and nose" in how


@pytest.mark.parametrize("up", ["y", "z"])
def test_a_rig_whose_only_pose_opens_the_jaw_is_right_side_up(up: str):
    """The head's skin alone (no eyes: a scan), its only pose jawOpen: up is the head's up,
    said to come from the jaw's motion, and the camera looks at the face from the front.
    Red before: up was taken across the way the jaw's skin looks (down), and came out as the
    front."""
    head = build_head("mm", up=up)
    skin = head.parts[0]
    rest = head.to_world(skin.rest)
    tris = skin.weld[skin.triangles]
    frame = detect_face_frame(rest, tris, [head.to_world(skin.poses["jawOpen"])], ["jawOpen"])
    np.testing.assert_allclose(frame.up, head.axes @ [0.0, 1.0, 0.0], atol=1e-9,
                               err_msg=frame.how)
    np.testing.assert_allclose(frame.front, head.axes @ [0.0, 0.0, 1.0], atol=1e-9,
                               err_msg=frame.how)
    assert frame.how.startswith(f"up {'+Y' if up == 'y' else '+Z'} (from the motion of jawOpen)")


def _fringe_camera() -> tuple[OrbitCamera, float]:
    """A face box 2 units wide framed from its front (yaw 0, pitch 0, Y up, looking down −Z),
    and the eye's distance that framing gives."""
    camera = OrbitCamera(yaw=0.0, pitch=0.0)
    camera.frame(np.array([-1.0, -1.0, -0.5]), np.array([1.0, 1.0, 0.5]))
    return camera, camera.distance


def test_the_eye_stands_clear_of_hair_reaching_past_it():
    """A low-poly hair shell whose fringe reaches 1.5 units past where framing put the eye:
    the eye backs off to just beyond the fringe (by 5 % of what it framed) and the near plane
    lies before the fringe, so the first picture shows the hair from outside, not its inside.
    Red without ``stand_clear_of``: the eye sat inside the fringe."""
    camera, framed = _fringe_camera()
    fringe_z = framed + 1.5
    fringe = np.array([[x, 0.8, fringe_z] for x in (-0.9, 0.0, 0.9)])
    radius = camera.radius
    camera.stand_clear_of(np.vstack([fringe, [[0.0, 0.0, 0.5]]]))
    assert camera.distance == pytest.approx(fringe_z + 0.05 * radius)
    near, far = camera.clip_planes()
    assert near < camera.distance - fringe_z
    assert far > camera.distance + 0.5  # the face's back still inside


def test_what_lies_beside_the_face_or_behind_it_does_not_move_the_eye():
    """An arm raised to the side (outside the framed window) and hair behind the head leave
    the framing as it was; so does a nose inside the face box."""
    camera, framed = _fringe_camera()
    half = framed * np.tan(np.radians(camera.fov_y) / 2.0)
    beside = np.array([[half + 0.5, 0.0, framed + 3.0], [0.0, 0.0, -4.0], [0.0, 0.0, 0.5]])
    radius = camera.radius
    camera.stand_clear_of(beside)
    assert camera.distance == framed
    assert camera.radius == radius
