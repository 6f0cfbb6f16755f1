"""Response curves of pose → area links (issue #21): the curve formulas, the activation vector
they shape, and the curves' way through the project file, the glTF and the folder export."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studio.core.files.errors import MeshError, ProjectError
from studio.core.formats.export import export_folder
from studio.core.formats.gltf.codec import load_gltf, save_gltf
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.response import LABELS, CurveBank, ResponseCurve, curves_from_dict
from tests.test_project_file import make_project, members, rewrite

pytestmark = pytest.mark.core

EASE_IN = ResponseCurve("ease_in")
CUSTOM = ResponseCurve("custom", points=((0.2, 0.0), (0.6, 0.9), (1.0, 1.0)))


# --------------------------------------------------------------------------- the formulas

@pytest.mark.parametrize(("curve", "x", "y"), [
    (ResponseCurve(), [0.0, 0.3, 1.0], [0.0, 0.3, 1.0]),  # linear: the identity
    (ResponseCurve(), [-0.5, 1.5], [-0.5, 1.5]),  # not clamped: old projects unchanged
    (EASE_IN, [0.5, 0.2], [0.25, 0.04]),  # y = x²
    (ResponseCurve("ease_out"), [0.5, 0.2], [0.75, 0.36]),  # y = 1 - (1 - x)²
    (ResponseCurve("ease_in_out"), [0.25, 0.5, 0.75], [0.15625, 0.5, 0.84375]),  # 3x² - 2x³
    # thresholds 0.2 .. 0.6: x = 0.3 is t = 0.25 of the way
    (ResponseCurve("smooth_step", 0.2, 0.6), [0.1, 0.3, 0.4, 0.7], [0.0, 0.15625, 0.5, 1.0]),
    # custom: flat before the first point, straight lines between, 0.45 at a half-segment
    (CUSTOM, [0.0, 0.2, 0.4, 0.6, 0.8, 1.0], [0.0, 0.0, 0.45, 0.9, 0.95, 1.0]),
    # clamped outside [0, 1]
    (EASE_IN, [-1.0, 2.0], [0.0, 1.0]),
    (ResponseCurve("ease_in_out"), [-0.3, 1.7], [0.0, 1.0]),
    (CUSTOM, [-1.0, 3.0], [0.0, 1.0]),
])
def test_hand_computed_values(curve: ResponseCurve, x: list[float], y: list[float]) -> None:
    np.testing.assert_allclose(curve.evaluate(np.array(x)), y, atol=1e-12)
    bank = CurveBank([curve] * len(x))  # the vectorised form gives the same
    np.testing.assert_allclose(bank.evaluate(np.array(x)), y, atol=1e-12)


@pytest.mark.parametrize(("make", "needle"), [
    (lambda: ResponseCurve("wobbly"), "kind must be one of"),
    (lambda: ResponseCurve("smooth_step", 0.6, 0.2), "start must be below end"),
    (lambda: ResponseCurve("smooth_step", 0.2, 1.5), "end must be a number from 0 to 1"),
    (lambda: ResponseCurve("ease_in", 0.2), "start and end belong to smooth_step"),
    (lambda: ResponseCurve("custom", points=((0.0, 0.0),)), "points must hold 2 to"),
    (lambda: ResponseCurve("custom", points=((0.5, 0.0), (0.5, 1.0))), "points[1] x must be"),
    (lambda: ResponseCurve("custom", points=((0.0, 0.0), (1.0, float("nan")))),
     "points[1] y must be a number"),
    (lambda: ResponseCurve("linear", points=((0.0, 0.0), (1.0, 1.0))), "points belong to"),
])
def test_invalid_curves_are_refused_naming_the_field(make, needle: str) -> None:
    with pytest.raises(ValueError) as info:
        make()
    assert needle in str(info.value)


def test_a_custom_curve_made_from_another_samples_it() -> None:
    custom = ResponseCurve("ease_in").as_custom()
    assert custom.points == ((0.0, 0.0), (0.25, 0.0625), (0.5, 0.25), (0.75, 0.5625), (1.0, 1.0))


# --------------------------------------------------------------------------- activations

def _reference(influence: InfluenceSetup, weights: dict[str, float]) -> np.ndarray:
    """The activations the obvious way: each link in turn, its curve by its own formula."""
    values = [a.activation for a in influence.areas]
    index = {a.name: i for i, a in enumerate(influence.areas)}
    for pose, weight in weights.items():
        for area, gain in influence.links.get(pose, {}).items():
            curve = influence.curves.get(pose, {}).get(area, ResponseCurve())
            if curve.kind == "custom":
                y = float(np.interp(weight, *zip(*curve.points, strict=True)))
            else:
                t = (weight - curve.start) / (curve.end - curve.start)
                t = t if curve.kind == "linear" else min(max(t, 0.0), 1.0)
                y = {"linear": t, "ease_in": t * t, "ease_out": 1 - (1 - t) ** 2,
                     "ease_in_out": t * t * (3 - 2 * t),
                     "smooth_step": t * t * (3 - 2 * t)}[curve.kind]
            values[index[area]] += gain * y
    return np.clip([0.0 if not a.visible else v for a, v in zip(
        influence.areas, values, strict=True)], 0.0, 1.0)


unit = st.floats(0.0, 1.0)


@st.composite
def curves(draw) -> ResponseCurve:
    kind = draw(st.sampled_from(list(LABELS)))
    if kind == "smooth_step":
        a, b = sorted(draw(st.lists(unit, min_size=2, max_size=2, unique=True)))
        return ResponseCurve(kind, a, b)
    if kind == "custom":
        xs = sorted(draw(st.lists(unit, min_size=2, max_size=8, unique=True)))
        return ResponseCurve(kind, points=tuple((x, draw(unit)) for x in xs))
    return ResponseCurve(kind)


@settings(max_examples=60, deadline=None)
@given(data=st.data(), n_areas=st.integers(1, 5), n_poses=st.integers(1, 6))
def test_activations_equal_a_per_link_reference(data, n_areas: int, n_poses: int) -> None:
    mask = np.zeros((2, 2), np.float32)
    areas = [InfluenceArea(f"a{i}", mask, activation=data.draw(st.floats(0, 0.5)),
                           visible=data.draw(st.booleans())) for i in range(n_areas)]
    poses = [f"p{i}" for i in range(n_poses)]
    links: dict[str, dict[str, float]] = {}
    table: dict[str, dict[str, ResponseCurve]] = {}
    for pose in poses:
        for area in areas:
            if data.draw(st.booleans()):
                links.setdefault(pose, {})[area.name] = data.draw(st.floats(0.0, 2.0))
                table.setdefault(pose, {})[area.name] = data.draw(curves())
    influence = InfluenceSetup(areas, links, table)
    frames = [{p: data.draw(st.floats(-0.2, 1.2)) for p in poses} for _ in range(3)]
    expected = [_reference(influence, weights) for weights in frames]
    for weights, reference in zip(frames, expected, strict=True):  # one derived table
        np.testing.assert_allclose(influence.activations(weights), reference, atol=2e-6)
    # the timeline's form: every frame at once, from a (frames × poses) array
    at_once = influence.activations_over(poses, [[w[p] for p in poses] for w in frames])
    np.testing.assert_allclose(at_once, expected, atol=1e-9)


def test_activations_follow_a_changed_curve() -> None:
    area = InfluenceArea("brow", np.zeros((2, 2), np.float32))
    influence = InfluenceSetup([area], {"frown": {"brow": 1.0}})
    assert influence.activations({"frown": 0.5})[0] == pytest.approx(0.5)
    influence.curves["frown"] = {"brow": EASE_IN}  # edited in place, after a frame
    assert influence.activations({"frown": 0.5})[0] == pytest.approx(0.25)
    influence.curves["frown"]["brow"] = ResponseCurve("ease_out")
    assert influence.activations({"frown": 0.5})[0] == pytest.approx(0.75)


# --------------------------------------------------------------------------- the project file

TABLE = {"smile": {"cheek/left": EASE_IN, "forehead right": CUSTOM},
         "frown": {"brow": ResponseCurve("smooth_step", 0.125, 0.8)}}


@pytest.fixture
def curved(tmp_path: Path) -> Path:
    project = make_project()
    project.influence.curves = {p: dict(c) for p, c in TABLE.items()}
    path = tmp_path / "curved.wrinkle"
    save_project(project, path)
    return path


def test_save_and_load_keep_every_curve_exactly(curved: Path) -> None:
    assert load_project(curved).influence.curves == TABLE
    doc = json.loads(members(curved)["project.json"])
    assert doc["influence"]["curves"]["frown"]["brow"] == {"kind": "smooth_step",
                                                           "start": 0.125, "end": 0.8}


def test_a_file_without_curves_loads_with_linear_links(tmp_path: Path, curved: Path) -> None:
    old = rewrite(curved, tmp_path / "old.wrinkle",
                  doc=lambda d: d["influence"].pop("curves"))
    project = load_project(old)
    assert project.influence.curves == {}
    gains = project.influence.links["smile"]
    weights = {"smile": 0.5, "frown": 0.0}
    expected = [0.25 + 0.5 * gains["forehead right"], 0.0, 0.0]  # own activation + gain · w
    np.testing.assert_allclose(project.influence.activations(weights), expected, atol=1e-6)


def test_linear_curves_are_not_written(tmp_path: Path) -> None:
    project = make_project()
    project.influence.curves = {"frown": {"brow": ResponseCurve()}}
    save_project(project, tmp_path / "plain.wrinkle")
    doc = json.loads(members(tmp_path / "plain.wrinkle")["project.json"])
    assert "curves" not in doc["influence"]


@pytest.mark.parametrize(("edit", "needle"), [
    (lambda c: c["frown"]["brow"].update(kind="zigzag"),
     "influence.curves.frown.brow: kind must be one of"),
    (lambda c: c["frown"]["brow"].update(end=0.1),
     "influence.curves.frown.brow: start must be below end"),
    (lambda c: c["smile"]["forehead right"]["points"][1].__setitem__(0, "0.6"),
     "influence.curves.smile.forehead right: points[1] x must be a number"),
    (lambda c: c["smile"]["forehead right"]["points"].append([0.9, 0.5]),
     "influence.curves.smile.forehead right: points[3] x must be greater"),
    (lambda c: c["smile"].__setitem__("cheek/left", [1, 2]),
     "influence.curves.smile.cheek/left: must be a JSON object"),
    (lambda c: c.__setitem__("frown", "ease_in"), "influence.curves.frown must be a JSON object"),
    (lambda c: c["frown"].__setitem__("nobody", {"kind": "ease_in"}),
     "names a key pose or influence area that does not exist"),
])
def test_damaged_curve_data_is_refused_naming_the_field(tmp_path: Path, curved: Path, edit,
                                                        needle: str) -> None:
    damaged = rewrite(curved, tmp_path / "damaged.wrinkle",
                      doc=lambda d: edit(d["influence"]["curves"]))
    with pytest.raises(ProjectError) as info:
        load_project(damaged)
    assert needle in str(info.value) and str(damaged) in str(info.value)


def test_curves_that_are_not_an_object_are_refused(tmp_path: Path, curved: Path) -> None:
    damaged = rewrite(curved, tmp_path / "damaged.wrinkle",
                      doc=lambda d: d["influence"].__setitem__("curves", [1]))
    with pytest.raises(ProjectError, match=r"influence\.curves must be a JSON object"):
        load_project(damaged)


# --------------------------------------------------------------------------- exports

@pytest.fixture(scope="module")
def small_curved():
    project = make_test_face(561, texture_size=64, mask_size=32)
    (one, first), (two, second) = [(p, a) for p, g in project.influence.links.items()
                                   for a in g][:2]
    project.influence.curves = {one: {first: EASE_IN}}
    project.influence.curves.setdefault(two, {})[second] = CUSTOM
    return project


def test_the_glb_carries_the_curves_and_reads_them_back(small_curved, tmp_path: Path) -> None:
    save_gltf(small_curved, tmp_path / "face.glb")
    back = load_gltf(tmp_path / "face.glb")
    assert back.influence.curves == small_curved.influence.curves
    weights = dict.fromkeys(small_curved.pose_names, 0.5)
    np.testing.assert_allclose(back.influence.activations(weights),
                               small_curved.influence.activations(weights), atol=1e-6)


def test_a_glb_with_a_damaged_curve_names_it(small_curved, tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    from studio.core.formats.gltf import codec as gltf

    # a pose of the file (a pose it lacks is left out with a line: see test_blender_edits)
    pose, area = next((p, a) for p, table in small_curved.influence.curves.items()
                      for a in table)
    monkeypatch.setattr(gltf, "curves_to_dict", lambda _: {pose: {area: {"kind": "?"}}})
    save_gltf(small_curved, tmp_path / "bad.glb")
    named = rf"{re.escape(pose)}\.{re.escape(area)}: kind must be one of"
    with pytest.raises(MeshError, match=named):
        load_gltf(tmp_path / "bad.glb")


def test_wrinkles_json_carries_the_curves(small_curved, tmp_path: Path) -> None:
    export_folder(small_curved, tmp_path / "out", bits=8)
    sheet = json.loads((tmp_path / "out" / "wrinkles.json").read_text())
    assert curves_from_dict(sheet["pose_curves"]) == small_curved.influence.curves
    (pose, table), *_ = small_curved.influence.curves.items()
    assert sheet["pose_curves"][pose][next(iter(table))] == {"kind": "ease_in"}
