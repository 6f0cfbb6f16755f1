"""Technique 2's per-vertex slots: which areas a vertex keeps, with their cones and maps."""

from __future__ import annotations

import numpy as np

from studio.core.wrinkles.wdv import SLOTS, WdvArea, WdvSetup


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
