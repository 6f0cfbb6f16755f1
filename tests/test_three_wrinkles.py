"""The three.js module ``wrinkles.js`` shipped beside every glTF export: its activations under
Node.js are the studio's for random links, gains and curves, taken through its own per-frame
path from ``morphTargetInfluences``; on three.js in headless Chromium, each technique changes
the same pixels of the face as ``render --blend normal`` does (three.js shades once, so the
module blends normals), at two poses and with a gain other than 1, lit as the studio lights
(tests/js/three_page.html); and on the glTF's own MeshStandardMaterial under three's light, in
the same places."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from scripts.web_picture import changed, face_share, pixels
from studio.cli import main
from studio.core.formats.gltf.codec import save_gltf
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.furrow_controls import FurrowControls
from tests.test_web_player_js import node, random_links
from tests.three_page import served, shoot, studio_view, three

HARNESS = Path(__file__).parent / "js" / "module_activations.mjs"
SIZE = 800
GAIN = 0.5  # the poses' links' gain: a module that left out the gain wrinkles far more
# the squint: technique 1 wrinkles the eye corners, under the eyes and the cheeks, technique 2
# the eye corners only, so swapped techniques show; the surprise: the forehead, by both
POSES = ("squeeze", "surprise")
OTHER = {"t1": "t2", "t2": "t1"}


def overlap(a: np.ndarray, b: np.ndarray) -> float:
    """Shared changed pixels over all changed pixels of either picture."""
    return float((a & b).sum() / max((a | b).sum(), 1))


def module_activations(folder: Path, weights: np.ndarray) -> np.ndarray:
    link = folder / "node_modules" / "three"
    link.parent.mkdir(exist_ok=True)
    link.symlink_to(three(), target_is_directory=True)
    done = subprocess.run([node(), str(HARNESS), str(folder)], input=json.dumps(weights.tolist()),
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return np.asarray(json.loads(done.stdout))


@pytest.mark.parametrize(("seed", "onset"), [(5, 0.0), (23, 0.3)])
def test_the_module_gives_the_studio_s_activations_from_the_morph_influences(tmp_path, seed,
                                                                              onset):
    rng = np.random.default_rng(seed)
    project = make_test_face(561, texture_size=64, mask_size=32)
    random_links(project, rng)
    project.furrows = project.furrows.with_controls(None, FurrowControls(onset=onset))
    save_gltf(project, tmp_path / "face.glb")
    assert (tmp_path / "wrinkles.js").is_file() and (tmp_path / "example.html").is_file()
    names = [p.name for p in project.poses]
    weights = np.concatenate([
        np.eye(len(names)),
        rng.uniform(0, 1, (20, len(names))) * (rng.uniform(0, 1, (20, len(names))) < 0.5)])
    got = module_activations(tmp_path, weights)
    for row, values in zip(weights, got, strict=True):
        mix = dict(zip(names, row.tolist(), strict=True))
        np.testing.assert_allclose(values, project.activations(mix), atol=2e-3,
                                   err_msg=str(mix))
    assert np.ptp(got) > 0.5


@pytest.fixture(scope="module")
def shots(tmp_path_factory) -> dict:
    """none / t1 / t2 at each pose, weight 1: three.js's pictures and the studio's renders."""
    tmp = tmp_path_factory.mktemp("three")
    project = make_test_face(2172)
    for pose in POSES:
        links = project.influence.links[pose]
        project.influence.links[pose] = dict.fromkeys(links, GAIN)
    save_project(project, tmp / "face.wrinkle", backup=False)
    save_gltf(project, tmp / "face.glb")
    query = studio_view(project)
    out: dict = {}
    with served(tmp) as url:
        for technique in ("none", "t1", "t2"):  # the glTF's own PBR material and three's light
            shot = tmp / f"standard_{technique}.png"
            shoot(url, {**query, "technique": technique, "pose": POSES[0], "weight": "1",
                        "material": "standard"}, shot, SIZE)
            out["standard", POSES[0], technique] = pixels(shot)
        for pose in POSES:
            for technique in ("none", "t1", "t2"):
                shot = tmp / f"three_{pose}_{technique}.png"
                shoot(url, {**query, "technique": technique, "pose": pose, "weight": "1"},
                      shot, SIZE)
                render = tmp / f"studio_{pose}_{technique}.png"
                assert main(["render", str(tmp / "face.wrinkle"), "--pose", pose, "--weight",
                             "1", "--technique", technique, "--size", f"{SIZE}x{SIZE}",
                             "--frame", "face", "--yaw", "0", "--blend", "normal",
                             "-o", str(render)]) == 0
                out["three", pose, technique] = pixels(shot)
                out["studio", pose, technique] = pixels(render)
    return out


@pytest.mark.parametrize("pose", POSES)
@pytest.mark.parametrize("technique", ["t1", "t2"])
def test_each_technique_changes_the_same_pixels_on_three_js_as_in_the_studio(shots, pose,
                                                                               technique):
    three_js = changed(shots["three", pose, technique], shots["three", pose, "none"])
    studio = changed(shots["studio", pose, technique], shots["studio", pose, "none"])
    assert face_share(shots["three", pose, "none"]) >= 0.10
    assert abs(face_share(shots["three", pose, "none"])
               - face_share(shots["studio", pose, "none"])) < 0.01  # the same camera
    assert studio.mean() > 0.003
    assert overlap(three_js, studio) >= 0.9
    assert (three_js ^ studio).mean() <= 0.005
    if pose == "squeeze":
        other = changed(shots["studio", pose, OTHER[technique]], shots["studio", pose, "none"])
        assert overlap(three_js, other) < 0.6  # where the other technique would not be


@pytest.mark.core
def test_no_variant_shows_a_whole_wrinkled_map_as_the_skin_s_look(tmp_path):
    """A viewer offering the file's variants shows the wrinkled maps and masks as pictures
    (unlit), never the skin lit with a whole wrinkled map as its normal map (every wrinkle at
    once, unmasked); every wrinkled map is still offered, so its image stays in the file."""
    project = make_test_face(561, texture_size=64, mask_size=32)
    save_gltf(project, tmp_path / "face.glb")
    data = (tmp_path / "face.glb").read_bytes()
    doc = json.loads(data[20:20 + int.from_bytes(data[12:16], "little")])
    variants = doc["materials"][1:]
    assert variants
    for material in variants:
        assert "normalTexture" not in material, material["name"]
        assert "KHR_materials_unlit" in material["extensions"], material["name"]
    shown = {doc["images"][doc["textures"][m["pbrMetallicRoughness"]["baseColorTexture"]
                                           ["index"]]["source"]]["name"] for m in variants}
    assert set(doc["extras"]["wrinklePlayer"]["wrinkle_maps"]) <= shown


@pytest.mark.parametrize("technique", ["t1", "t2"])
def test_on_the_gltf_s_own_standard_material_the_wrinkles_show_in_the_same_places(
        shots, technique):
    """Physically based light is not the studio's: the changed pixels' edges move, their place
    does not."""
    pose = POSES[0]
    standard = changed(shots["standard", pose, technique], shots["standard", pose, "none"])
    studio = changed(shots["studio", pose, technique], shots["studio", pose, "none"])
    other = changed(shots["studio", pose, OTHER[technique]], shots["studio", pose, "none"])
    assert 0.7 < standard.mean() / studio.mean() < 1.4
    assert overlap(standard, studio) >= 0.65
    assert overlap(standard, other) < 0.6


def test_technique_2_on_three_js_waits_for_the_pose_s_onset(tmp_path):
    """With an onset of 0.6, the squint at 0.5 shows no technique-2 wrinkle (its rest moves
    with what the onset holds back, as the studio's WrinkleDrive), at 1 it does."""
    project = make_test_face(2172)
    project.furrows = project.furrows.with_controls(None, FurrowControls(onset=0.6))
    save_gltf(project, tmp_path / "face.glb")
    query = studio_view(project)
    shot = {}
    with served(tmp_path) as url:
        for technique, weight in (("none", "0.5"), ("t2", "0.5"), ("none", "1"), ("t2", "1")):
            path = tmp_path / f"{technique}_{weight}.png"
            shoot(url, {**query, "technique": technique, "pose": POSES[0], "weight": weight},
                  path, SIZE)
            shot[technique, weight] = pixels(path)
    assert changed(shot["t2", "0.5"], shot["none", "0.5"]).mean() == 0
    assert changed(shot["t2", "1"], shot["none", "1"]).mean() > 0.003
