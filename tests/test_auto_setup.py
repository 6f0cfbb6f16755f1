"""Automatic starting points from the key poses (issue 8's --auto, issue 10's strain → areas),
on a hand-built flat face whose numbers can be worked out on paper."""

from __future__ import annotations

import numpy as np
import pytest

from studio.cli import main
from studio.core.animation.poses import KeyPose
from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import save_obj
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.setup import auto_setup as auto
from studio.core.setup.wrinkle_synth import is_flat
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from studio.core.wrinkles.wdv import WdvArea

pytestmark = pytest.mark.core

N = 21  # vertices along each side of the grid: spacing 0.1 over [-1, 1]
SQUEEZE = 0.9  # the left half (x < 0) is squeezed to 90 % along x


def grid_mesh(n: int = N, uv_scale: tuple[float, float] = (1.0, 1.0)) -> FaceMesh:
    """A flat square face in z = 0 over [-1, 1]², UVs (x + 1)/2, (y + 1)/2 (optionally scaled),
    each grid cell split into two triangles along its (a, c) diagonal."""
    xs = np.linspace(-1.0, 1.0, n)
    x, y = np.meshgrid(xs, xs)
    rest = np.c_[x.ravel(), y.ravel(), np.zeros(n * n)].astype(np.float32)
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    triangles = np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    uvs = (rest[:, :2] + 1.0) / 2.0 * np.float32(uv_scale)
    return FaceMesh(rest, triangles, uvs, np.arange(n * n))


def squeezed(rest: np.ndarray, factor: float = SQUEEZE) -> np.ndarray:
    """The left half moved toward x = 0: x' = factor·x where x < 0; the right half stays."""
    out = rest.copy()
    out[:, 0] = np.where(rest[:, 0] < 0.0, rest[:, 0] * factor, rest[:, 0])
    return out


def grid_project(**poses: np.ndarray) -> Project:
    mesh = grid_mesh()
    textures = FaceTextures(flat_normal_map(8), flat_normal_map(8), flat_normal_map(8))
    return Project("grid", mesh, [KeyPose(k, v) for k, v in poses.items()], textures)


def uv_texel(shape: tuple[int, int], x: float, y: float) -> tuple[int, int]:
    """(row, column) of the mask texel over grid point (x, y)."""
    h, w = shape
    u, v = (x + 1.0) / 2.0, (y + 1.0) / 2.0
    return min(int((1.0 - v) * h), h - 1), min(int(u * w), w - 1)


@pytest.fixture
def face() -> Project:
    mesh = grid_mesh()
    return grid_project(squeeze=squeezed(mesh.rest),
                        shift=mesh.rest + np.float32([0.3, -0.2, 0.1]),
                        still=mesh.rest.copy())


# --- issue 8: auto setup -------------------------------------------------------------------------

# The squeeze maps x → 0.9·x on the left half: every triangle there has principal stretches 0.9
# (along x) and 1 (along y), so a principal compression of exactly 0.1, and the right half 0.
# An interior vertex of the left half averages only such triangles: 0.1, which is also the 98th
# percentile, so the auto mask maps it to (0.1 / 0.1 − 0.1) / 0.9 = 1.
INTERIOR_MASK = 1.0


def test_each_pose_gets_vectors_where_it_moves_and_a_mask_where_it_compresses(face):
    report = auto.auto_setup(face, mask_size=64, fraction=0.25)
    rest = face.mesh.rest
    # squeeze moves vertex x < 0 by 0.1·|x| along +x; Suggest keeps motion > 25 % of the
    # largest (0.1 at x = -1), i.e. x < -0.25
    area = face.wdv.areas[0]
    assert (area.name, area.pose) == ("squeeze", "squeeze")
    expected = rest[:, 0] < -0.25
    assert np.array_equal(area.authored, expected)
    assert np.allclose(area.directions[expected], [1.0, 0.0, 0.0], atol=1e-6)
    assert np.allclose(area.lengths[expected], 0.1 * np.abs(rest[expected, 0]), atol=1e-6)
    # shift moves every vertex by the same vector: vectors everywhere along it, but no mask
    shift = face.wdv.areas[1]
    assert shift.name == "shift" and shift.authored.all()
    assert np.allclose(shift.directions, np.float32([0.3, -0.2, 0.1]) / np.sqrt(0.14), atol=1e-6)
    assert [a.name for a in face.wdv.areas] == ["squeeze", "shift"]
    assert report.still_poses == ["still"] and report.flat_poses == ["shift", "still"]
    # one mask, from squeeze's compression: strong in the left half, nothing in the right
    (mask_area,) = face.influence.areas
    assert mask_area.name == "squeeze" and mask_area.mask.shape == (64, 64)
    assert mask_area.mask[uv_texel((64, 64), -0.5, 0.0)] == pytest.approx(INTERIOR_MASK, abs=1e-3)
    assert mask_area.mask[uv_texel((64, 64), 0.5, 0.0)] == 0.0
    assert face.influence.links == {"squeeze": {"squeeze": 1.0}}
    # the activation follows the pose
    assert face.influence.activations({"squeeze": 0.5})[0] == pytest.approx(0.5)
    assert "shift, still (compresses no skin)" in report.summary()


def test_the_mask_is_the_areas_panels_auto_mask(face):
    """Without not-face vertices, an auto-setup mask is the Auto mask button's (up to float32
    rounding: it measures compression with the strain mode's float32 edge lengths)."""
    report = auto.suggest_setup(face, mask_size=128)
    expected = mask_ops.auto_mask(face.mesh, face.pose("squeeze").positions, 128)
    np.testing.assert_allclose(report.influence_areas[0].mask, expected, atol=1e-5)
    assert face.influence.areas == [] and face.wdv.areas == []  # a suggestion changes nothing


def test_not_face_vertices_get_no_vectors_and_no_mask(face):
    rest = face.mesh.rest
    face.not_face = rest[:, 1] > 0.3  # the top of the grid is an "eye"
    auto.auto_setup(face, mask_size=64)
    squeeze = face.wdv.areas[0]
    assert not squeeze.authored[face.not_face].any()
    assert squeeze.authored[(rest[:, 0] < -0.3) & (rest[:, 1] < 0.2)].all()
    mask = face.influence.areas[0].mask
    assert mask[uv_texel(mask.shape, -0.5, 0.8)] == 0.0  # compressed, but not skin
    assert mask[uv_texel(mask.shape, -0.5, -0.5)] == pytest.approx(INTERIOR_MASK, abs=1e-3)


def test_a_pose_that_only_moves_not_face_vertices_moves_nothing(face):
    rest = face.mesh.rest
    eye = rest[:, 1] > 0.5
    blink = rest.copy()
    blink[eye, 2] += 0.2
    project = grid_project(blink=blink)
    project.not_face = eye
    report = auto.suggest_setup(project, mask_size=32)
    assert report.empty and report.still_poses == ["blink"] and report.flat_poses == ["blink"]


def test_names_are_unique_and_existing_areas_and_links_stay(face):
    face.wdv.areas.append(WdvArea.empty("squeeze", "squeeze", face.mesh.n_welded))
    face.influence.areas.append(InfluenceArea("squeeze", np.zeros((32, 32), np.float32)))
    face.influence.links = {"squeeze": {"squeeze": 0.5}, "shift": {"squeeze": 1.0}}
    report = auto.auto_setup(face)
    assert [a.name for a in face.wdv.areas] == ["squeeze", "squeeze 2", "shift"]
    assert [a.name for a in face.influence.areas] == ["squeeze", "squeeze 2"]
    assert face.influence.areas[1].mask.shape == (32, 32)  # the project's mask resolution
    assert face.influence.links == {"squeeze": {"squeeze": 0.5, "squeeze 2": 1.0},
                                    "shift": {"squeeze": 1.0}}
    assert [a.name for a in report.wdv_areas] == ["squeeze 2", "shift"]
    with pytest.raises(StudioError, match="32×32"):
        auto.suggest_setup(face, mask_size=64)


def test_areas_of_poses_are_those_linked_to_or_made_from_them(face):
    auto.auto_setup(face, mask_size=16)
    face.influence.links["shift"] = {"squeeze": 0.0}  # a zero gain is no link
    assert [a.name for a in auto.areas_of_poses(face, ["squeeze"])] == ["squeeze", "squeeze"]
    assert [type(a).__name__ for a in auto.areas_of_poses(face, ["shift", "still"])] == [
        "WdvArea"]
    assert auto.areas_of_poses(face, []) == []


def test_the_uv_raster_interpolates_like_rasterise_uv():
    mesh = grid_mesh(9)
    values = (mesh.rest[:, 0] * 0.3 + mesh.rest[:, 1] ** 2).astype(np.float32)
    raster = auto.UvRaster(mesh, 40)
    expected, covered = mask_ops.rasterise_uv(mesh.uvs, mesh.triangles, values, 40)
    np.testing.assert_allclose(raster.image(values), expected, atol=1e-5)
    assert np.array_equal(raster.triangle >= 0, covered)


def test_a_fresh_project_gets_the_default_mask_size():
    project = grid_project(squeeze=squeezed(grid_mesh().rest))
    report = auto.suggest_setup(project)
    assert report.influence_areas[0].mask.shape == (auto.DEFAULT_MASK_SIZE,) * 2


def test_new_with_auto_writes_a_project_with_areas(tmp_path, capsys):
    mesh = grid_mesh()
    save_obj(tmp_path / "neutral.obj", mesh)
    save_obj(tmp_path / "squeeze.obj", mesh, squeezed(mesh.rest))
    save_obj(tmp_path / "still.obj", mesh, mesh.rest)
    args = ["new", "--mesh", str(tmp_path / "neutral.obj"), "--pose",
            f"squeeze={tmp_path / 'squeeze.obj'}", "--pose", f"still={tmp_path / 'still.obj'}"]
    assert main([*args, "--auto", "-o", str(tmp_path / "auto.wrinkle")]) == 0
    out = capsys.readouterr().out
    assert "auto setup" in out and "still" in out and "synthesised" in out
    project = load_project(tmp_path / "auto.wrinkle")
    assert [a.name for a in project.wdv.areas] == ["squeeze"]
    assert [a.name for a in project.influence.areas] == ["squeeze"]
    assert project.influence.links == {"squeeze": {"squeeze": 1.0}}
    # no --wrinkle-normal: the flat placeholder became a map with furrows
    assert not is_flat(project.textures.normal_wrinkled)
    assert main([*args, "-o", str(tmp_path / "plain.wrinkle")]) == 0
    plain = load_project(tmp_path / "plain.wrinkle")
    assert plain.wdv.areas == [] and plain.influence.areas == []
    assert is_flat(plain.textures.normal_wrinkled)


# --- issue 10: the automatic mode's result, made editable ---------------------------------------

# An interior vertex of the squeezed half has 2 edges along x (shortened by 1 − 0.9 = 0.1), 2
# along y (unchanged) and 2 diagonals (1 − √(0.81 + 1)/√2 = 0.048689); its mean compression is
# (0.2 + 0.097378) / 6 = 0.049563, which the default gain (full at 12 %) makes 0.41302.
INTERIOR_WEIGHT = (2 * 0.1 + 2 * (1 - np.sqrt(0.81 + 1) / np.sqrt(2))) / 6 / 0.12


def test_strain_weights_by_hand(face):
    weights = auto.strain_weights(face, {"squeeze": 1.0})
    rest = face.mesh.rest
    interior = (rest[:, 0] < -0.15) & (rest[:, 0] > -0.95) & (np.abs(rest[:, 1]) < 0.95)
    assert np.allclose(weights[interior], INTERIOR_WEIGHT, atol=1e-5)
    assert not weights[rest[:, 0] > 0.05].any()
    assert auto.strain_weights(face, {"shift": 1.0}).max() < 1e-4  # float rounding at most


def test_strain_to_mask_reproduces_the_strain_at_the_current_weights(face):
    area, links = auto.strain_mask(face, {"squeeze": 1.0}, mask_size=64)
    assert area.name == "squeeze strain"
    assert area.mask[uv_texel((64, 64), -0.5, 0.0)] == pytest.approx(INTERIOR_WEIGHT, abs=1e-4)
    assert area.mask[uv_texel((64, 64), 0.5, 0.0)] == 0.0
    assert links == {"squeeze": {"squeeze strain": 1.0}}
    # at half the pose, the links still give activation 1 at these weights
    _, half = auto.strain_mask(face, {"squeeze": 0.5, "shift": 0.0}, mask_size=64)
    assert half == {"squeeze": {"squeeze strain": 2.0}}
    with pytest.raises(StudioError, match="neutral"):
        auto.strain_mask(face, {})
    with pytest.raises(StudioError, match="no skin is compressed"):
        auto.strain_mask(face, {"shift": 1.0}, mask_size=64)


def test_strain_to_wdv_area_takes_the_compressed_vertices_and_their_motion(face):
    area = auto.strain_wdv_area(face, {"squeeze": 1.0, "shift": 0.0})
    rest = face.mesh.rest
    assert (area.name, area.pose) == ("squeeze strain", "squeeze")
    interior = (rest[:, 0] < -0.15) & (rest[:, 0] > -0.95) & (np.abs(rest[:, 1]) < 0.95)
    assert area.authored[interior].all() and not area.authored[rest[:, 0] > -0.05].any()
    assert np.allclose(area.directions[area.authored], [1.0, 0.0, 0.0], atol=1e-6)
    assert np.allclose(area.lengths[area.authored],
                       0.1 * np.abs(rest[area.authored, 0]), atol=1e-6)
    face.not_face = rest[:, 1] > 0.0
    assert not auto.strain_wdv_area(face, {"squeeze": 1.0}).authored[face.not_face].any()
    with pytest.raises(StudioError, match=r"above 0\.99"):
        auto.strain_wdv_area(face, {"squeeze": 1.0}, threshold=0.99)


@pytest.mark.parametrize("stop_at", [1, 3, 5])  # during the set-up, at its end, in synthesis
def test_a_cancelled_auto_start_leaves_the_project_untouched(face, stop_at):
    calls = []

    def progress(done: int, total: int) -> bool:
        calls.append((done, total))
        return len(calls) < stop_at

    assert auto.auto_start(face, progress=progress) is None
    assert face.influence.areas == [] and face.wdv.areas == []
    assert face.textures.wrinkle_map_names == ["wrinkles"]
    assert is_flat(face.textures.normal_wrinkled)
    assert len(calls) == stop_at and all(0 < d <= t for d, t in calls)
    done = auto.auto_start(face, progress=lambda d, t: True)
    assert done is not None and face.influence.areas and not is_flat(face.textures.normal_wrinkled)


def _shown(area: WdvArea, delta: np.ndarray) -> np.ndarray:
    """Technique 2's visibility of ``area`` for the motion ``delta`` (the shader's formula)."""
    from studio.core.wrinkles.wdv import WdvSetup, visibility

    return visibility(delta, WdvSetup([area]).pack_slots(len(delta))).max(axis=1)


def test_two_other_poses_at_once_do_not_show_an_area_s_wrinkles_where_neither_squeezes():
    """Issue 38: an expression sums poses. Hand-computed on two vertices, the area's vectors
    along +x with a 20° cone: pose B moves them along (1, 1) (45°, outside the cone) and pose C
    along (1, −0.6) (31°, outside) — neither alone shows the wrinkles, but together they move
    along (2, 0.4) (11.3°, inside: 2.04 × (1 − 11.3/20) = 0.89 at full weight, its vectors
    being 1 long). Where
    neither squeezes the skin (vertex 0) the cone narrows below 11.3° and the sum shows
    nothing; where C squeezes it (vertex 1) the cone stays. The area's own pose, along its
    vectors, shows as before."""
    directions = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], np.float32)
    area = WdvArea("A", "A", directions, np.ones(2, np.float32), cone_angle_deg=20.0)
    b = np.array([[1.0, 1.0, 0.0]] * 2, np.float32)
    c = np.array([[1.0, -0.6, 0.0]] * 2, np.float32)
    assert _shown(area, b).max() == 0.0 and _shown(area, c).max() == 0.0
    np.testing.assert_allclose(_shown(area, b + c), 2.04 * (1.0 - 11.31 / 20.0), atol=1e-3)
    auto.narrow_cones([area], {"A": directions, "B": b, "C": c},
                      {"A": np.ones(2), "B": np.zeros(2), "C": np.array([0.0, 0.5])})
    cones = area.vertex_cones_deg()
    angle = np.degrees(np.arctan2(0.4, 2.0))
    assert cones[0] == pytest.approx(auto.CONE_SHRINK * angle, abs=1e-4) and cones[1] == 20.0
    shown = _shown(area, b + c)
    assert shown[0] == 0.0 and shown[1] > 0.5
    np.testing.assert_allclose(_shown(area, directions), 1.0)


def test_on_a_pose_s_placed_lines_only_poses_with_lines_of_their_own_keep_its_cones():
    """Both vertices lie on the lines anatomy placed for A. Pose B moves them along (1, 0.2)
    (11.3°, inside A's 20° cone) and squeezes the skin there (weight 1): without placed lines
    of its own its squeeze does not count on A's lines, and the cone narrows below 11.3° at
    both; pose C, the same motion, has placed lines (a cheek raise beside a squint) and keeps
    the cone where it squeezes (vertex 1). Without ``lines``, B's squeeze kept both."""
    directions = np.array([[1.0, 0.0, 0.0]] * 2, np.float32)
    motion = np.array([[1.0, 0.2, 0.0]] * 2, np.float32)
    angle = np.degrees(np.arctan2(0.2, 1.0))
    lines = {"A": np.array([True, True]), "C": np.array([False, True])}

    def cones(others: dict, squeezed: dict, placed: dict | None) -> np.ndarray:
        area = WdvArea("A", "A", directions, np.ones(2, np.float32), cone_angle_deg=20.0)
        auto.narrow_cones([area], {"A": directions, **others}, {"A": np.ones(2), **squeezed},
                          placed)
        return area.vertex_cones_deg()

    squeezing = {"B": np.ones(2)}
    np.testing.assert_allclose(cones({"B": motion}, squeezing, lines),
                               auto.CONE_SHRINK * angle, atol=1e-4)
    np.testing.assert_allclose(cones({"B": motion}, squeezing, None), 20.0)
    np.testing.assert_allclose(cones({"C": motion}, {"C": np.array([0.0, 1.0])}, lines),
                               [auto.CONE_SHRINK * angle, 20.0], atol=1e-4)
