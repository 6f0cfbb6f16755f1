"""Technique 2's per-vertex slots: which areas a vertex keeps, with their cones and maps."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.wdv import SLOTS, WdvArea, WdvSetup, wrinkle_directions

pytestmark = pytest.mark.core


def area(name: str, lengths: list[float], **kwargs) -> WdvArea:
    lengths = np.array(lengths, np.float32)
    directions = np.zeros((len(lengths), 3), np.float32)
    directions[lengths > 0, 0] = 1.0
    return WdvArea(name, "pose", directions, lengths, **kwargs)


def test_a_vertex_in_more_areas_than_slots_keeps_the_longest_motions_in_any_order():
    lengths = [0.1, 0.5, 0.3, 0.2, 0.4]  # vertex 0 is in five areas; vertex 1 in none
    areas = [area(f"a{i}", [v, 0.0]) for i, v in enumerate(lengths)]
    forward = WdvSetup(areas).pack_slots(2)
    backward = WdvSetup(areas[::-1]).pack_slots(2)
    assert SLOTS == 4
    np.testing.assert_allclose(sorted(forward.dirs[0, :, 3]), [0.2, 0.3, 0.4, 0.5])  # 0.1 out
    assert np.allclose(sorted(backward.dirs[0, :, 3]), sorted(forward.dirs[0, :, 3]))
    assert not forward.dirs[1].any() and not forward.cones[1].any()


def test_slots_carry_each_areas_painted_cone_and_map_index():
    painted = area("painted", [1.0, 1.0], cone_angle_deg=20.0, wrinkle_map="smile",
                   cone_angles_deg=np.array([0.0, 5.0], np.float32))
    plain = area("plain", [0.0, 2.0], cone_angle_deg=30.0)
    slots = WdvSetup([painted, plain]).pack_slots(2, lambda name: 1 if name == "smile" else 0)
    np.testing.assert_allclose(np.degrees(slots.cones[0, 0]), 20.0)  # unpainted: the area's
    assert slots.maps[0, 0] == 1 and slots.dirs[0, 1:].sum() == 0
    # vertex 1: "plain" moves further, so it takes the first slot
    np.testing.assert_allclose(np.degrees(slots.cones[1, :2]), [30.0, 5.0], rtol=1e-6)
    assert slots.maps[1, :2].tolist() == [0, 1]


def test_muted_areas_take_no_slot():
    muted = area("muted", [1.0], enabled=False)
    assert not WdvSetup([muted]).pack_slots(1).dirs.any()


# --- by hand: types the shader buffers rely on, thresholds relative to the face, slot values ---


def test_areas_hold_float32_whatever_they_are_given():
    area = WdvArea("a", "p", np.ones((2, 3)), np.ones(2), cone_angles_deg=np.array([0.0, 0.5]))
    assert area.directions.dtype == area.lengths.dtype == area.cone_angles_deg.dtype == np.float32
    cones = area.vertex_cones_deg()
    assert cones.dtype == np.float32
    assert cones.tolist() == [20.0, 0.5]  # 0 = the area's angle; half a degree is painted
    plain = WdvArea.empty("b", "p", 3, cone_angle_deg=12.5)
    assert plain.directions.shape == (3, 3) and plain.lengths.shape == (3,)
    assert plain.directions.dtype == plain.lengths.dtype == np.float32
    assert plain.vertex_cones_deg().dtype == np.float32
    assert plain.vertex_cones_deg().tolist() == [12.5] * 3 and not plain.authored.any()


def test_still_is_judged_against_the_face_size_not_its_distance_from_the_origin():
    """A face 1 unit across, 1000 units from the origin: a 5e-6 motion moves (more than 1e-6
    of the face's size); the same face in millimetres (1000 across) needs 1e-3."""
    rest = np.array([[1000, 0, 0], [1001, 0, 0], [1000, 1, 0]], np.float64)
    target = rest.copy()
    target[0, 1] += 5e-6
    result = wrinkle_directions(rest, target, [0, 1])
    assert result.lengths.dtype == result.directions.dtype == np.float32
    assert result.lengths[0] > 0 and result.still.tolist() == [1]
    mm = rest * 1000.0
    jitter = mm.copy()
    jitter[0, 1] += 5e-4  # 5e-7 of the face's 1000 mm: still
    assert wrinkle_directions(mm, jitter, [0]).still.tolist() == [0]
    point = np.zeros((2, 3))  # no extent at all: sizes are measured in units
    moved = point.copy()
    moved[0, 0] = 1.5e-6
    assert wrinkle_directions(point, moved, [0]).still.tolist() == []


def test_slots_hold_the_authored_values_by_hand():
    dirs = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 0]], np.float32)
    area = WdvArea("a", "p", dirs, np.array([0.5, 2.0, 0.0]), cone_angle_deg=30.0,
                   cone_angles_deg=np.array([0.0, 60.0, 0.0]), wrinkle_map="second")
    slots = WdvSetup([area]).pack_slots(3)
    assert slots.dirs.dtype == slots.cones.dtype == slots.maps.dtype == np.float32
    np.testing.assert_array_equal(slots.dirs[:, 0], [[1, 0, 0, 0.5], [0, 1, 0, 2.0],
                                                     [0, 0, 0, 0]])
    np.testing.assert_allclose(slots.cones[:, 0], np.radians([30.0, 60.0, 0.0]), rtol=1e-6)
    assert slots.maps[:, 0].tolist() == [0, 0, 0]  # no map index given: the first map
    mapped = WdvSetup([area]).pack_slots(3, {"second": 2}.get)
    assert mapped.maps[:, 0].tolist() == [2, 2, 0]  # only where the area is authored
    assert not slots.dirs[:, 1:].any() and not slots.cones[:, 1:].any()
