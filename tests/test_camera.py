"""The orbit camera's interaction (orbit, pan, zoom), its picking rays and its saved form, checked
against hand-computed geometry of a camera looking down the face's front axis."""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.core.mesh.camera import OrbitCamera

pytestmark = pytest.mark.core


def front_camera(**kwargs) -> OrbitCamera:
    """A camera straight in front of the face (eye on +Z of the target, looking toward −Z)."""
    return OrbitCamera(**{"yaw": 0.0, "pitch": 0.0, **kwargs})


# --- orbit -----------------------------------------------------------------------------------

def test_orbit_adds_to_yaw_and_pitch():
    """Orbiting turns the camera by exactly the asked angles."""
    cam = front_camera(yaw=30.0, pitch=5.0)
    cam.orbit(20.0, 10.0)
    assert cam.yaw == pytest.approx(50.0)
    assert cam.pitch == pytest.approx(15.0)
    assert isinstance(cam.pitch, float)


def test_orbit_by_90_degrees_puts_the_eye_on_the_faces_left():
    """A quarter turn of yaw from the front moves the eye onto +X at the same distance."""
    cam = front_camera(distance=4.0, target=np.array([1.0, 2.0, 3.0]))
    cam.orbit(90.0, 0.0)
    np.testing.assert_allclose(cam.eye(), [5.0, 2.0, 3.0], atol=1e-12)


def test_orbit_wraps_yaw_into_one_turn():
    """Yaw stays within [0, 360): 350° + 20° is 10°, and −30° from 10° is 340°."""
    cam = front_camera(yaw=350.0)
    cam.orbit(20.0, 0.0)
    assert cam.yaw == pytest.approx(10.0)
    cam.orbit(-30.0, 0.0)
    assert cam.yaw == pytest.approx(340.0)


@pytest.mark.parametrize(("start", "step", "expected"), [(80.0, 30.0, 89.0), (-80.0, -30.0, -89.0),
                                                          (88.5, 0.4, 88.9), (-88.5, -0.4, -88.9)])
def test_orbit_stops_pitch_just_short_of_the_poles(start, step, expected):
    """Pitch is held within ±89° so the view never flips over the top or the bottom."""
    cam = front_camera(pitch=start)
    cam.orbit(0.0, step)
    assert cam.pitch == pytest.approx(expected)


# --- pan -------------------------------------------------------------------------------------

def test_pan_moves_the_target_right_and_up_by_fractions_of_the_view_height():
    """Panning by (dx, dy) moves the target along screen right and up, scaled by the height of
    the view at the target's distance (2 · distance · tan(fov/2))."""
    cam = front_camera(distance=4.0, fov_y=60.0, target=np.array([1.0, 2.0, 3.0]))
    height = 2.0 * 4.0 * math.tan(math.radians(30.0))
    cam.pan(0.25, 0.5)
    np.testing.assert_allclose(cam.target, [1.0 + 0.25 * height, 2.0 + 0.5 * height, 3.0],
                               atol=1e-12)
    assert cam.distance == 4.0 and cam.yaw == 0.0 and cam.pitch == 0.0


def test_pan_follows_the_turned_camera():
    """Seen from the face's left (yaw 90°), screen right is −Z and a pan left/down is negative."""
    cam = front_camera(yaw=90.0, distance=2.0, fov_y=90.0)  # view height 4 at the target
    cam.pan(0.5, -0.25)
    np.testing.assert_allclose(cam.target, [0.0, -1.0, -2.0], atol=1e-12)


# --- zoom ------------------------------------------------------------------------------------

def test_zoom_multiplies_the_distance():
    """A factor below 1 moves closer, above 1 moves away, by exactly that ratio."""
    cam = front_camera(distance=5.0, radius=2.0)
    cam.zoom(0.5)
    assert cam.distance == pytest.approx(2.5)
    assert isinstance(cam.distance, float)
    cam.zoom(3.0)
    assert cam.distance == pytest.approx(7.5)


def test_zoom_is_held_between_a_twentieth_and_a_hundred_radii():
    """Zooming cannot pass into the model nor lose it in the distance."""
    cam = front_camera(distance=5.0, radius=2.0)
    cam.zoom(1e-4)
    assert cam.distance == pytest.approx(0.1)
    cam = front_camera(distance=5.0, radius=2.0)
    cam.zoom(1e4)
    assert cam.distance == pytest.approx(200.0)


# --- picking rays ----------------------------------------------------------------------------

def ray_camera() -> OrbitCamera:
    """Eye at (0, 0, 6) looking at the origin, 90° vertical field of view; the clipping planes
    are 2 and 10 from the eye (distance 6 ∓ 2 · radius 2), so the near plane is z = 4."""
    return front_camera(distance=6.0, radius=2.0, fov_y=90.0)


def test_ray_through_the_centre_pixel_runs_along_the_view_axis():
    """The middle of the viewport looks straight at the target, starting on the near plane."""
    origin, direction = ray_camera().ray(100.0, 50.0, 200, 100)
    np.testing.assert_allclose(origin, [0.0, 0.0, 4.0], atol=1e-9)
    np.testing.assert_allclose(direction, [0.0, 0.0, -1.0], atol=1e-9)


@pytest.mark.parametrize(("x", "y", "corner"), [(0.0, 0.0, (-4.0, 2.0)),
                                                (200.0, 100.0, (4.0, -2.0)),
                                                (200.0, 0.0, (4.0, 2.0))])
def test_ray_through_a_corner_pixel_leaves_the_eye_through_the_near_planes_corner(x, y, corner):
    """Pixel (0, 0) is the top left: at the near plane (2 from the eye, tan 45° = 1) the view is
    2 high each way and, for a 2:1 viewport, 4 wide each way."""
    origin, direction = ray_camera().ray(x, y, 200, 100)
    np.testing.assert_allclose(origin, [corner[0], corner[1], 4.0], atol=1e-9)
    expected = np.array([corner[0], corner[1], -2.0])  # from the eye (0, 0, 6) to the origin
    np.testing.assert_allclose(direction, expected / np.linalg.norm(expected), atol=1e-9)
    assert np.linalg.norm(direction) == pytest.approx(1.0)


def test_ray_hits_the_point_that_projects_to_its_pixel():
    """A world point projected to a pixel lies on the ray cast back through that pixel, for a
    camera turned and moved off the axes."""
    cam = OrbitCamera(target=np.array([0.3, -0.2, 0.1]), distance=3.0, yaw=35.0, pitch=-20.0,
                      fov_y=40.0, radius=0.8)
    point = np.array([0.5, 0.1, 0.4])
    (px,), _ = cam.project(point, 320, 240)
    origin, direction = cam.ray(px[0], px[1], 320, 240)
    to_point = point - origin
    along = float(to_point @ direction)
    assert along > 0.0
    np.testing.assert_allclose(origin + along * direction, point, atol=1e-9)


# --- saved form ------------------------------------------------------------------------------

def test_to_dict_is_plain_json_values_and_round_trips():
    """The saved camera is plain floats under fixed keys, and reads back to the same view."""
    # columns left, up, front of a Z-up face looking toward −Y
    basis = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    cam = OrbitCamera(target=np.array([1.0, -2.0, 0.5], np.float32), distance=7.5, yaw=33.0,
                      pitch=-12.0, fov_y=42.0, radius=1.25, basis=basis)
    data = cam.to_dict()
    assert data == {"target": [1.0, -2.0, 0.5], "distance": 7.5, "yaw": 33.0, "pitch": -12.0,
                    "fov_y": 42.0, "radius": 1.25,
                    "basis": [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]}
    assert all(type(v) is float for v in data["target"])
    assert all(type(v) is float for row in data["basis"] for v in row)
    back = OrbitCamera.from_dict(data)
    np.testing.assert_allclose(back.target, cam.target)
    np.testing.assert_allclose(back.basis, basis)
    np.testing.assert_allclose(back.eye(), cam.eye(), atol=1e-12)
    np.testing.assert_allclose(back.view_projection(64, 48), cam.view_projection(64, 48),
                               atol=1e-12)


def test_from_dict_of_nothing_is_the_default_camera():
    """An empty or partial saved camera fills in the defaults (target at the origin)."""
    cam = OrbitCamera.from_dict({})
    default = OrbitCamera()
    assert cam.target.tolist() == [0.0, 0.0, 0.0]
    assert cam.to_dict() == default.to_dict()
    partial = OrbitCamera.from_dict({"yaw": 90, "radius": "2.5"})
    assert partial.yaw == 90.0 and type(partial.yaw) is float and partial.radius == 2.5
    assert partial.target.tolist() == [0.0, 0.0, 0.0] and partial.distance == default.distance


@pytest.mark.parametrize("damaged", [
    [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],  # sheared
    [[1.2, 0.0, 0.0], [0.0, 1.2, 0.0], [0.0, 0.0, 1.2]],  # scaled
    [[1.0, 0.0], [0.0, 1.0]],  # the wrong shape
    [[float("nan"), 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],  # not finite
])
def test_from_dict_refuses_a_basis_that_is_no_rotation(damaged):
    """A damaged basis in a saved camera falls back to the default axes."""
    cam = OrbitCamera.from_dict({"basis": damaged, "yaw": 10.0})
    assert cam.basis.tolist() == np.eye(3).tolist()
    assert cam.yaw == 10.0


def test_from_dict_takes_a_rotation_saved_with_six_decimals():
    """A rotation written with rounded values (a few 1e-7 off orthonormal) is still taken."""
    a, b = math.radians(30.0), math.radians(50.0)
    rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0],
                   [0.0, 0.0, 1.0]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(b), -math.sin(b)],
                   [0.0, math.sin(b), math.cos(b)]])
    rounded = np.round(rz @ rx, 6)
    assert not np.allclose(rounded.T @ rounded, np.eye(3), rtol=0.0, atol=1e-8)
    cam = OrbitCamera.from_dict({"basis": rounded.tolist()})
    np.testing.assert_array_equal(cam.basis, rounded)


# --- direction, view and projection ------------------------------------------------------------

@pytest.mark.parametrize(("yaw", "pitch", "expected"), [
    (0.0, 0.0, (0.0, 0.0, 1.0)),
    (90.0, 0.0, (1.0, 0.0, 0.0)),
    (90.0, 60.0, (0.5, math.sqrt(3.0) / 2.0, 0.0)),
    (0.0, 60.0, (0.0, math.sqrt(3.0) / 2.0, 0.5)),
    (180.0, -30.0, (0.0, -0.5, -math.sqrt(3.0) / 2.0)),
])
def test_direction_follows_yaw_and_pitch(yaw, pitch, expected):
    """Yaw turns the eye toward the face's left (+X), pitch raises it; always a unit vector."""
    direction = front_camera(yaw=yaw, pitch=pitch).direction()
    np.testing.assert_allclose(direction, expected, atol=1e-12)


def test_direction_is_in_the_faces_own_axes():
    """For a Z-up head facing −Y, the front view looks from −Y, yaw 90° from +X, and +Z is up."""
    basis = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    np.testing.assert_allclose(front_camera(basis=basis).direction(), [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(front_camera(basis=basis, yaw=90.0).direction(), [1, 0, 0],
                               atol=1e-12)
    assert front_camera(basis=basis).up.tolist() == [0.0, 0.0, 1.0]


def test_the_view_matrix_of_a_camera_looking_down_from_above():
    """From 30° above, screen right stays +X, screen up leans back, and the target lies straight
    ahead at the camera's distance."""
    cam = front_camera(pitch=30.0, distance=2.0, target=np.array([1.0, 1.0, 1.0]))
    view = cam.view_matrix()
    s, c = 0.5, math.sqrt(3.0) / 2.0
    np.testing.assert_allclose(view[:3, :3], [[1, 0, 0], [0, c, -s], [0, s, c]], atol=1e-12)
    np.testing.assert_allclose(view @ [1.0, 1.0, 1.0, 1.0], [0, 0, -2, 1], atol=1e-12)
    np.testing.assert_allclose(view @ np.r_[cam.eye(), 1.0], [0, 0, 0, 1], atol=1e-12)


@pytest.mark.parametrize(("distance", "radius", "near", "far"), [
    (6.0, 2.0, 2.0, 10.0),  # outside the framed sphere: planes just around it
    (1.0, 1.0, 0.01, 3.0),  # inside it: a hundredth of the distance
    (0.005, 1.0, 1e-4, 2.005),  # right on the target: never closer than 1e-4
])
def test_clip_planes_hug_the_framed_sphere(distance, radius, near, far):
    """The near plane is 2 radii in front of the target but at least a hundredth of the
    distance (and 1e-4); the far plane is 2 radii behind it."""
    got = front_camera(distance=distance, radius=radius).clip_planes()
    assert got == pytest.approx((near, far))


def test_project_gives_pixels_and_view_depths():
    """Points in front of a 60° camera 6 away land on hand-computed pixels of a 200×100 view."""
    cam = front_camera(distance=6.0, radius=2.0, fov_y=60.0)
    f = 1.0 / math.tan(math.radians(30.0))  # 1.732…
    points = [[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 2]]
    px, depth = cam.project(points, 200, 100)
    np.testing.assert_allclose(px, [[100.0, 50.0], [100.0, (1.0 - f / 6.0) * 50.0],
                                    [(1.0 + f / 2.0 / 6.0) * 100.0, 50.0], [100.0, 50.0]],
                               atol=1e-9)
    np.testing.assert_allclose(depth, [6.0, 6.0, 6.0, 4.0], atol=1e-12)
    one, one_depth = cam.project(np.array([0, 1, 0]), 200, 100)
    assert one.shape == (1, 2) and one_depth.shape == (1,)


def test_a_collapsed_viewport_projects_as_if_one_pixel_high():
    """A viewport of height 0 (a minimised widget) does not divide by zero."""
    cam = front_camera()
    np.testing.assert_allclose(cam.view_projection(200, 0),
                               cam.projection_matrix(200.0) @ cam.view_matrix())
    assert np.isfinite(cam.view_projection(200, 0)).all()


# --- framing -------------------------------------------------------------------------------------

TAN30 = math.tan(math.radians(30.0))


def test_frame_centres_on_a_wide_box_and_backs_off_until_it_fits():
    """A box 4 wide, 2 high and 1.5 deep, seen from the front with a 60° view: the target is
    its centre, the radius half its diagonal, and the near corners fit with a 10 % margin."""
    cam = front_camera(fov_y=60.0)
    cam.frame([1, 2, 3], [5, 4, 4.5])
    np.testing.assert_allclose(cam.target, [3.0, 3.0, 3.75])
    assert cam.radius == pytest.approx(math.sqrt(22.25) / 2.0)
    assert cam.distance == pytest.approx(2.0 * 1.1 / TAN30 + 0.75)


def test_frame_fits_a_tall_box_by_its_height():
    """A box taller than wide is fitted by its height."""
    cam = front_camera(fov_y=60.0)
    cam.frame([0, 0, 0], [1, 6, 2], margin=1.25)
    np.testing.assert_allclose(cam.target, [0.5, 3.0, 1.0])
    assert cam.radius == pytest.approx(math.sqrt(41.0) / 2.0)
    assert cam.distance == pytest.approx(3.0 * 1.25 / TAN30 + 1.0)


def test_frame_fits_the_box_as_seen_from_the_current_direction():
    """Seen from the side (yaw 90°) the box's depth is across the view and its width is deep."""
    cam = front_camera(fov_y=60.0, yaw=90.0)
    cam.frame([1, 2, 3], [5, 4, 4.5])
    assert cam.distance == pytest.approx(1.0 * 1.1 / TAN30 + 2.0)


def test_frame_points_lets_the_nearest_wide_point_decide():
    """For points that are not a box, the distance is what the most demanding point needs: here
    the wide point nearest to the eye."""
    cam = front_camera(fov_y=60.0)
    cam.frame_points([[-2, 0, 0.75], [2, 0, 0.25], [0, 1, -0.75], [0, -1, -0.75]])
    np.testing.assert_allclose(cam.target, [0.0, 0.0, 0.0])
    assert cam.radius == pytest.approx(math.sqrt(22.25) / 2.0)
    assert cam.distance == pytest.approx(2.0 * 1.1 / TAN30 + 0.75)


def test_frame_a_small_head_and_a_single_point():
    """Framing works in any units: a head in metres gets a radius under one, and a single point
    a tiny positive radius and distance rather than zero."""
    cam = front_camera(fov_y=60.0)
    cam.frame([0.0, 0.0, 0.0], [0.2, 0.1, 0.1])
    assert cam.radius == pytest.approx(math.sqrt(0.06) / 2.0)
    assert cam.distance == pytest.approx(0.1 * 1.1 / TAN30 + 0.05)
    cam.frame_points([[1.0, 2.0, 3.0]])
    assert cam.target.tolist() == [1.0, 2.0, 3.0]
    assert cam.radius == pytest.approx(1e-6)
    assert cam.distance == pytest.approx(1e-7)
