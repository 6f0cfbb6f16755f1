"""Which way a head made elsewhere looks and which way is up, from more than one pose's motion:
the way the moving skin faces and its left–right symmetry overrule an up that is the face's own
facing (a ponytail longer than the head is tall, a blink whose lid moves toward the camera);
``--front`` beside ``--up``. The heads are the production test head's skin (tests/
production_head.py) in the conventions of each case, built here."""

from __future__ import annotations

import numpy as np
import pytest

from studio.cli import main
from studio.core.files.errors import StudioError
from studio.core.setup.face_frame import detect_face_frame
from tests.production_head import build_head
from tests.test_full_body import _grid_box

# the sample's axes (x left, y up, z front) turned so that the face looks toward −Z, Y up
TO_MINUS_Z = np.diag([-1.0, 1.0, -1.0])


def head_with(turn: np.ndarray | None = None, ponytail: bool = False,
              names: tuple[str, ...] = ("unit1", "unit2", "unit3")):
    """(rest, welded triangles, poses, names): the skin, turned, with poses that say nothing of
    their direction by name, and a ponytail hanging far behind it."""
    turn = np.eye(3) if turn is None else turn
    head = build_head("m", vertices=900, up="y")
    skin = head.parts[0]
    rest = skin.rest @ turn.T
    tris = skin.weld[skin.triangles]
    poses = [skin.poses[p] @ turn.T for p in ("browInnerUp", "browDown_L", "mouthSmile_L")]
    if ponytail:  # 3.5 units long behind the head (the head is 2.15 tall)
        pos, box_tris, _ = _grid_box((0.0, 0.3, -2.6), (0.3, 0.3, 3.5), 2, (0, 0), (1, 1))
        pos = pos @ turn.T
        box_tris = box_tris + len(rest)
        rest = np.concatenate([rest, pos])
        tris = np.concatenate([tris, box_tris])
        poses = [np.concatenate([p, pos]) for p in poses]
    return rest, tris, poses, list(names)


@pytest.mark.core
def test_a_ponytail_longer_than_the_head_does_not_make_it_look_up() -> None:
    rest, tris, poses, names = head_with(ponytail=True)
    assert np.ptp(rest[:, 2]) > np.ptp(rest[:, 1])  # the extents alone say Z up
    frame = detect_face_frame(rest, tris, poses, names)
    assert np.allclose(frame.up, (0, 1, 0)), frame.how
    assert np.allclose(frame.front, (0, 0, 1)), frame.how
    assert "symmetry" in frame.how


@pytest.mark.core
def test_a_blink_toward_the_camera_does_not_make_the_front_up() -> None:
    """A VRM 0.x face (−Z front) whose only named pose is a blink pushing the lid forward: the
    blink's "down" motion said −Z was down (+Z up), the face's own facing."""
    rest, tris, _, _ = head_with(TO_MINUS_Z)
    blink = rest.copy()
    lid = (np.abs(rest[:, 0] + 0.27) < 0.12) & (np.abs(rest[:, 1] - 0.15) < 0.06)
    lid &= rest[:, 2] < -0.3
    blink[lid, 2] -= 0.04 * (1.0 - np.abs(rest[lid, 1] - 0.15) / 0.06)
    frame = detect_face_frame(rest, tris, [blink], ["blink_left"])
    assert np.allclose(frame.up, (0, 1, 0)), frame.how
    assert np.allclose(frame.front, (0, 0, -1)), frame.how


@pytest.mark.core
def test_front_is_taken_as_given_and_must_be_across_up() -> None:
    rest, tris, poses, names = head_with(TO_MINUS_Z)
    frame = detect_face_frame(rest, tris, poses, names, front="-z")
    assert np.allclose(frame.front, (0, 0, -1)) and "front -Z (as given)" in frame.how
    with pytest.raises(StudioError, match="not at right angles"):
        detect_face_frame(rest, tris, poses, names, up="z", front="-z")


@pytest.mark.core
def test_a_bad_front_on_the_command_line_is_one_line_and_exit_2(tmp_path, capsys) -> None:
    code = main(["new", "--mesh", str(tmp_path / "none.obj"), "--front", "sideways",
                 "-o", str(tmp_path / "x.wrinkle")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "'sideways' is not an axis" in err
