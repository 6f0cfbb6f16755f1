"""The face frame's edge cases on tiny hand-built heads: axis names with rounding noise, the pose
names whose words say up or down, the mesh edges and their deformation, which skin counts as
deformed (a percentile of the deformed skin only), how poses vote for up (order, tiny motion,
cancelling motion, a fifth of the largest), how the front is found (normals that cancel, a
slight tilt at any scale, non-skin parts, a head far from the origin), the mirror axis, and
aiming the camera. Heads come in any units and conventions, so each rule is checked where a
wrong threshold or sign would pick another axis or say another reason in the report."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.camera import OrbitCamera
from studio.core.setup.face_features import unique_edges
from studio.core.setup.face_frame import (
    FaceFrame,
    _deformation,
    _pose_direction,
    _snap,
    aim,
    axis_name,
    detect_face_frame,
)

pytestmark = pytest.mark.core

MARGIN = 1.12

# A 3 × 3 sheet in the x-z plane (Z up) facing -Y: rows of x = 0, 1, 2 at z = 0, 1, 2.
GRID = np.array([[x, 0, z] for z in (0, 1, 2) for x in (0, 1, 2)], np.float64)
GRID_TRIS = np.array(
    [
        t
        for r in range(2)
        for c in range(2)
        for t in (
            [3 * r + c, 3 * r + c + 1, 3 * r + c + 4],
            [3 * r + c, 3 * r + c + 4, 3 * r + c + 3],
        )
    ]
)
TOP = slice(6, 9)
BOTTOM = slice(0, 3)
# A 3-4-5 right triangle in the x-z plane facing -Y: every edge length is exact, and so is
# every edge's relative change when it is scaled about its first corner.
TRIANGLE = np.array([[0, 0, 0], [3, 0, 0], [0, 0, 4]], np.float64)


def _lift(
    points: np.ndarray, rows: slice | list[int], by: tuple[float, float, float]
) -> np.ndarray:
    moved = points.copy()
    moved[rows] += by
    return moved


def _triangles(scales: list[float], gap: float = 10.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Disjoint 3-4-5 triangles side by side along x; a pose scales triangle i by scales[i]
    about its first corner (relative edge change scales[i] - 1 on all its corners)."""
    rest, pose, tris = [], [], []
    for i, s in enumerate(scales):
        corner = np.array([gap * i, 0.0, 0.0])
        rest.append(TRIANGLE + corner)
        pose.append(TRIANGLE * s + corner)
        tris.append([3 * i, 3 * i + 1, 3 * i + 2])
    return np.vstack(rest), np.vstack(pose), np.array(tris)


# --------------------------------------------------------------------------------------------
# Axis names and snapping
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("vector", "name"),
    [
        ((0, 0, 1), "+Z"),
        ((-1.0, 0.0, 0.0), "-X"),
        ((1e-7, 0.0, 1.0), "+Z"),
        ((0.0, -1.0, -5e-7), "-Y"),
        ((0.6, 0.8, 0.0), "(0.60, 0.80, 0.00)"),
        ((1e-4, 0.0, 1.0), "(0.00, 0.00, 1.00)"),
    ],
)
def test_axis_name_tolerates_rounding_noise_only(vector: tuple[float, ...], name: str):
    """An axis with noise under a millionth (a float32 round trip) is still named as the axis;
    anything further off is shown as its rounded components."""
    assert axis_name(np.array(vector)) == name


def test_snap_with_no_allowed_axis_keeps_the_unit_vector():
    v, snapped = _snap(np.array([3.0, 4.0, 0.0]), [])
    np.testing.assert_allclose(v, [0.6, 0.8, 0.0])
    assert snapped is False


def test_snap_within_30_degrees_only():
    """20° off +X snaps to +X (as floats); 40° off does not and keeps its own unit vector."""
    t = np.radians(20.0)
    v, snapped = _snap(np.array([2 * np.cos(t), 2 * np.sin(t), 0.0]))
    assert snapped is True and v.dtype == np.float64
    np.testing.assert_array_equal(v, [1.0, 0.0, 0.0])
    t = np.radians(40.0)
    v, snapped = _snap(np.array([np.cos(t), np.sin(t), 0.0]) * 5.0)
    assert snapped is False
    np.testing.assert_allclose(v, [np.cos(t), np.sin(t), 0.0])


# --------------------------------------------------------------------------------------------
# Which way a pose's name says it moves the skin
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "direction"),
    [
        ("brow_down", -1),
        ("Jaw-Down", -1),
        ("big.frown", -1),
        ("Blink L", -1),
        ("Brow_Raise", 1),
        ("browRaise", 1),
        ("Brows Up", 1),
        ("brow.up", 1),
        ("Surprise", 1),
        ("stretch", 0),
        ("jaw_left", 0),
        ("", 0),
    ],
)
def test_words_in_a_pose_name_say_up_or_down(name: str, direction: int):
    """Separators (space, _, ., -) and case do not matter; down words win; other names say
    nothing (0)."""
    assert _pose_direction(name, True) == direction


@pytest.mark.parametrize("name", ["brow_down", "Brow_Raise", "stretch"])
def test_words_are_not_read_when_arkit_names_are_present(name: str):
    assert _pose_direction(name, False) == 0


@pytest.mark.parametrize(
    ("name", "direction"),
    [
        ("jawOpen", -1),
        ("browInnerUp", 1),
        ("mouthSmileLeft", 1),
        ("jawLeft", 0),
    ],
)
def test_arkit_names_say_their_direction_with_or_without_words(name: str, direction: int):
    assert _pose_direction(name, False) == direction
    assert _pose_direction(name, True) == direction


# --------------------------------------------------------------------------------------------
# Edges and their deformation
# --------------------------------------------------------------------------------------------


def test_edges_are_each_undirected_edge_once():
    tris = np.array([[0, 1, 2], [2, 1, 3]])
    edges, uses = unique_edges(tris)
    np.testing.assert_array_equal(edges, [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]])
    np.testing.assert_array_equal(uses, [1, 1, 2, 1, 1])  # the shared edge twice


def test_deformation_is_the_largest_relative_edge_change():
    """A 3-4-5 triangle's 4-edge stretched to 6 (its corners 1 and 2 move): the corners of
    that edge change by 0.5; a second pose stretching every edge by 10 % adds 0.1 at corner
    0."""
    rest = TRIANGLE.copy()
    edges, _ = unique_edges(np.array([[0, 1, 2]]))
    stretched = rest.copy()
    stretched[2] = (0, 0, 6)  # 4 → 6 (+50 %), the hypotenuse 5 → √45 (+34 %)
    out = _deformation(rest, [stretched, rest * 1.1], edges)
    np.testing.assert_allclose(out, [0.5, np.sqrt(45) / 5 - 1.0, 0.5])


def test_a_zero_length_edge_does_not_count_as_deformed():
    """Two vertices at one place (a seam not welded) pulled apart: no relative change can be
    measured from a zero length, so they count 0, not infinity."""
    rest = np.array([[0, 0, 0], [0, 0, 0], [1, 0, 0]], np.float64)
    pose = np.array([[0, 0, 0], [0, 0, 0.5], [1, 0, 0]], np.float64)
    out = _deformation(rest, [pose], np.array([[0, 1]]))
    np.testing.assert_array_equal(out, [0.0, 0.0, 0.0])


# --------------------------------------------------------------------------------------------
# Which skin is the face
# --------------------------------------------------------------------------------------------


def test_a_face_of_exactly_three_deformed_vertices_is_framed_and_a_tenth_is_not_enough():
    """Strong deformation 10 (95th percentile of the deformed skin); a triangle deformed by
    exactly a tenth of that (1.0) is not face: the face is the strong triangle alone — three
    vertices, enough to say where it faces."""
    rest, pose, tris = _triangles([11.0, 2.0])
    frame = detect_face_frame(rest, tris, [pose], ["stretch"], up="z")
    assert frame.how == "up +Z (as given); front -Y (the way the face's surface faces)"
    # x of the face: 0, 3, 0 → percentiles 1 and 99 are 0 and 2.94
    assert frame.centre[0] == pytest.approx(1.47)
    assert frame.half[0] == pytest.approx(1.47 * MARGIN)


def test_the_strong_deformation_is_a_percentile_of_the_deformed_skin_only():
    """One triangle deformed among many still (under 5 % of the vertices): the strong
    deformation is measured over deformed skin, so the triangle is the face."""
    rest, pose, tris = _triangles([2.0])
    behind = np.tile([1.0, 1.0, 4 / 3], (60, 1))  # still skin behind the triangle's middle
    frame = detect_face_frame(
        np.vstack([rest, behind]), tris, [np.vstack([pose, behind])], ["stretch"], up="z"
    )
    assert frame.how == "up +Z (as given); front -Y (the way the face's surface faces)"
    assert frame.centre[0] == pytest.approx(1.47)


def test_weakly_deformed_skin_is_face_when_above_a_tenth_of_the_95th_percentile():
    """Nineteen triangles deformed by 1 and one by 100: the 95th percentile of the 60 values
    is 1 + 0.05 · 99 = 5.95, a tenth of it is under 1, so all twenty triangles are face."""
    rest, pose, tris = _triangles([2.0] * 19 + [101.0])
    frame = detect_face_frame(rest, tris, [pose], ["stretch"], up="z")
    face = frame.to_face(rest)
    assert np.abs(face[:, 0]).max() <= 1.0  # every triangle inside the box, left to right
    assert frame.half[0] > 80.0


def test_a_pose_that_only_moves_the_head_deforms_nothing():
    """A translated head: no edge changes, no face region, the upper skin is framed (and poses
    given without names are fine)."""
    frame = detect_face_frame(GRID, GRID_TRIS, [GRID + np.array([0.5, 0.2, 0.1])])
    assert frame.how == (
        "up +Z (the longer of the Y and Z extents; give --up to choose); how sure of up: "
        "unsure, 0.10; no "
        "key pose deforms the skin: the face is taken to be the upper skin; "
        "front -Y (the usual convention with that up axis)"
    )


def test_a_face_of_one_skin_point_gets_a_tiny_box():
    """Only one vertex is skin: the box has no extent, so it is a thousandth of the face's
    size each way — the size of a single point taken as 1."""
    rest = np.array([[0, 0, 0], [5, 0, 0], [0, 7, 0], [2, 3, 4]], np.float64)
    frame = detect_face_frame(rest, np.array([[0, 1, 2]]), skin=np.array([0, 0, 0, 1]), up="y")
    np.testing.assert_allclose(frame.half, [1e-3, 1e-3, 1e-3])
    np.testing.assert_allclose(frame.centre, [2, 3, 4])
    assert frame.mirror_plane == 2.0


# --------------------------------------------------------------------------------------------
# Up from the extents and the poses
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("z_extent", "up"),
    [
        (1.0, (0.0, 1.0, 0.0)),
        (1.001, (0.0, 1.0, 0.0)),
        (1.0005, (0.0, 1.0, 0.0)),
        (1.002, (0.0, 0.0, 1.0)),
    ],
)
def test_z_is_up_only_when_clearly_the_longer_extent(z_extent: float, up: tuple[float, ...]):
    """Y wins ties and near-ties: Z must be more than 0.1 % longer than Y."""
    rest = np.array([[0, 0, 0], [1, 1, 0], [0, 0, z_extent], [1, 0.5, 0.5]], np.float64)
    frame = detect_face_frame(rest, np.array([[0, 1, 2]]))
    assert frame.up == up


def test_the_mirror_axis_is_the_model_axis_along_left():
    """X up: the face looks toward +Z and its left is -Y, so masks mirror across Y, through
    the middle of the skin."""
    rest = np.array([[0, 1, 0], [2, 5, 0], [1, 3, 3]], np.float64)
    frame = detect_face_frame(rest, np.array([[0, 1, 2]]), up="x")
    assert frame.left == (0.0, -1.0, 0.0)
    assert frame.mirror_axis == 1
    assert frame.mirror_plane == 3.0


def test_a_pose_that_says_nothing_does_not_stop_the_vote():
    """jawLeft (no direction) before browInnerUp: browInnerUp still votes."""
    poses = [_lift(GRID, BOTTOM, (0.5, 0, 0)), _lift(GRID, TOP, (0, 0, 0.5))]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, ["jawLeft", "browInnerUp"])
    assert frame.how.startswith("up +Z (from the motion of browInnerUp); ")


def test_motion_under_a_hundred_thousandth_of_the_face_does_not_vote():
    """eyeWideLeft moving one vertex 1e-5 sideways (face size √8 ≈ 2.8: under 2.8e-5) is
    noise and does not vote; browInnerUp after it does."""
    poses = [_lift(GRID, [4], (1e-5, 0, 0)), _lift(GRID, TOP, (0, 0, 0.5))]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, ["eyeWideLeft", "browInnerUp"])
    assert frame.up == (0.0, 0.0, 1.0)
    assert frame.how.startswith("up +Z (from the motion of browInnerUp); ")


def test_motion_of_a_face_with_no_skin_does_not_vote():
    """Every vertex marked not-face: the named pose moves no skin; up from the extents."""
    frame = detect_face_frame(
        GRID, GRID_TRIS, [_lift(GRID, TOP, (0, 0, 0.5))], ["browInnerUp"], skin=np.zeros(9)
    )
    assert frame.how.startswith("up +Z (the longer of the Y and Z extents; give --up to choose); ")


def test_motion_that_cancels_out_does_not_vote():
    """browInnerUp pulling the top corners apart (mean motion zero): no direction to vote
    for, so up comes from the extents."""
    pose = _lift(_lift(GRID, [6], (-0.5, 0, 0)), [8], (0.5, 0, 0))
    frame = detect_face_frame(GRID, GRID_TRIS, [pose], ["browInnerUp"])
    assert frame.how.startswith("up +Z (the longer of the Y and Z extents; give --up to choose); ")


def test_only_motion_over_a_fifth_of_the_largest_is_averaged():
    """browInnerUp lifts one vertex by 5 and slides six others by exactly 1 (a fifth): only
    the lift is averaged, so +Z is up, not +X."""
    pose = _lift(GRID, [7], (0, 0, 5.0))
    pose = _lift(pose, [0, 1, 2, 3, 4, 5], (1.0, 0, 0))
    frame = detect_face_frame(GRID, GRID_TRIS, [pose], ["browInnerUp"])
    assert frame.up == (0.0, 0.0, 1.0)


def test_three_voting_poses_are_all_named_without_an_ellipsis():
    names = ["browInnerUp", "eyeWideLeft", "eyeWideRight"]
    poses = [_lift(GRID, TOP, (0, 0, 0.5 + 0.1 * i)) for i in range(3)]
    frame = detect_face_frame(GRID, GRID_TRIS, poses, names)
    assert frame.how.startswith(
        "up +Z (from the motion of browInnerUp, eyeWideLeft, eyeWideRight); "
    )


# --------------------------------------------------------------------------------------------
# Front
# --------------------------------------------------------------------------------------------


def _face_and_head(
    face: np.ndarray, head: np.ndarray, tris: np.ndarray = GRID_TRIS
) -> tuple[np.ndarray, np.ndarray]:
    """The face sheet (deformed by pulling its bottom row down) and still head points."""
    rest = np.vstack([face, head])
    return rest, _lift(rest, BOTTOM, (0, 0, -0.5))


def test_normals_that_cancel_exactly_leave_the_front_to_where_the_face_sits():
    """A two-sided face sheet (each triangle twice, once each way round) at y = -1 on a head
    whose back is at y = +1: its normals sum to zero, so the face's place says -Y."""
    face = GRID + np.array([0.0, -1.0, 0.0])
    head = np.array([[0, 1, 0], [1, 1, 1], [2, 1, 2]], np.float64)
    rest, pose = _face_and_head(face, head)
    tris = np.vstack([GRID_TRIS, GRID_TRIS[:, [0, 2, 1]]])
    frame = detect_face_frame(rest, tris, [pose], ["stretch"], up="z")
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (where the face sits on the head)")


def _tilted_flat_face(scale: float, tilt: float) -> FaceFrame:
    """A face sheet lying flat (facing up) at y -2 … 0 in front of head points at y = 1, its
    upper rows raised by ``tilt`` (relative to its size) so it leans slightly toward -Y."""
    sheet = np.array([[x, y - 2, 0] for y in (0, 1, 2) for x in (0, 1, 2)], np.float64)
    head = np.array([[0, 1, 0], [1, 1, 0], [2, 1, 0]], np.float64)
    rest = np.vstack([sheet, head]) * scale
    rest[3:9, 2] += tilt * scale
    pose = _lift(rest, BOTTOM, (0, -0.5 * scale, 0))
    return detect_face_frame(rest, GRID_TRIS, [pose], ["stretch"], up="z")


@pytest.mark.parametrize("scale", [100.0, 1.0, 0.01])
@pytest.mark.parametrize(
    ("tilt", "reason"),
    [
        (1e-10, "where the face sits on the head"),
        (1e-7, "the way the face's surface faces"),
    ],
)
def test_a_flat_face_is_flat_up_to_a_billionth_of_a_tilt_at_any_scale(
    scale: float, tilt: float, reason: str
):
    """A lean of a ten-billionth is rounding (the face is flat, fronted by where it sits); a
    lean of a ten-millionth is real (fronted by its surface) — in any units."""
    frame = _tilted_flat_face(scale, tilt)
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith(f"; front -Y ({reason})")


def test_a_flat_face_below_the_head_is_fronted_horizontally():
    """A flat face (facing up) in front of and far below the rest of the head: where it sits
    counts only horizontally, so the front is -Y, not tipped downward."""
    sheet = np.array([[x, y - 2, 0] for y in (0, 1, 2) for x in (0, 1, 2)], np.float64)
    head = np.array([[0, 1, 5], [1, 1, 5], [2, 1, 5]], np.float64)
    rest = np.vstack([sheet, head])
    pose = _lift(rest, BOTTOM, (0, -0.5, 0))
    frame = detect_face_frame(rest, GRID_TRIS, [pose], ["stretch"], up="z")
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (where the face sits on the head)")


def test_parts_that_are_not_skin_do_not_move_the_head():
    """A lone face sheet facing -Y with eyes (not skin) far in front of it: the head is the
    skin, the face sits at its middle, and its surface says -Y — not reversed."""
    eyes = np.array([[0, -10, 1], [2, -10, 1]], np.float64)
    rest, pose = _face_and_head(GRID, eyes)
    skin = np.r_[np.ones(9), np.zeros(2)]
    frame = detect_face_frame(rest, GRID_TRIS, [pose], ["jawOpen"], skin=skin)
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (the way the face's surface faces)")


def test_a_face_off_to_the_side_of_the_head_keeps_its_surface_front():
    """The face sits to the head's +X side (the rest of the skin at x = -10), across from
    where its normals point: neither behind nor in front, so no reversal."""
    side = np.array([[-10, 0, 0], [-10, 0, 1], [-10, 0, 2]], np.float64)
    rest, pose = _face_and_head(GRID, side)
    frame = detect_face_frame(rest, GRID_TRIS, [pose], ["jawOpen"])
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (the way the face's surface faces)")


@pytest.mark.parametrize("scale", [0.01, 0.1])
def test_inward_normals_are_caught_on_a_small_head(scale: float):
    """A head in metres (a hundredth the size) wound inside out: still reversed to -Y."""
    face = GRID + np.array([0.0, -1.0, 0.0])
    back = np.array([[2 - x, 1, z] for z in (0, 1, 2) for x in (0, 1, 2)], np.float64)
    rest = np.vstack([face, back]) * scale
    tris = np.vstack([GRID_TRIS, GRID_TRIS + 9])[:, ::-1]
    pose = _lift(rest, BOTTOM, (0, 0, -0.5 * scale))
    frame = detect_face_frame(rest, tris, [pose], ["jawOpen"])
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (the surface's normals point inward; taken reversed)")


def test_inward_normals_are_caught_on_a_head_far_from_the_origin():
    """The same inside-out head placed ten million units along x: the face's offset from the
    head's middle is measured against the head's size, not its distance from the origin."""
    face = GRID + np.array([0.0, -1.0, 0.0])
    back = np.array([[2 - x, 1, z] for z in (0, 1, 2) for x in (0, 1, 2)], np.float64)
    rest = np.vstack([face, back]) + np.array([1e7, 0.0, 0.0])
    tris = np.vstack([GRID_TRIS, GRID_TRIS + 9])[:, ::-1]
    pose = _lift(rest, BOTTOM, (0, 0, -0.5))
    frame = detect_face_frame(rest, tris, [pose], ["jawOpen"])
    assert frame.front == (0.0, -1.0, 0.0)
    assert "normals point inward" in frame.how


def test_a_tiny_asymmetry_of_a_big_head_is_not_an_offset():
    """A face sheet in millimetres (2 m across) with one still skin point a micrometre in
    front: the face sits at the head's middle within a millionth, its surface says -Y."""
    rest = GRID * 1000.0
    point = np.array([[1000.0, -1e-3, 1000.0]])
    full = np.vstack([rest, point])
    pose = _lift(full, BOTTOM, (0, 0, -500.0))
    frame = detect_face_frame(full, GRID_TRIS, [pose], ["jawOpen"])
    assert frame.front == (0.0, -1.0, 0.0)
    assert frame.how.endswith("; front -Y (the way the face's surface faces)")


@pytest.mark.parametrize(
    ("up", "sheet", "front", "left", "name"),
    [
        (
            "x",
            np.array([[0, y, z] for z in (0, 1, 2) for y in (0, 1, 2)], np.float64),
            (0.0, 0.0, 1.0),
            (0.0, -1.0, 0.0),
            "+Z",
        ),
        (
            "-x",
            np.array([[0, y, z] for z in (0, 1, 2) for y in (0, 1, 2)], np.float64),
            (0.0, 0.0, -1.0),
            (0.0, -1.0, 0.0),
            "-Z",
        ),
        (
            "y",
            np.array([[x, 0, z] for z in (0, 1, 2) for x in (0, 1, 2)], np.float64),
            (0.0, 0.0, -1.0),
            (-1.0, 0.0, 0.0),
            "-Z",
        ),
    ],
)
def test_a_face_with_nothing_to_go_by_gets_a_side_perpendicular_to_up(
    up: str, sheet: np.ndarray, front: tuple[float, ...], left: tuple[float, ...], name: str
):
    """A sheet lying across the up axis, deformed all alike: the front is up × X (up × Y
    when up is along X), a horizontal axis."""
    frame = detect_face_frame(sheet, GRID_TRIS, [sheet * 2.0], ["grow"], up=up)
    assert frame.front == front
    assert frame.left == left
    assert frame.how.endswith(f"; front {name} (nothing to go by; an arbitrary side)")


# --------------------------------------------------------------------------------------------
# The box's corners and aiming the camera
# --------------------------------------------------------------------------------------------

FRAME = FaceFrame(
    (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0), (1.0, 2.0, 3.0), (0.5, 1.0, 2.0), "given"
)


def test_the_corners_are_all_eight_of_the_box():
    corners = FRAME.corners()
    signs = {tuple(row) for row in np.rint(FRAME.to_face(corners)).astype(int)}
    assert signs == {(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)}
    np.testing.assert_allclose(corners.min(axis=0), [0.5, 0.0, 2.0])
    np.testing.assert_allclose(corners.max(axis=0), [1.5, 4.0, 4.0])


def test_aim_frames_the_face_box_by_default():
    """Aimed with no frame named, the camera turns to the face's axes and centres on the face
    box (the project is not needed when the frame is given)."""
    camera = OrbitCamera()
    assert aim(camera, None, face=FRAME) is FRAME
    np.testing.assert_array_equal(camera.basis, FRAME.basis())
    np.testing.assert_allclose(camera.target, [1.0, 2.0, 3.0])
    named = OrbitCamera()
    aim(named, None, "face", face=FRAME)
    np.testing.assert_allclose(named.target, camera.target)
    assert named.distance == camera.distance


def test_aim_frames_the_whole_mesh_otherwise():
    class _Mesh:
        rest = np.zeros((0, 3))  # no vertex stands before the face (see test_framing.py)

        def bounds(self) -> tuple[np.ndarray, np.ndarray]:
            return np.array([-10.0, -10.0, -10.0]), np.array([10.0, 30.0, 10.0])

    class _Project:
        mesh = _Mesh()

    camera = OrbitCamera()
    aim(camera, _Project(), "all", face=FRAME)
    np.testing.assert_allclose(camera.target, [0.0, 10.0, 0.0])
    face_camera = OrbitCamera()
    aim(face_camera, _Project(), "face", face=FRAME)
    assert camera.distance > 3 * face_camera.distance
