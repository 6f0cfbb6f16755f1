"""A pose's onset (issue 45, point 6) without a GPU: the weight through the onset, technique 1's
activations, the controls for all poses and one combined, the project file (saved, reopened,
and a file from before onsets read as none), and the exports that carry activations — the web
page's own script under Node.js (its technique 2's rest too), the Blender drivers, the glTF
animation's activations and the export folder's sheet."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from studio.commands.export import web_look
from studio.core.animation.poses import PoseBlender
from studio.core.animation.timeline import sequence_all_poses
from studio.core.formats.blender_material import link_term
from studio.core.formats.export import export_folder
from studio.core.formats.gltf.codec import _Gltf, save_gltf
from studio.core.formats.web_export import web_page
from studio.core.mesh.camera import OrbitCamera
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.furrow_controls import FurrowControls
from studio.core.wrinkles.response import ResponseCurve, onset_weight
from tests.test_blender_material import CURVES
from tests.test_web_player_js import page_activations, random_links

pytestmark = pytest.mark.core


@pytest.fixture
def face():
    """A small face whose areas are linked to its poses (some through curves)."""
    project = make_test_face(561, texture_size=64, mask_size=32)
    random_links(project, np.random.default_rng(7))
    return project


def with_onset(project, pose: str | None, onset: float):
    project.furrows = project.furrows.with_controls(pose, FurrowControls(onset=onset))
    return project


def test_no_onset_leaves_any_weight_exactly_as_it_is_and_an_onset_delays_it():
    weights = np.array([-0.3, 0.0, 0.2, 0.5, 0.9, 1.0, 1.4])
    assert np.array_equal(onset_weight(weights, 0.0), weights)
    delayed = onset_weight(weights, 0.6)
    assert np.array_equal(delayed[weights <= 0.6], np.zeros((weights <= 0.6).sum()))
    assert delayed[weights == 1.0] == 1.0
    assert delayed[weights == 0.9] == pytest.approx(0.75)


def test_a_pose_s_onset_on_top_of_all_poses_is_one_remap_after_the_other():
    project = with_onset(with_onset(make_test_face(561, texture_size=64, mask_size=32),
                                    None, 0.5), "surprise", 0.5)
    assert project.furrows.of("surprise").onset == pytest.approx(0.75)
    assert project.furrows.of("frown").onset == 0.5
    seen = project.wrinkle_weights({"surprise": 0.875, "frown": 0.75})
    assert seen["surprise"] == pytest.approx(0.5) and seen["frown"] == pytest.approx(0.5)
    with pytest.raises(ValueError, match=r"onset must be a number from 0 to 0\.95"):
        FurrowControls(onset=1.0)


def test_technique_1_sees_each_pose_through_its_onset(face):
    pose = face.poses[0].name
    before = {w: face.activations({pose: w}) for w in (0.3, 0.5, 1.0)}
    resting = face.activations({pose: 0.0})  # the pose at rest (a curve may start above 0)
    with_onset(face, pose, 0.5)
    assert np.array_equal(face.activations({pose: 0.3}), resting)  # below: no lines
    assert np.array_equal(face.activations({pose: 1.0}), before[1.0])  # full: as before
    assert np.array_equal(face.activations({pose: 0.75}), before[0.5])  # halfway past it
    assert not np.array_equal(before[0.3], resting)  # the link did act there before
    # the timeline's many frames at once say the same
    names = [p.name for p in face.poses]
    frames = np.zeros((2, len(names)))
    frames[:, 0] = [0.3, 0.75]
    np.testing.assert_allclose(face.activations_over(names, frames),
                               [resting, before[0.5]], atol=1e-6)


def test_the_onsets_are_saved_and_a_file_from_before_them_has_none(face, tmp_path):
    with_onset(with_onset(face, None, 0.2), face.poses[1].name, 0.4)
    path = tmp_path / "onsets.wrinkle"
    save_project(face, path)
    again = load_project(path)
    assert again.furrows.all.onset == 0.2
    assert again.furrows.of(face.poses[1].name).onset == pytest.approx(1 - 0.8 * 0.6)
    with zipfile.ZipFile(path) as archive:
        doc = json.loads(archive.read("project.json"))
    assert doc["version"] == 4

    older = tmp_path / "older.wrinkle"  # as the last studio wrote it: version 3, no onset
    save_project(make_test_face(561, texture_size=64, mask_size=32), older)
    with zipfile.ZipFile(older) as archive:
        members = {n: archive.read(n) for n in archive.namelist()}
    doc = json.loads(members["project.json"])
    doc["version"] = 3
    doc["furrows"] = {"all": {"depth": 1.0, "spacing": 1.0, "sharpness": 1.0}}
    members["project.json"] = json.dumps(doc).encode()
    with zipfile.ZipFile(older, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    assert load_project(older).furrows.all == FurrowControls()


def test_the_web_page_s_script_sees_each_pose_through_its_onset(face, tmp_path):
    names = [p.name for p in face.poses]
    with_onset(with_onset(face, None, 0.3), names[0], 0.5)
    page = tmp_path / "index.html"
    page.write_text(web_page(face, OrbitCamera(), web_look()), encoding="utf-8")
    rng = np.random.default_rng(3)
    weights = np.concatenate([np.eye(len(names)) * 0.6, np.eye(len(names)),
                              rng.uniform(0, 1, (12, len(names)))])
    on_page = page_activations(page, weights)
    for row, got in zip(weights, on_page, strict=True):
        mix = dict(zip(names, row.tolist(), strict=True))
        np.testing.assert_allclose(got, face.activations(mix), atol=2e-3, err_msg=str(mix))


@pytest.mark.parametrize("curve", CURVES, ids=[c.kind for c in CURVES])
def test_a_blender_driver_bakes_the_pose_s_onset_into_its_curve(curve: ResponseCurve):
    for x in np.linspace(-0.2, 1.2, 29):
        term = link_term(0.75, curve, 0.4).format(x=repr(float(x)))
        got = eval(term, {"__builtins__": {}, "min": min, "max": max})
        want = 0.75 * float(curve.evaluate(onset_weight(x, 0.4)))
        assert got == pytest.approx(want, abs=1e-12), (curve.kind, x)


def test_the_gltf_animation_s_activations_bake_the_onsets(face, tmp_path):
    face.timeline = sequence_all_poses([p.name for p in face.poses])
    with_onset(face, None, 0.5)
    path = tmp_path / "face.glb"
    save_gltf(face, path)
    (animation,) = _Gltf(path).doc["animations"]
    areas = animation["extras"]["wrinkleStudio"]["activations"]["areas"]
    values = np.array([a["values"] for a in areas]).T
    gltf = _Gltf(path)
    sampler = animation["samplers"][0]
    frames = gltf.accessor(sampler["input"]).ravel() * face.timeline.fps + face.timeline.start
    for i in (0, len(frames) // 3, len(frames) // 2):
        weights = face.timeline.weights_at(frames[i])
        np.testing.assert_allclose(values[i], face.activations(weights), atol=1e-6)
    assert any(not np.allclose(values[i], face.influence.activations(
        face.timeline.weights_at(frames[i])), atol=1e-3) for i in range(len(frames)))


def test_the_web_page_s_technique_2_measures_past_each_pose_s_onset(face, tmp_path):
    """The page moves technique 2's rest by what the onsets hold back, as the studio's
    ``WrinkleDrive`` does: the shader then measures only the motion past each onset."""
    names = [p.name for p in face.poses]
    with_onset(with_onset(face, None, 0.2), names[0], 0.5)
    page = tmp_path / "index.html"
    page.write_text(web_page(face, OrbitCamera(), web_look()), encoding="utf-8")
    weights = np.array([[0.4] + [0.0] * (len(names) - 1), np.linspace(0.1, 0.9, len(names)),
                        np.ones(len(names))])
    on_page = page_activations(page, weights, "rest").reshape(len(weights), -1, 3)
    blender = PoseBlender(face.mesh.rest, face.poses)
    for row, got in zip(weights, on_page, strict=True):
        mix = dict(zip(names, row.tolist(), strict=True))
        positions = blender.blend(mix).copy()
        moved = face.mesh.rest + positions - blender.blend(face.wrinkle_weights(mix))
        scale = np.abs(positions - face.mesh.rest).max()
        np.testing.assert_allclose(got, moved[face.mesh.weld], atol=2e-3 * scale + 1e-6)
    resting = on_page[0] - face.mesh.rest[face.mesh.weld]
    assert np.abs(resting).max() > 0.01 * scale  # at 0.4 the first pose is all held back


def test_the_export_folder_s_sheet_carries_the_onsets(face, tmp_path):
    names = [p.name for p in face.poses]
    export_folder(face, tmp_path / "plain")
    plain = json.loads((tmp_path / "plain" / "wrinkles.json").read_text(encoding="utf-8"))
    assert "pose_onsets" not in plain  # no onset: the sheet as it always was
    with_onset(with_onset(face, None, 0.2), names[0], 0.5)
    export_folder(face, tmp_path / "out")
    sheet = json.loads((tmp_path / "out" / "wrinkles.json").read_text(encoding="utf-8"))
    assert sheet["pose_onsets"] == {n: face.furrows.of(n).onset for n in names}
    assert sheet["pose_onsets"][names[0]] == pytest.approx(0.6)


def test_the_engine_layout_sheet_carries_the_onsets(face, tmp_path):
    """An engine's own curves must put each pose's weight through its onset too: the layout
    sheet a technical artist reads says so, as the folder's does."""
    from studio.core.engines.export import SHEET, export_layout

    name = face.poses[0].name
    export_layout(face, tmp_path / "plain", "metahuman")
    plain = json.loads((tmp_path / "plain" / SHEET).read_text(encoding="utf-8"))
    assert "pose_onsets" not in plain
    with_onset(face, name, 0.4)
    export_layout(face, tmp_path / "out", "metahuman")
    sheet = json.loads((tmp_path / "out" / SHEET).read_text(encoding="utf-8"))
    assert sheet["pose_onsets"] == {name: pytest.approx(0.4)}
