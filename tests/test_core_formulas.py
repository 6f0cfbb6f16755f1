"""The numpy references of the shaders' formulas, checked by hand-computed cases.

``tests/test_gpu_reference.py`` holds the GPU to these references; this file holds the references
to the formulas themselves (technique 2's visibility, technique 1's composed weight), with numpy
only, so the fast tests that mutation testing runs (scripts/mutation.sh) pin them down too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose, PoseBlender, check_pose_topology, ease, interpolate
from studio.core.files.errors import MeshError
from studio.core.wrinkles.mask_sparse import (
    K,
    composed_weight,
    composed_weights,
    quantise,
    sparse_masks,
)
from studio.core.wrinkles.normalmap import flip_green, height_to_normal
from studio.core.wrinkles.wdv import (
    SLOTS,
    WdvArea,
    WdvSetup,
    WdvSlots,
    visibility,
    wrinkle_directions,
)

pytestmark = pytest.mark.core


def one_slot(direction, authored: float, cone_deg: float, wrinkle_map: int = 0,
             n: int = 1) -> WdvSlots:
    """``n`` vertices with the same single authored slot (the other slots unused)."""
    dirs = np.zeros((n, SLOTS, 4), np.float32)
    dirs[:, 0, :3] = direction
    dirs[:, 0, 3] = authored
    cones = np.zeros((n, SLOTS), np.float32)
    cones[:, 0] = math.radians(cone_deg)
    maps = np.zeros((n, SLOTS), np.float32)
    maps[:, 0] = wrinkle_map
    return WdvSlots(dirs, cones, maps)


def tilted(length: float, degrees: float) -> np.ndarray:
    """A motion of ``length`` at ``degrees`` from +X, in the XY plane."""
    a = math.radians(degrees)
    return np.array([[length * math.cos(a), length * math.sin(a), 0.0]])


@pytest.mark.parametrize(("length", "angle", "authored", "scale_free", "k", "expected"), [
    (0.5, 0.0, 1.0, True, 1.0, 0.5),      # along d: w = |δ| / authored
    (1.0, 10.0, 2.0, True, 1.0, 0.25),    # half-way out of a 20° cone halves it
    (1.0, 10.0, 2.0, False, 1.0, 0.5),    # in model units: the authored length is ignored
    (1.0, 5.0, 1.0, True, 0.5, 0.375),    # the expression factor scales it
    (3.0, 0.0, 1.0, True, 1.0, 1.0),      # clamped at 1
    (1.0, 19.0, 1.0, True, 1.0, 0.05),    # just inside the cone
    (1.0, 20.0, 1.0, True, 1.0, 0.0),     # on the cone's edge: outside
    (1.0, 25.0, 1.0, True, 1.0, 0.0),     # outside the cone
    (1.0, 180.0, 1.0, True, 1.0, 0.0),    # against the direction
    (0.0, 0.0, 1.0, True, 1.0, 0.0),      # at rest
])
def test_technique_2_visibility_matches_the_formula(length, angle, authored, scale_free, k,
                                                    expected):
    w = visibility(tilted(length, angle), one_slot((1, 0, 0), authored, 20.0), k, scale_free)
    assert w.shape == (1, 4)
    assert w[0, 0] == pytest.approx(expected, abs=1e-6)
    assert not w[0, 1:].any()


def test_unauthored_slots_and_zero_cones_show_nothing():
    delta = tilted(1.0, 0.0)
    assert not visibility(delta, one_slot((1, 0, 0), 0.0, 20.0)).any()
    assert not visibility(delta, one_slot((1, 0, 0), 1.0, 0.0)).any()
    assert not visibility(delta, one_slot((0, 0, 0), 1.0, 20.0)).any()


def test_each_map_takes_its_strongest_slot():
    dirs = np.zeros((1, SLOTS, 4), np.float32)
    dirs[0, :, :3] = (1, 0, 0)
    dirs[0, :, 3] = (4.0, 2.0, 1.0, 8.0)  # visibility 0.25, 0.5, 1.0, 0.125 for |δ| = 1
    cones = np.full((1, SLOTS), math.radians(30.0), np.float32)
    maps = np.array([[1, 1, 3, 1]], np.float32)
    w = visibility(tilted(1.0, 0.0), WdvSlots(dirs, cones, maps))
    assert w[0] == pytest.approx([0.0, 0.5, 0.0, 1.0])


def test_per_vertex_values_are_independent():
    slots = one_slot((0, 1, 0), 1.0, 40.0, n=3)
    delta = np.array([[0, 0.5, 0], [0, 0, 0], [0.5, 0, 0]], float)
    assert visibility(delta, slots)[:, 0] == pytest.approx([0.5, 0.0, 0.0])


def test_create_sets_unit_directions_and_lengths_for_moving_selected_vertices():
    rest = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    target = rest + np.array([[0, 3, 4], [0, 0, 0], [2, 0, 0], [0, 0, 5]], np.float32)
    result = wrinkle_directions(rest, target, np.array([0, 1, 2]))
    assert result.directions.ravel().tolist() == pytest.approx(
        [0, 0.6, 0.8, 0, 0, 0, 1, 0, 0, 0, 0, 0])
    assert result.lengths.tolist() == pytest.approx([5.0, 0.0, 2.0, 0.0])
    assert result.still.tolist() == [1]  # selected but not moving: reported, no NaN


def test_slots_keep_the_longest_motions_whatever_the_area_order():
    n = 2
    areas = []
    for i, length in enumerate((1.0, 5.0, 2.0, 4.0, 3.0)):
        area = WdvArea.empty(f"a{i}", "p", n, cone_angle_deg=10.0 + i)
        area.directions[0] = (1, 0, 0)
        area.lengths[0] = length
        areas.append(area)
    areas[2].cone_angles_deg = np.array([33.0, 0.0], np.float32)  # painted on vertex 0
    slots = WdvSetup(areas).pack_slots(n, map_index=lambda name: 2)
    assert slots.dirs[0, :, 3].tolist() == [5.0, 4.0, 3.0, 2.0]
    assert np.degrees(slots.cones[0]).tolist() == pytest.approx([11.0, 13.0, 14.0, 33.0])
    assert slots.maps[0].tolist() == [2, 2, 2, 2]
    assert not slots.dirs[1].any() and not slots.cones[1].any()  # nothing authored there
    areas[1].enabled = False
    assert WdvSetup(areas).pack_slots(n).dirs[0, :, 3].tolist() == [4.0, 3.0, 2.0, 1.0]
    assert not WdvSetup([]).pack_slots(n).dirs.any()


def test_composed_weight_is_the_clamped_sum_of_mask_times_activation():
    masks = np.zeros((3, 1, 3), np.float32)
    masks[0] = [[1.0, 1.0, 0.0]]
    masks[1] = [[0.5, 1.0, 0.0]]
    masks[2] = [[0.0, 0.0, 0.2]]
    sparse = sparse_masks(masks)
    s = composed_weight(sparse, np.array([0.4, 0.8, 1.0]))
    assert s[0].tolist() == pytest.approx([0.4 + 128 / 255 * 0.8, 1.0, 51 / 255], abs=1e-6)


def test_composed_weights_route_each_area_to_its_map():
    masks = np.ones((3, 1, 1), np.float32)
    out = composed_weights(sparse_masks(masks), np.array([0.25, 0.5, 0.125]), np.array([0, 2, 2]))
    assert out[0, 0].tolist() == pytest.approx([0.25, 0.0, 0.625, 0.0])


def test_more_than_k_areas_keep_the_strongest_and_report_the_dropped_weight():
    values = [0.1, 0.9, 0.3, 0.7, 0.5, 0.2]
    masks = np.array(values, np.float32)[:, None, None] * np.ones((1, 2, 3), np.float32)
    sparse = sparse_masks(masks)
    assert sparse.dropped_weight == pytest.approx(round(0.2 * 255) / 255)  # the fifth strongest
    assert sorted(sparse.indices[1, 2].tolist()) == [1, 2, 3, 4]
    assert sorted(sparse.weights[1, 2].tolist()) == sorted(quantise(np.array([0.9, 0.3, 0.7, 0.5])))
    act = np.ones(len(values)) * 0.25
    assert composed_weight(sparse, act)[0, 0] == pytest.approx(
        0.25 * sum(round(v * 255) / 255 for v in (0.9, 0.3, 0.7, 0.5)), abs=1e-6)


def test_few_areas_fill_the_first_slots_and_no_weight_is_dropped():
    masks = np.array([[[0.0, 1.0]], [[1.0, 0.0]]], np.float32)
    sparse = sparse_masks(masks)
    assert sparse.dropped_weight == 0.0
    assert sparse.indices[0, 0, :2].tolist() == [0, 1]
    assert sparse.weights[0, :, :2].tolist() == [[0, 255], [255, 0]]
    assert not sparse.weights[..., 2:].any() and sparse.weights.shape[-1] == K


def test_quantise_rounds_and_clamps_and_passes_bytes_through():
    assert quantise(np.array([-1.0, 0.5, 2.0])).tolist() == [0, 128, 255]
    raw = np.array([1, 2], np.uint8)
    assert quantise(raw) is raw


def test_masks_taller_than_one_chunk_are_all_composed():
    masks = np.zeros((5, 150, 2), np.float32)
    masks[4, 140:, 1] = 1.0
    sparse = sparse_masks(masks)
    s = composed_weight(sparse, np.array([0, 0, 0, 0, 0.5]))
    assert s[140:, 1] == pytest.approx(0.5) and not s[:140].any() and not s[:, 0].any()


@pytest.mark.parametrize(("mode", "fraction", "expected"), [
    ("linear", 0.25, 0.25),
    ("cosine", 0.25, (1 - math.cos(0.25 * math.pi)) / 2),  # Parke: C = (1 − cos(fπ)) / 2
    ("cosine", 0.5, 0.5),
    ("smooth", 0.25, 0.15625),  # f²(3 − 2f)
    ("smooth", 0.75, 0.84375),
    ("constant", 0.99, 0.0),
    ("constant", 1.0, 1.0),
    ("linear", -0.5, 0.0),  # fractions outside [0, 1] are clamped
    ("smooth", 1.5, 1.0),
])
def test_pose_interpolation_eases_the_fraction(mode, fraction, expected):
    a = np.array([[0.0, 2.0, -1.0]], np.float32)
    b = np.array([[4.0, 2.0, 3.0]], np.float32)
    assert ease(fraction, mode) == pytest.approx(expected, abs=1e-9)
    assert interpolate(a, b, fraction, mode).ravel().tolist() == pytest.approx(
        (a + expected * (b - a)).ravel().tolist(), abs=1e-6)


def test_an_unknown_interpolation_mode_is_refused():
    with pytest.raises(ValueError, match="bouncy"):
        ease(0.5, "bouncy")


def test_a_pose_of_another_topology_or_with_nan_is_refused_by_name():
    rest = np.zeros((3, 3), np.float32)
    check_pose_topology(rest, KeyPose("fine", np.ones((3, 3))))
    with pytest.raises(MeshError, match=r"'short' has 2 vertices, the neutral mesh has 3"):
        check_pose_topology(rest, KeyPose("short", np.zeros((2, 3))))
    bad = np.zeros((3, 3))
    bad[2, 1] = np.nan
    with pytest.raises(MeshError, match="'holed' has a non-finite coordinate at vertex 2"):
        check_pose_topology(rest, KeyPose("holed", bad))


def test_blending_many_poses_and_then_none_gives_the_formula_each_time():
    rest = np.zeros((2, 3), np.float32)
    poses = [KeyPose(f"p{k}", np.full((2, 3), k + 1.0)) for k in range(5)]
    blender = PoseBlender(rest, poses)
    weights = {"p0": 1.0, "p1": 0.5, "p2": 0.25, "p3": 2.0, "p4": -1.0}  # the matrix product
    expected = 1.0 * 1 + 0.5 * 2 + 0.25 * 3 + 2.0 * 4 - 1.0 * 5
    assert blender.blend(weights).ravel().tolist() == pytest.approx([expected] * 6)
    assert blender.blend({"p1": 0.5, "p3": 0.25}).ravel().tolist() == pytest.approx([2.0] * 6)
    assert not blender.blend({}).any()


def reference_normal(height: np.ndarray, su: float, sv: float, top: int) -> np.ndarray:
    """The bump-to-normal formula texel by texel: gx = h(x−1) − h(x+1) along a row,
    gy = h(row below) − h(row above), n = normalize(gx·s_u, gy·s_v, 1), edges repeated."""
    rows, cols = height.shape
    out = np.zeros((rows, cols, 3))
    for r in range(rows):
        for c in range(cols):
            def h(rr: int, cc: int) -> float:
                return float(height[min(max(rr, 0), rows - 1), min(max(cc, 0), cols - 1)])
            n = np.array([(h(r, c - 1) - h(r, c + 1)) * su, (h(r + 1, c) - h(r - 1, c)) * sv, 1.0])
            n /= np.linalg.norm(n)
            out[r, c] = np.floor((n * 0.5 + 0.5) * top + 0.5)
    return out


@pytest.mark.parametrize(("strength", "bits"), [(1.0, 8), (0.5, 16), ((2.0, 0.25), 8)])
def test_a_height_map_becomes_the_normal_map_of_the_formula(strength, bits):
    rng = np.random.default_rng(bits)
    height = rng.random((5, 7)).astype(np.float32)
    su, sv = (strength, strength) if np.isscalar(strength) else strength
    got = height_to_normal(height, strength, bits=bits)
    assert got.dtype == (np.uint8 if bits == 8 else np.uint16)
    np.testing.assert_array_equal(got, reference_normal(height, su, sv, 2**bits - 1))


def test_a_slope_up_the_image_and_toward_u_tilts_the_normal_to_minus_x_and_minus_y():
    ramp = np.tile(np.arange(4, dtype=np.float32), (4, 1))  # rising toward +u
    n = height_to_normal(ramp, 1.0).astype(int)
    assert n[1, 1, 0] < 128 and n[1, 1, 1] == 128
    n = height_to_normal(ramp.T[::-1], 1.0).astype(int)  # rising toward row 0 (+v)
    assert n[1, 1, 1] < 128 and n[1, 1, 0] == 128
    assert height_to_normal(np.zeros((2, 2)), 3.0).tolist() == [[[128, 128, 255]] * 2] * 2


def test_height_maps_and_bit_depths_that_cannot_be_converted_are_refused():
    with pytest.raises(ValueError, match="bits must be 8 or 16"):
        height_to_normal(np.zeros((2, 2)), bits=12)
    with pytest.raises(ValueError, match="2-D"):
        height_to_normal(np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match="2-D"):
        height_to_normal(np.zeros((0, 3)))


def test_flip_green_inverts_only_green_and_leaves_the_input():
    image = np.array([[[10, 20, 30]]], np.uint8)
    assert flip_green(image).tolist() == [[[10, 235, 30]]]
    assert image.tolist() == [[[10, 20, 30]]]
    assert flip_green(np.array([[[0, 1000, 0]]], np.uint16))[0, 0, 1] == 65535 - 1000
    assert flip_green(np.array([[[0.5, 0.25, 1.0]]]))[0, 0].tolist() == [0.5, 0.75, 1.0]
    with pytest.raises(ValueError, match="normal map"):
        flip_green(np.zeros((2, 2)))


def test_visibility_reads_however_many_slots_it_is_given_and_never_goes_negative():
    dirs = np.zeros((1, 2, 4), np.float32)  # two slots, not SLOTS
    dirs[0, 1] = (1, 0, 0, 1)
    slots = WdvSlots(dirs, np.full((1, 2), math.radians(20.0), np.float32),
                     np.array([[0, 1]], np.float32))
    assert visibility(tilted(0.5, 0.0), slots)[0].tolist() == pytest.approx([0, 0.5, 0, 0])
    assert not visibility(tilted(0.5, 0.0), slots, expression_factor=-1.0).any()


def test_an_empty_area_keeps_its_name_pose_and_settings_with_nothing_authored():
    area = WdvArea.empty("brow", "surprise", 3, cone_angle_deg=30.0, wrinkle_map="deep")
    assert (area.name, area.pose, area.cone_angle_deg, area.wrinkle_map) == (
        "brow", "surprise", 30.0, "deep")
    assert area.directions.shape == (3, 3) and area.lengths.shape == (3,)
    assert not area.authored.any()
    assert area.vertex_cones_deg().tolist() == [30.0] * 3


def test_the_composed_weights_are_float32_like_the_gpu_texture():
    sparse = sparse_masks(np.ones((2, 1, 1), np.float32))
    assert composed_weights(sparse, np.array([0.5, 0.25]), np.array([0, 1])).dtype == np.float32
    assert composed_weight(sparse, np.array([0.5, 0.25])).dtype == np.float32


def test_a_track_without_keys_weighs_nothing_one_frame_at_a_time():
    from studio.core.animation.timeline import Key, Track

    assert Track("frown").value_at(5.0) == 0.0
    track = Track("frown", [Key(10, 0.4, "linear"), Key(20, 0.8, "linear")])
    assert track.value_at(0.0) == pytest.approx(0.4)  # held before the first key
    assert track.value_at(15.0) == pytest.approx(0.6)
    assert track.value_at(99.0) == pytest.approx(0.8)  # and after the last
