"""Cavity and colour with every wrinkled map (issue 46, point 1), on a face set up as ``new
--auto`` sets one up: in millimetres, Z up and facing −Y, its UVs one cell of the square,
with one pose (an artist's name for it) that scrunches a band of the forehead up (horizontal
furrows) and stretches a band below it.

Pixels are taken in named regions of the skin look's render: the bottoms of the creases (the
cavity map's darkest texels), the compressed band between them, the stretched band, and skin
the pose only carries along (no strain, no furrow).
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.setup.auto_setup import auto_start
from studio.core.wrinkles.skin_tone import TINT_ONE
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

POSE = "Brows_Up_L+R"
N = 61  # vertices a side
WIDTH, HEIGHT = 160.0, 200.0  # millimetres
U0, U1, V0, V1 = 0.1, 0.6, 0.3, 0.9  # the face's UV cell
PIXELS = 320
SCRUNCH = (10.0, 70.0, 0.8)  # z from, z to (mm), factor: the band shortened to 80 %
STRETCH = (-70.0, -10.0, 1.2)  # … and this one lengthened by 20 %


def posed_z(z: np.ndarray) -> np.ndarray:
    """Where the pose takes a height: the scrunched band shortened toward its foot, the
    stretched band lengthened toward its top, the skin beyond each band carried along."""
    z = np.asarray(z, np.float64)
    lo, hi, k = SCRUNCH
    out = np.where(z > hi, z - (1 - k) * (hi - lo), np.where(z > lo, lo + (z - lo) * k, z))
    lo, hi, k = STRETCH
    return np.where(z < lo, z - (k - 1) * (hi - lo), np.where(z < hi, hi + (z - hi) * k, out))


def uv_of(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.stack([U0 + (U1 - U0) * (x + WIDTH / 2) / WIDTH,
                     V0 + (V1 - V0) * (z + HEIGHT / 2) / HEIGHT], -1)


def make_face() -> Project:
    xs, zs = np.meshgrid(np.linspace(-WIDTH / 2, WIDTH / 2, N),
                         np.linspace(-HEIGHT / 2, HEIGHT / 2, N))
    rest = np.c_[xs.ravel(), np.zeros(N * N), zs.ravel()].astype(np.float32)
    idx = np.arange(N * N).reshape(N, N)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    triangles = np.r_[np.c_[a, b, c], np.c_[a, c, d]]  # facing −Y
    mesh = FaceMesh(rest, triangles, uv_of(rest[:, 0], rest[:, 2]).astype(np.float32),
                    np.arange(N * N))
    pose = rest.copy()
    pose[:, 2] = posed_z(rest[:, 2])
    textures = FaceTextures(np.full((512, 512, 3), (200, 160, 140), np.uint8),
                            flat_normal_map(512), flat_normal_map(512))
    project = Project("forehead", mesh, [KeyPose(POSE, pose)], textures)
    camera = OrbitCamera(yaw=0.0, pitch=0.0, basis=np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]).T)  # left +X, up +Z, front −Y
    both = np.r_[rest, pose]
    camera.frame(both.min(axis=0), both.max(axis=0), 1.05)
    project.view["camera"] = camera.to_dict()
    return project


@pytest.fixture(scope="module")
def face() -> Project:
    project = make_face()
    assert auto_start(project) is not None
    return project


def texel(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    rows = np.clip(((1.0 - uv[..., 1]) * h).astype(int), 0, h - 1)
    cols = np.clip((uv[..., 0] * w).astype(int), 0, w - 1)
    return image[rows, cols]


def regions(face: Project) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{region: (rest x, rest z) of its points}: the crease bottoms (the cavity's darkest
    tenth in the scrunched band), the compressed band, the stretched band, carried skin."""
    x, z = np.meshgrid(np.linspace(-60, 60, 121), np.linspace(-95, 95, 381))
    x, z = x.ravel(), z.ravel()
    cavity = texel(face.textures.cavity_maps["wrinkles"], uv_of(x, z)).astype(float)
    band = (z > SCRUNCH[0] + 8) & (z < SCRUNCH[1] - 8)
    deepest = band & (cavity <= np.percentile(cavity[band], 10))
    stretched = (z > STRETCH[0] + 8) & (z < STRETCH[1] - 8)
    carried = z < STRETCH[0] - 8
    return {name: (x[m], z[m]) for name, m in (("crease bottoms", deepest),
                                                ("compressed", band),
                                                ("stretched", stretched),
                                                ("carried", carried))}


def pixels(image: np.ndarray, camera: OrbitCamera, x: np.ndarray, z: np.ndarray,
           weight: float) -> np.ndarray:
    """(n, 3) the render's colours over these skin points, posed at ``weight``."""
    posed = z + weight * (posed_z(z) - z)
    px, _ = camera.project(np.c_[x, np.zeros_like(x), posed], PIXELS, PIXELS)
    cols, rows = px[:, 0].astype(int), px[:, 1].astype(int)
    return image[rows, cols].astype(np.float64)


@pytest.fixture(scope="module")
def renders(face, gl_context):
    """The skin look at the pose's full weight (and at none) with the face's tone maps, with
    its cavity map left open, and with no tone maps (a face set up before issue 46)."""
    out = {}
    settings = RenderSettings(technique="t1", look="skin", light_rig="studio")
    textures = face.textures
    cavity, colour = dict(textures.cavity_maps), dict(textures.colour_maps)
    with OffscreenStudio(face, PIXELS, PIXELS, samples=0, ctx=gl_context) as studio:
        for name, (cavities, colours) in {"toned": (cavity, colour),
                                          "no cavity": ({}, colour),
                                          "plain": ({}, {})}.items():
            textures.cavity_maps, textures.colour_maps = dict(cavities), dict(colours)
            studio.scene.reload_textures()
            for weight in (0.0, 1.0):
                out[name, weight] = studio.render(settings, {POSE: weight})
        camera = studio.camera
    textures.cavity_maps, textures.colour_maps = cavity, colour
    return out, camera


def test_the_set_up_makes_cavity_and_colour_with_the_furrows(face):
    textures = face.textures
    assert set(textures.cavity_maps) == set(textures.colour_maps) == {"wrinkles"}
    places = regions(face)
    cavity = textures.cavity_maps["wrinkles"]
    colour = textures.colour_maps["wrinkles"].astype(float)
    deep = texel(cavity, uv_of(*places["crease bottoms"])).astype(float)
    assert deep.mean() < 200  # the furrows' bottoms lie in shadow …
    assert (texel(cavity, uv_of(*places["carried"])) == 255).all()  # … open skin does not
    assert (texel(cavity, uv_of(*places["stretched"])) == 255).all()
    flushed = texel(colour, uv_of(*places["compressed"])).mean(axis=0)
    pale = texel(colour, uv_of(*places["stretched"])).mean(axis=0)
    carried = texel(colour, uv_of(*places["carried"]))
    assert flushed[0] >= TINT_ONE - 1 and flushed[1] < TINT_ONE - 10  # redder: less green
    assert pale[1] > TINT_ONE + 4 and pale[2] > TINT_ONE + 4  # paler
    assert np.abs(carried - TINT_ONE).max() <= 1  # moved, not strained: unchanged


def test_the_bottom_of_a_crease_darkens_with_cavity(face, renders):
    images, camera = renders
    places = regions(face)
    toned = pixels(images["toned", 1.0], camera, *places["crease bottoms"], 1.0).mean()
    open_ = pixels(images["no cavity", 1.0], camera, *places["crease bottoms"], 1.0).mean()
    assert toned < open_ - 12, (toned, open_)
    carried = [pixels(images[k, 1.0], camera, *places["carried"], 1.0)
               for k in ("toned", "no cavity")]
    assert np.abs(carried[0] - carried[1]).max() <= 1  # open skin keeps its light


def test_a_compressing_pose_flushes_its_skin_with_the_colour_map(face, renders):
    """(The stretched band's paler tint shows only where a wrinkle weight reaches it: the
    set-up's mask covers the compressed skin, so there it does not.)"""
    images, camera = renders

    def redness(name: str, region: str) -> float:
        rgb = pixels(images[name, 1.0], camera, *regions(face)[region], 1.0)
        return float((rgb[:, 0] / np.maximum(rgb[:, 1], 1.0)).mean())

    assert redness("no cavity", "compressed") > redness("plain", "compressed") + 0.1
    assert redness("no cavity", "carried") == pytest.approx(redness("plain", "carried"),
                                                            abs=0.01)


def test_at_no_weight_the_tone_maps_change_nothing(renders):
    images, _ = renders
    assert np.array_equal(images["toned", 0.0], images["plain", 0.0])


def test_the_project_file_keeps_them_and_an_older_file_has_none(face, tmp_path):
    save_project(face, tmp_path / "toned.wrinkle")
    loaded = load_project(tmp_path / "toned.wrinkle").textures
    for kind in ("cavity_maps", "colour_maps"):
        for name, image in getattr(face.textures, kind).items():
            assert np.array_equal(getattr(loaded, kind)[name], image)
    old = make_face()  # as a file written before issue 46: no tone members
    save_project(old, tmp_path / "old.wrinkle")
    assert not load_project(tmp_path / "old.wrinkle").textures.has_tone
