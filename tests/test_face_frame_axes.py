"""The face frame on tiny hand-built heads: the axis names a user types, the conventional front
for each up axis, the face box without and with key poses, Y-up and Z-up, and the saved form."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.setup.face_frame import (
    _conventional_front,
    detect_face_frame,
    parse_axis,
)

pytestmark = pytest.mark.core

# Percentiles 1 and 99 of three values a < b < c (numpy's linear interpolation): the face box
# spans 0.98 of the region's extent, then MARGIN (1.12) wider.
SHRINK = 0.98
MARGIN = 1.12


# --------------------------------------------------------------------------------------------
# Axis names
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "expected"), [
    ("y", (0, 1, 0)), ("+Z", (0, 0, 1)), ("-y", (0, -1, 0)), (" -X ", (-1, 0, 0)),
    ("+x", (1, 0, 0)), ("-z", (0, 0, -1)),
])
def test_parse_axis_reads_signed_and_unsigned_names(text: str, expected: tuple[int, ...]):
    """x, +x, -x (any case, spaces around) are the unit vectors along the model axes."""
    np.testing.assert_array_equal(parse_axis(text), expected)


@pytest.mark.parametrize("text", ["diagonal", "", "+-y", "--z", "xy"])
def test_parse_axis_refuses_anything_else(text: str):
    """Anything but an axis name is refused with the names that are allowed."""
    with pytest.raises(StudioError) as info:
        parse_axis(text)
    assert str(info.value) == f"'{text}' is not an axis (use x, y, z, -x, -y or -z)"


# --------------------------------------------------------------------------------------------
# Without key poses: the convention that goes with the up axis
# --------------------------------------------------------------------------------------------

# Five skin points, heights (along +Y) 0, 0, 1, 2, 2: the upper half (height >= the median 1)
# is the last three, which frame the face.
HEAD_Y = np.array([[-1, 0, 0], [1, 0, 0], [0, 1, 1], [-1, 2, 0], [1, 2, 0]], np.float64)
TRI = np.array([[0, 1, 2]])


@pytest.mark.parametrize(("up", "front", "left"), [
    ("y", (0, 0, 1), (1, 0, 0)),
    ("-y", (0, 0, -1), (1, 0, 0)),
    ("z", (0, -1, 0), (1, 0, 0)),
    ("-z", (0, 1, 0), (1, 0, 0)),
    ("x", (0, 0, 1), (0, -1, 0)),
    ("-x", (0, 0, 1), (0, 1, 0)),
])
def test_without_poses_the_front_is_the_convention_of_the_up_axis(
        up: str, front: tuple[int, ...], left: tuple[int, ...]):
    """Y up faces +Z, Z up faces -Y (and the reverse for -Y, -Z); X up faces +Z; left is
    up × front; the frame says what it assumed."""
    frame = detect_face_frame(HEAD_Y, TRI, up=up)
    assert frame.up == tuple(float(c) for c in parse_axis(up))
    assert frame.front == tuple(float(c) for c in front)
    assert frame.left == tuple(float(c) for c in left)
    name = {"x": "+X", "-x": "-X", "y": "+Y", "-y": "-Y", "z": "+Z", "-z": "-Z"}[up]
    front_name = "+-"[min(front) < 0] + "XYZ"[int(np.flatnonzero(front)[0])]
    assert frame.how == (f"up {name} (as given); no key pose deforms the skin: the face is "
                         f"taken to be the upper skin; front {front_name} (the usual "
                         "convention with that up axis)")


def test_without_poses_the_box_is_the_upper_half_of_the_skin():
    """Y up: the box spans the points at or above the median height, shrunk to percentiles
    1 and 99 and widened by the margin; the mirror plane runs through the skin's middle."""
    frame = detect_face_frame(HEAD_Y, TRI, up="y")
    # Upper points: x -1, 0, 1; y 1, 2, 2; z 0, 1, 0.
    lo_y, hi_y = 1 + 0.02 * 1, 2.0
    lo_z, hi_z = 0.0, 0.98
    np.testing.assert_allclose(frame.centre, [0, (lo_y + hi_y) / 2, (lo_z + hi_z) / 2])
    np.testing.assert_allclose(frame.half, [SHRINK * MARGIN, (hi_y - lo_y) / 2 * MARGIN,
                                            (hi_z - lo_z) / 2 * MARGIN])
    assert frame.mirror_axis == 0
    assert frame.mirror_plane == 0.0


def test_without_poses_the_upper_half_is_of_the_skin_only():
    """Points that are not skin (a hat far above) neither join the box nor move the median."""
    hat = np.array([[0, 10, 0], [1, 10, 0], [0, 10, 1]], np.float64)
    rest = np.vstack([HEAD_Y, hat])
    skin = np.array([1, 1, 1, 1, 1, 0, 0, 0])
    frame = detect_face_frame(rest, TRI, skin=skin, up="y")
    alone = detect_face_frame(HEAD_Y, TRI, up="y")
    np.testing.assert_allclose(frame.centre, alone.centre)
    np.testing.assert_allclose(frame.half, alone.half)
    assert frame.mirror_plane == 0.0


def test_without_poses_or_up_the_longer_extent_is_up():
    """Taller along Z than Y: Z up, facing -Y (Blender); taller along Y: Y up, facing +Z."""
    tall_z = HEAD_Y[:, [0, 2, 1]]
    frame = detect_face_frame(tall_z, TRI)
    assert (frame.up, frame.front, frame.left) == ((0, 0, 1), (0, -1, 0), (1, 0, 0))
    assert frame.how.startswith("up +Z (the longer of the Y and Z extents; give --up to "
                                "choose); ")
    frame = detect_face_frame(HEAD_Y, TRI)
    assert (frame.up, frame.front, frame.left) == ((0, 1, 0), (0, 0, 1), (1, 0, 0))


@pytest.mark.parametrize(("up", "expected"), [
    ((0.0, 0.96, 0.28), (0.0, 0.28, -0.96)),  # mostly Y: crossed with X
    ((0.6, 0.8, 0.0), (0.0, 0.0, -1.0)),  # crossed with X, then normalised
    ((0.96, 0.0, 0.28), (-0.28, 0.0, 0.96)),  # mostly X: crossed with Y instead
    ((0.9, 0.0, 0.19 ** 0.5), (-(0.19 ** 0.5), 0.0, 0.9)),  # |x| = 0.9 exactly: Y too
])
def test_an_up_off_the_axes_gets_an_arbitrary_perpendicular_front(
        up: tuple[float, ...], expected: tuple[float, ...]):
    """An up along no axis has no convention: the front is up × X (or up × Y when up is
    mostly X), as a unit vector, and says it is arbitrary."""
    front, reason = _conventional_front(np.array(up))
    np.testing.assert_allclose(front, expected, atol=1e-12)
    assert reason == "nothing to go by; an arbitrary side"


# --------------------------------------------------------------------------------------------
# With key poses
# --------------------------------------------------------------------------------------------

# A 3 × 3 sheet in the x-z plane (Z up) facing -Y: rows of x = 0, 1, 2 at z = 0, 1, 2.
GRID = np.array([[x, 0, z] for z in (0, 1, 2) for x in (0, 1, 2)], np.float64)
GRID_TRIS = np.array([t for r in range(2) for c in range(2) for t in (
    [3 * r + c, 3 * r + c + 1, 3 * r + c + 4], [3 * r + c, 3 * r + c + 4, 3 * r + c + 3])])
Z_UP_TO_Y_UP = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], np.float64)  # (x, y, z) → (x, z, -y)


def _jaw_open(points: np.ndarray, down: np.ndarray) -> np.ndarray:
    """The bottom row (z = 0 in the Z-up sheet) pulled 0.5 down: the lower two rows deform."""
    moved = points.copy()
    moved[:3] += 0.5 * down
    return moved


@pytest.mark.parametrize("convention", ["z-up", "y-up"])
def test_a_deforming_pose_gives_up_front_and_box(convention: str):
    """jawOpen pulls the chin down: up is against its motion, front is where the deformed
    skin faces, and the box is the deformed rows (x 0…2, two rows high, flat)."""
    turn = np.eye(3) if convention == "z-up" else Z_UP_TO_Y_UP
    rest = GRID @ turn.T
    up = turn @ [0.0, 0.0, 1.0]
    front = turn @ [0.0, -1.0, 0.0]
    frame = detect_face_frame(rest, GRID_TRIS, [_jaw_open(rest, -up)], ["jawOpen"])
    np.testing.assert_array_equal(frame.up, up)
    np.testing.assert_array_equal(frame.front, front)
    np.testing.assert_array_equal(frame.left, [1, 0, 0])
    up_name, front_name = ("+Z", "-Y") if convention == "z-up" else ("+Y", "+Z")
    # one pose moving straight down: its agreement 1, times n / (n + 1) for a lone pose
    assert frame.how == (f"up {up_name} (from the motion of jawOpen); how sure of up: "
                         "fairly sure, 0.50 (1 of 1 moving that way); "
                         f"front {front_name} (the way the face's surface faces)")
    # Deformed: rows z = 0 and 1, x 0, 1, 2 twice each (percentiles 1 and 99 are the ends).
    np.testing.assert_allclose(frame.centre, turn @ [1.0, 0.0, 0.5])
    np.testing.assert_allclose(frame.half, [MARGIN, 0.5 * MARGIN, 1e-3 * np.hypot(2, 2)])
    assert frame.mirror_axis == 0 and frame.mirror_plane == 1.0


def test_the_frame_converts_points_to_face_coordinates():
    """to_face maps the box's centre to 0 and its corners to ±1 on every axis."""
    rest = GRID
    frame = detect_face_frame(rest, GRID_TRIS, [_jaw_open(rest, np.array([0.0, 0, -1]))],
                              ["jawOpen"])
    np.testing.assert_allclose(frame.to_face(np.array([frame.centre])), [[0, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(np.abs(frame.to_face(frame.corners())), 1.0)


def test_to_dict_holds_every_field_as_plain_lists():
    """The saved form of a frame: each axis, centre and half as a list, how and the mirror."""
    frame = detect_face_frame(HEAD_Y, TRI, up="y")
    saved = frame.to_dict()
    assert saved == {
        "left": [1.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "front": [0.0, 0.0, 1.0],
        "centre": list(frame.centre), "half": list(frame.half), "how": frame.how,
        "mirror_axis": 0, "mirror_plane": 0.0,
    }
    assert all(type(saved[k]) is list for k in ("left", "up", "front", "centre", "half"))
    assert saved["centre"] == pytest.approx([0.0, 1.51, 0.49])
    assert saved["how"].startswith("up +Y (as given)")


# --------------------------------------------------------------------------------------------
# Which way up: the poses' names and motion
# --------------------------------------------------------------------------------------------


def _lift(points: np.ndarray, rows: slice, by: tuple[float, float, float]) -> np.ndarray:
    moved = points.copy()
    moved[rows] += by
    return moved


TOP = slice(6, 9)  # the sheet's z = 2 row
BOTTOM = slice(0, 3)


def test_a_pose_named_by_a_word_says_up():
    """Without ARKit names, a 'Brow_Raise' lifting the top row says +Z is up."""
    frame = detect_face_frame(GRID, GRID_TRIS, [_lift(GRID, TOP, (0, 0, 0.5))], ["Brow_Raise"])
    assert frame.up == (0.0, 0.0, 1.0)
    assert frame.how.startswith("up +Z (from the motion of Brow_Raise); ")


def test_arkit_names_outvote_words():
    """With an ARKit name present, a pose named only by a word ('blink') does not vote."""
    poses = [_lift(GRID, TOP, (0, 0, 0.5)), _lift(GRID, BOTTOM, (0.5, 0, 0))]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, ["browInnerUp", "big_blink"])
    assert frame.up == (0.0, 0.0, 1.0)
    assert frame.how.startswith("up +Z (from the motion of browInnerUp); ")


def test_poses_that_cancel_leave_up_to_the_extents():
    """An up pose and a down pose moving the same way cancel: up falls back to the extents."""
    poses = [_lift(GRID, TOP, (0, 0, 0.5)), _lift(GRID, TOP, (0, 0, 0.5))]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, ["browInnerUp", "jawOpen"])
    assert frame.how.startswith("up +Z (the longer of the Y and Z extents; give --up to "
                                "choose); ")


def test_many_voting_poses_are_listed_three_then_an_ellipsis():
    """Four poses that say up: the first three are named, then '…'."""
    names = ["browInnerUp", "eyeWideLeft", "eyeWideRight", "mouthSmileLeft"]
    poses = [_lift(GRID, TOP, (0, 0, 0.5 + 0.1 * i)) for i in range(4)]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, names)
    assert frame.how.startswith("up +Z (from the motion of browInnerUp, eyeWideLeft, "
                                "eyeWideRight …); ")


# --------------------------------------------------------------------------------------------
# Which way front: the deformed skin's surface, and where it sits on the head
# --------------------------------------------------------------------------------------------


def _sheet(origin: tuple[float, ...], u: tuple[float, ...], v: tuple[float, ...],
           first: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A 3 × 3 sheet of points origin + i u + j v; its triangles face u × v."""
    o, u_, v_ = (np.asarray(a, np.float64) for a in (origin, u, v))
    points = np.array([o + i * u_ + j * v_ for j in range(3) for i in range(3)])
    return points, GRID_TRIS + first


def _head(flip: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A face sheet at y = -1 facing -Y and the back of the head at y = +1 facing +Y (Z up);
    ``flip`` turns every triangle inside out."""
    face, face_tris = _sheet((0, -1, 0), (1, 0, 0), (0, 0, 1))
    back, back_tris = _sheet((2, 1, 0), (-1, 0, 0), (0, 0, 1), first=9)
    tris = np.vstack([face_tris, back_tris])
    return np.vstack([face, back]), tris[:, ::-1] if flip else tris


def test_inward_normals_are_reversed_by_where_the_face_sits():
    """Triangles wound inside out face +Y, but the deformed skin sits at -Y: front is -Y."""
    for flip, reason in ((False, "the way the face's surface faces"),
                         (True, "the surface's normals point inward; taken reversed")):
        rest, tris = _head(flip)
        frame = detect_face_frame(rest, tris, [_lift(rest, BOTTOM, (0, 0, -0.5))], ["jawOpen"])
        assert frame.front == (0.0, -1.0, 0.0)
        assert frame.how.endswith(f"; front -Y ({reason})")


def test_a_face_lying_flat_is_fronted_by_where_it_sits():
    """Deformed skin whose surface faces straight up: front is its side of the head."""
    face, face_tris = _sheet((0, -2, 0), (1, 0, 0), (0, 1, 0))
    rest_of_head, head_tris = _sheet((0, 1, 0), (1, 0, 0), (0, 1, 0), first=9)
    rest = np.vstack([face, rest_of_head])
    pose = _lift(rest, BOTTOM, (0, -0.5, 0))
    frame = detect_face_frame(rest, np.vstack([face_tris, head_tris]), [pose], ["stretch"],
                              up="z")
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (where the face sits on the head)")


def test_a_face_with_nothing_to_go_by_gets_an_arbitrary_side():
    """All of a flat sheet deformed alike, facing up: no side is known, one is chosen."""
    rest, tris = _sheet((0, 0, 0), (1, 0, 0), (0, 1, 0))
    frame = detect_face_frame(rest, tris, [rest * 2.0], ["grow"], up="z")
    assert frame.front == (0.0, 1.0, 0.0)
    assert frame.left == (-1.0, 0.0, 0.0)
    assert frame.how.endswith("; front +Y (nothing to go by; an arbitrary side)")


@pytest.mark.parametrize("scale", [1.0, 0.01])
@pytest.mark.parametrize(("degrees", "front", "name"), [
    (20.0, (0.0, -1.0, 0.0), "-Y"),
    (110.0, (1.0, 0.0, 0.0), "+X"),
    (45.0, (0.5 ** 0.5, -(0.5 ** 0.5), 0.0), "(0.71, -0.71, 0.00)"),
])
def test_the_front_snaps_to_an_axis_only_within_30_degrees(
        degrees: float, front: tuple[float, ...], name: str, scale: float):
    """A face turned 20° from -Y (or from +X) is taken as facing that axis; turned 45° it keeps
    its own way; the same for a face a hundredth the size."""
    t = np.radians(degrees)
    turn = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])
    rest, tris = _head()
    rest = rest @ turn.T * scale
    pose = _lift(rest, BOTTOM, (0, 0, -0.5 * scale))
    frame = detect_face_frame(rest, tris, [pose], ["jawOpen"])
    np.testing.assert_allclose(frame.front, front, atol=1e-12)
    np.testing.assert_allclose(frame.left, np.cross((0, 0, 1), front), atol=1e-12)
    assert frame.how.endswith(f"; front {name} (the way the face's surface faces)")


def test_arkit_poses_that_say_no_direction_do_not_vote():
    """jawLeft names no up or down: only browInnerUp's lift votes, whatever jawLeft moves."""
    poses = [_lift(GRID, TOP, (0, 0, 0.5)), _lift(GRID, BOTTOM, (0.5, 0, 0))]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, ["browInnerUp", "jawLeft"])
    assert frame.up == (0.0, 0.0, 1.0)
    assert frame.how.startswith("up +Z (from the motion of browInnerUp); ")


@pytest.mark.parametrize("scale", [0.01, 0.1, 1.0, 100.0])
@pytest.mark.parametrize(("degrees", "front"), [
    (30.0, (0.0, -1.0, 0.0)), (45.0, (0.5 ** 0.5, -(0.5 ** 0.5), 0.0)),
    (70.0, (1.0, 0.0, 0.0)), (135.0, (0.5 ** 0.5, 0.5 ** 0.5, 0.0)),
])
def test_a_lone_face_sheet_keeps_the_way_it_faces(scale: float, degrees: float,
                                                  front: tuple[float, ...]):
    """A face on its own (a scanned mask, no back of the head) sits at the head's centre: the
    rounding left in that offset (1e-19) must not count as the face sitting behind its
    normals and reverse the front. The jawOpen sheet turned about Z, at four scales."""
    a = np.radians(degrees)
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0, 0, 1]])
    rest = (GRID * scale) @ turn.T
    frame = detect_face_frame(rest, GRID_TRIS, [_jaw_open(rest, np.array([0, 0, -scale]))],
                              ["jawOpen"])
    np.testing.assert_allclose(frame.front, front, atol=1e-9)
    assert frame.how.endswith("(the way the face's surface faces)")


def test_a_mesh_without_skin_or_poses_is_framed_as_a_whole():
    """Every vertex marked not-face and no pose: the frame comes from the whole mesh (the
    upper half of it), not an error."""
    rest, tris = _sheet((0, 0, 0), (1, 0, 0), (0, 0, 1))
    frame = detect_face_frame(rest, tris, skin=np.zeros(len(rest), bool), up="z")
    assert frame.up == (0.0, 0.0, 1.0)
    np.testing.assert_allclose(frame.centre[2], 1.5)  # the upper half: rows z = 1 and 2
