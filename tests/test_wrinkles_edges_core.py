"""Edge cases of the wrinkle data modules, each with a hand-computed expectation.

Mask operations (clamped fills, mirroring an odd-width mask, weighted sums and where they
overflow, mesh edges, per-vertex compression with an unused vertex), influence areas (links to
missing areas, clamping, integer activations, an empty setup, gains rebuilt only after a change),
response curves (every validation message, normalised fields, a near-vertical custom step),
skin strain (a collapsed edge, an unused vertex, the weight clamp), wrinkle-vector visibility
(a motion exactly along the authored direction, scale-free lengths, unauthored slots without
warnings) and the technique table's messages.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup, _Gains
from studio.core.wrinkles.response import CurveBank, ResponseCurve
from studio.core.wrinkles.strain import StrainField
from studio.core.wrinkles.techniques import shader_define, technique
from studio.core.wrinkles.wdv import SLOTS, WdvSlots, visibility

pytestmark = pytest.mark.core

Array = np.ndarray


# --- mask operations ----------------------------------------------------------------------------


def test_fill_clamps_the_value_to_the_unit_range():
    m = np.zeros((2, 2), np.float32)
    assert mask_ops.fill(m, -0.5).tolist() == [[0.0, 0.0], [0.0, 0.0]]
    assert mask_ops.fill(m, 1.5).tolist() == [[1.0, 1.0], [1.0, 1.0]]
    assert mask_ops.fill(m).tolist() == [[1.0, 1.0], [1.0, 1.0]]


def test_invert_and_levels_give_float32_masks_for_any_input():
    m = np.array([[0.0, 0.25]], np.float64)
    assert mask_ops.invert(m).dtype == np.float32
    assert mask_ops.levels(m).dtype == np.float32


def test_mirror_u_on_an_odd_width_keeps_the_middle_column():
    m = np.array([[1.0, 2.0, 3.0, 4.0, 5.0]], np.float32)
    assert mask_ops.mirror_u(m).tolist() == [[1.0, 2.0, 3.0, 2.0, 1.0]]  # "left" by default
    assert mask_ops.mirror_u(m, "left").tolist() == [[1.0, 2.0, 3.0, 2.0, 1.0]]
    assert mask_ops.mirror_u(m, "right").tolist() == [[5.0, 4.0, 3.0, 4.0, 5.0]]
    assert mask_ops.mirror_u(m, "max").tolist() == [[5.0, 4.0, 3.0, 4.0, 5.0]]
    m2 = np.array([[0.0, 0.9, 0.2, 0.1]], np.float32)
    assert mask_ops.mirror_u(m2, "max")[0] == pytest.approx([0.1, 0.9, 0.9, 0.1])


def test_weighted_sum_of_one_two_and_no_masks():
    masks = np.array([[[0.5, 1.0]], [[0.25, 0.0]]], np.float64)
    one = mask_ops.weighted_sum(masks[:1], [2.0])
    assert one.dtype == np.float32 and one.tolist() == [[1.0, 2.0]]
    assert mask_ops.weighted_sum(masks, [1.0, 2.0]).tolist() == [[1.0, 1.0]]
    empty = mask_ops.weighted_sum(np.zeros((0, 3, 3), np.float32), [])
    assert empty.dtype == np.float32 and empty.shape == (1, 1) and empty[0, 0] == 0.0


def test_overlap_flags_only_sums_above_the_limit_and_uncovered_texels():
    masks = np.array([[[0.5, 0.75, 0.0, 0.0]], [[0.5, 0.5, 0.0, 0.0]]], np.float32)
    coverage = np.array([[True, True, True, False]])
    over, none = mask_ops.overlap(masks, [1.0, 1.0], coverage)
    assert over.tolist() == [[False, True, False, False]]  # exactly 1.0 is not a conflict
    assert none.tolist() == [[False, False, True, False]]  # uncovered, inside the layout only
    over, none = mask_ops.overlap([], [])
    assert over.tolist() == [[False]] and none.dtype == bool and none.tolist() == [[True]]


def test_mesh_edges_are_unique_and_undirected():
    edges = mask_ops.mesh_edges(np.array([[0, 1, 2], [2, 1, 3]]))
    assert edges.tolist() == [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]


def test_vertex_compression_covers_unused_vertices():
    rest = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]])
    posed = rest.copy()
    posed[1, 0] = 0.5  # edge 0-1 halves; edge 1-2 shortens from √2 to √1.25
    out = mask_ops.vertex_compression(rest, posed, np.array([[0, 1, 2]]))
    s12 = 1.0 - np.sqrt(1.25) / np.sqrt(2.0)
    assert out.dtype == np.float32
    assert out == pytest.approx([0.25, (0.5 + s12) / 2, s12 / 2, 0.0])


# --- influence areas -----------------------------------------------------------------------------


def area(name: str, activation: float = 0.0, visible: bool = True) -> InfluenceArea:
    return InfluenceArea(name, np.ones((2, 2), np.float32), activation=activation, visible=visible)


def test_a_link_to_a_missing_area_does_not_hide_the_links_after_it():
    setup = InfluenceSetup([area("a"), area("b")], {"smile": {"gone": 1.0, "b": 0.5}})
    assert setup.activations({"smile": 1.0}).tolist() == [0.0, 0.5]
    assert setup.activations_over(["smile"], [[1.0], [0.5]]).tolist() == [[0.0, 0.5], [0.0, 0.25]]


def test_activations_are_clamped_to_the_unit_range_both_ways():
    setup = InfluenceSetup([area("a", 0.5), area("b", 0.75)], {"frown": {"a": -2.0, "b": 1.0}})
    values = setup.activations({"frown": 1.0})
    assert values.dtype == np.float32 and values.tolist() == [0.0, 1.0]
    assert setup.activations_over(["frown"], [[1.0]]).tolist() == [[0.0, 1.0]]


def test_activations_without_pose_weights_on_a_linked_setup():
    setup = InfluenceSetup([area("a", 0.25), area("b", 0.5, visible=False)], {"smile": {"a": 1.0}})
    assert setup.activations().tolist() == [0.25, 0.0]
    assert setup.activations({"other": 1.0}).tolist() == [0.25, 0.0]


def test_an_integer_activation_still_adds_fractional_links():
    setup = InfluenceSetup([area("a", 0)], {"smile": {"a": 0.5}})
    setup.areas[0].activation = 0  # as a project file may hold it
    assert setup.activations({"smile": 0.5}).tolist() == [0.25]


def test_an_empty_setup():
    setup = InfluenceSetup()
    stack = setup.mask_stack()
    assert stack.shape == (0, 1, 1) and stack.dtype == np.float32
    assert setup.activations({"smile": 1.0}).tolist() == []
    assert setup.resolution is None


def test_the_gains_are_built_once_and_again_after_each_change(monkeypatch):
    built = []
    original = _Gains.build.__func__

    def counting(cls: type, *args: object) -> _Gains:
        built.append(1)
        return original(cls, *args)

    monkeypatch.setattr(_Gains, "build", classmethod(counting))
    setup = InfluenceSetup([area("a")], {"smile": {"a": 0.5}})
    setup.activations({"smile": 1.0})
    setup.activations({"smile": 0.5})
    assert len(built) == 1
    setup.links["smile"]["a"] = 1.0
    assert setup.activations({"smile": 0.5}).tolist() == [0.5]
    assert len(built) == 2
    setup.curves["smile"] = {"a": ResponseCurve("ease_in")}
    assert setup.activations({"smile": 0.5}).tolist() == [0.25]
    assert len(built) == 3
    setup.areas.append(area("b"))
    assert setup.activations({"smile": 0.5}).tolist() == [0.25, 0.0]
    assert len(built) == 4
    setup.activations({"smile": 0.5})
    assert len(built) == 4


# --- response curves -----------------------------------------------------------------------------


def test_curve_validation_messages():
    with pytest.raises(
        ValueError,
        match=r"^kind must be one of linear, ease_in, ease_out, "
        r"ease_in_out, smooth_step, custom, not 'wobbly'$",
    ):
        ResponseCurve("wobbly")
    with pytest.raises(ValueError, match=r"^start must be a number from 0 to 1$"):
        ResponseCurve("smooth_step", start=1.5)
    with pytest.raises(ValueError, match=r"^end must be a number from 0 to 1$"):
        ResponseCurve("smooth_step", end=-0.5)
    with pytest.raises(ValueError, match=r"^start must be below end$"):
        ResponseCurve("smooth_step", start=0.5, end=0.5)
    with pytest.raises(ValueError, match=r"^points must be a list of pairs \[x, y\]$"):
        ResponseCurve("custom", points=5)
    with pytest.raises(ValueError, match=r"^points\[1\] must be a pair \[x, y\]$"):
        ResponseCurve("custom", points=[(0.0, 0.0), (1.0,)])


def test_a_curve_normalises_its_fields_to_floats_and_tuples():
    c = ResponseCurve("smooth_step", start=0, end=1)
    assert type(c.start) is float and type(c.end) is float
    custom = ResponseCurve("custom", points=[[0, 0], [1, 1]])
    assert custom.points == ((0.0, 0.0), (1.0, 1.0))
    assert type(custom.points[1][0]) is float
    assert hash(custom) == hash(ResponseCurve("custom", points=((0.0, 0.0), (1.0, 1.0))))


def test_a_near_vertical_custom_step_saturates_quietly():
    step = ResponseCurve("custom", points=((0.0, 0.0), (5e-324, 1.0)))
    bank = CurveBank([step, ResponseCurve("ease_in")])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = bank.evaluate(np.array([1.0, 0.5]))
    assert out.tolist() == [1.0, 0.25]


# --- skin strain -------------------------------------------------------------------------------


def test_strain_with_a_collapsed_edge_and_an_unused_vertex():
    """Vertices 1 and 3 share a rest position (a zero-length edge, which cannot compress) and
    vertex 4 is in no triangle: both must give finite values, quietly."""
    rest = np.array(
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [9.0, 9.0, 9.0]]
    )
    mesh = FaceMesh(rest, np.array([[0, 1, 2], [1, 3, 2]]), np.zeros((4, 2)), np.arange(4))
    field = StrainField(mesh)
    posed = rest.copy()
    posed[0, 0] = 0.5  # edge 0-1 shortens to half; 0-2 to √1.25 of 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        comp = field.compression(posed.astype(np.float32))
        weights = field.weights(posed.astype(np.float32))
    s02 = 1.0 - np.sqrt(1.25)
    assert comp.dtype == np.float32
    # edges: 0-1, 0-2, 1-2, 1-3 (zero length: 0), 2-3; only 0-1 compresses (0-2 stretches)
    assert comp == pytest.approx([(0.5 + max(s02, 0.0)) / 2, 0.5 / 3, 0.0, 0.0, 0.0], abs=1e-6)
    assert weights == pytest.approx([1.0, 1.0, 0.0, 0.0, 0.0])  # 0.25, 0.17 ≥ 0.12: full


# --- wrinkle-vector visibility -----------------------------------------------------------------


def slots(direction: list[float], authored: float, cone_rad: float) -> WdvSlots:
    dirs = np.zeros((1, SLOTS, 4), np.float32)
    dirs[0, 0, :3] = direction
    dirs[0, 0, 3] = authored
    cones = np.zeros((1, SLOTS), np.float32)
    cones[0, 0] = cone_rad
    return WdvSlots(dirs, cones, np.zeros((1, SLOTS), np.float32))


def test_a_motion_exactly_along_the_authored_direction_shows_fully_scaled():
    v = np.array([-1.27, -0.62, 0.04])  # its float32 unit vector gives a cosine just above 1
    unit = (v / np.linalg.norm(v)).tolist()
    s = slots(unit, 4.0 * float(np.linalg.norm(v)), 0.3)
    out = visibility(v[None], s)
    assert out[0] == pytest.approx([0.25, 0.0, 0.0, 0.0], rel=1e-5)
    s = slots(unit, 0.5, 0.3)  # scale-free: |delta| over the authored 0.5
    small = v[None] / np.linalg.norm(v) * 0.25
    assert visibility(small, s)[0, 0] == pytest.approx(0.5, rel=1e-5)
    assert visibility(small, s, scale_free=False)[0, 0] == pytest.approx(0.25, rel=1e-5)


def test_still_vertices_and_empty_slots_are_invisible_and_quiet():
    s = slots([1.0, 0.0, 0.0], 1.0, 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        still = visibility(np.zeros((1, 3)), s)
        unauthored = visibility(np.array([[1.0, 0.0, 0.0]]), slots([1.0, 0.0, 0.0], 0.0, 0.5))
        no_cone = visibility(np.array([[1.0, 0.0, 0.0]]), slots([1.0, 0.0, 0.0], 1.0, 0.0))
    assert still.tolist() == [[0.0] * 4]
    assert unauthored.tolist() == [[0.0] * 4]
    assert no_cone.tolist() == [[0.0] * 4]


# --- techniques -------------------------------------------------------------------------------


def test_unknown_technique_message_lists_the_choices():
    with pytest.raises(
        ValueError,
        match=r"^unknown technique 'wavy' \(choose from t2, t1, strain, "
        r"none, flat\)$",
    ):
        technique("wavy")
    assert shader_define("t1") == "TECHNIQUE_T1"
    assert shader_define("strain") == "TECHNIQUE_STRAIN"
