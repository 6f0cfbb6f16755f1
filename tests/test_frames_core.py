"""Small pieces of the face's frame: the frame's saved form, the list of region names, the up
axis a user types, and the frame of a head without deforming poses (the axis conventions)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.mesh.face_regions import region_name, region_names
from studio.core.setup.face_frame import (
    FaceFrame,
    _conventional_front,
    axis_name,
    detect_face_frame,
    parse_axis,
)

pytestmark = pytest.mark.core

# a Z-up head facing −Y (Blender's convention), its face box off the origin
BLENDER_FRAME = FaceFrame(left=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), front=(0.0, -1.0, 0.0),
                          centre=(0.5, -3.0, 160.0), half=(80.0, 110.0, 60.0),
                          how="up +Z (as given); front -Y (the usual convention)",
                          mirror_axis=0, mirror_plane=0.25)


def test_face_frame_to_dict_names_every_field_with_plain_lists():
    """The saved frame holds every field under its own name, vectors as JSON lists."""
    data = BLENDER_FRAME.to_dict()
    assert data == {"left": [1.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0], "front": [0.0, -1.0, 0.0],
                    "centre": [0.5, -3.0, 160.0], "half": [80.0, 110.0, 60.0],
                    "how": "up +Z (as given); front -Y (the usual convention)",
                    "mirror_axis": 0, "mirror_plane": 0.25}
    assert json.loads(json.dumps(data)) == data


def test_face_frame_reads_back_from_its_dict():
    """A frame rebuilt from its saved form (vectors back to tuples) is the same frame and puts
    points at the same face coordinates."""
    data = BLENDER_FRAME.to_dict()
    vectors = ("left", "up", "front", "centre", "half")
    back = FaceFrame(**{k: tuple(v) if k in vectors else v for k, v in data.items()})
    assert back == BLENDER_FRAME
    chin_tip = np.array([[0.5, -63.0, 50.0]])  # 60 in front of, 110 below the centre
    np.testing.assert_allclose(back.to_face(chin_tip), [[0.0, -1.0, 1.0]])


def test_region_names_list_every_name_a_point_can_get():
    """The list holds the central regions and both sides of each sided one, once each, and every
    name ``region_name`` gives is in it."""
    names = region_names()
    assert len(names) == len(set(names)) == 6 + 2 * 9
    for name in ("forehead", "between the brows", "nose", "upper lip", "chin", "lower lip",
                 "left brow", "right brow", "left nasolabial fold", "right jaw",
                 "left upper eyelid", "right upper eyelid"):
        assert name in names
    grid = np.linspace(-1.2, 1.2, 13)
    assert {region_name(float(x), float(y)) for x in grid for y in grid} <= set(names)


def test_region_names_is_a_copy_the_caller_may_change():
    """Changing the returned list does not change what later calls return."""
    names = region_names()
    names.clear()
    assert "forehead" in region_names()


# --- the up axis a user types --------------------------------------------------------------------

@pytest.mark.parametrize(("text", "expected"), [("y", (0, 1, 0)), ("+x", (1, 0, 0)),
                                                ("-Z", (0, 0, -1)), (" -y ", (0, -1, 0)),
                                                ("Z", (0, 0, 1))])
def test_parse_axis_reads_signed_and_unsigned_axes(text, expected):
    """``--up`` takes x, y or z, with or without a sign, any case: a float unit vector."""
    axis = parse_axis(text)
    assert axis.dtype == np.float64
    assert axis.tolist() == list(expected)


@pytest.mark.parametrize("text", ["", "+", "++y", "w", "xy", "-+z"])
def test_parse_axis_refuses_anything_else_and_says_what_is_allowed(text):
    """Anything but a (signed) axis letter is refused with the list of accepted values."""
    with pytest.raises(StudioError, match=r"is not an axis \(use x, y, z, -x, -y or -z\)"):
        parse_axis(text)


# --- a head without deforming poses --------------------------------------------------------------

NO_TRIANGLES = np.zeros((0, 3), np.int64)


@pytest.mark.parametrize(("up", "front"), [("+y", (0, 0, 1)), ("-y", (0, 0, -1)),
                                           ("+z", (0, -1, 0)), ("-z", (0, 1, 0)),
                                           ("+x", (0, 0, 1)), ("-x", (0, 0, 1))])
def test_without_poses_the_front_follows_the_up_axis_convention(up, front):
    """Y up faces +Z (glTF, Maya), Z up faces −Y (Blender), the other signs mirror that, and an
    X up faces +Z; the frame says it used the convention and stays right-handed."""
    rest = np.random.default_rng(0).normal(size=(20, 3))
    frame = detect_face_frame(rest, NO_TRIANGLES, up=up)
    assert frame.up == tuple(float(v) for v in parse_axis(up))
    assert frame.front == tuple(float(v) for v in front)
    assert f"front {axis_name(front)} (the usual convention with that up axis)" in frame.how
    np.testing.assert_allclose(np.cross(frame.up, frame.front), frame.left)


def test_without_poses_the_face_box_is_the_upper_half_of_the_skin():
    """The face is taken to be the skin from its median height up (the median vertex included):
    a body below and props that are not skin change neither the box nor its centre."""
    heights = np.arange(11.0)  # skin: a column 0 … 10 high, median 5
    skin_column = np.c_[np.zeros(11), heights, np.zeros(11)]
    body = np.c_[np.zeros(11), heights - 40.0, np.zeros(11)]  # not skin, far below
    props = np.array([[50.0, 9.0, 0.0], [-50.0, 9.0, 0.0], [0.0, 9.0, 30.0]])  # not skin, high
    rest = np.r_[skin_column, body, props]
    skin = np.r_[np.ones(11), np.zeros(11), np.zeros(3)]
    frame = detect_face_frame(rest, NO_TRIANGLES, skin=skin, up="y")
    # the region is heights 5 … 10: its 1st and 99th percentiles are 5.05 and 9.95
    np.testing.assert_allclose(frame.centre, [0.0, 7.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(frame.half[1], (9.95 - 5.05) / 2.0 * 1.12)
    assert frame.half[0] == frame.half[2] == pytest.approx(1e-3 * 10.0)  # the smallest box


# --- the last-resort front for an up that is no axis ---------------------------------------------

@pytest.mark.parametrize(("up", "across"), [((0.48, 0.6, 0.64), (1.0, 0.0, 0.0)),
                                            ((0.28, 0.96, 0.0), (1.0, 0.0, 0.0)),
                                            ((0.96, 0.0, 0.28), (0.0, 1.0, 0.0)),
                                            ((-0.96, 0.28, 0.0), (0.0, 1.0, 0.0))])
def test_an_up_that_is_no_axis_gets_an_arbitrary_unit_front_square_to_it(up, across):
    """No convention applies: the front is up × X (up × Y when up is nearly X), normalised, and
    the reason says it is arbitrary."""
    front, reason = _conventional_front(np.array(up))
    expected = np.cross(up, across)
    np.testing.assert_allclose(front, expected / np.linalg.norm(expected), atol=1e-12)
    assert reason == "nothing to go by; an arbitrary side"
