"""The bundled sample face: exact sizes, sound topology, poses that fold the skin where the
wrinkles are painted, maps and presets that agree with the geometry, and the bump-to-normal
conversion they are baked with."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.sample.mesh import build_geometry
from studio.core.sample.synthetic import landmark_uvs, make_test_face, sample_landmarks
from studio.core.wrinkles.normalmap import flip_green, height_to_normal

pytestmark = pytest.mark.core

POSES = ["brow_raise_right", "brow_raise_left", "surprise", "squeeze", "frown"]
MASKS = ["forehead right", "forehead left", "between brows", "eye corner right",
         "eye corner left", "under eye right", "under eye left", "cheeks"]
# each mask's own landmark (the cheeks mask is checked at both cheeks)
MASK_LANDMARK = {
    "forehead right": ["forehead right"], "forehead left": ["forehead left"],
    "between brows": ["between brows"], "eye corner right": ["eye corner right"],
    "eye corner left": ["eye corner left"], "under eye right": ["under eye right"],
    "under eye left": ["under eye left"], "cheeks": ["cheek right", "cheek left"],
}
LANDMARK_NAMES = {"forehead", "forehead right", "forehead left", "between brows",
                  "eye corner right", "eye corner left", "under eye right", "under eye left",
                  "cheek right", "cheek left", "nose tip", "chin", "mouth"}


@pytest.fixture(scope="module")
def face():
    return make_test_face()


@pytest.fixture(scope="module")
def marks(face):
    return sample_landmarks(face)


def texel(image: np.ndarray, uv: np.ndarray) -> tuple[int, int]:
    """(row, column) of the texel under a UV point; row 0 is v = 1."""
    h, w = image.shape[:2]
    return (min(int((1.0 - uv[1]) * h), h - 1), min(int(uv[0] * w), w - 1))


def near(positions: np.ndarray, point: np.ndarray, radius: float) -> np.ndarray:
    return np.flatnonzero(np.linalg.norm(positions - point, axis=1) < radius)


def motion(face, pose: str) -> np.ndarray:
    return np.linalg.norm(face.pose(pose).positions - face.mesh.rest, axis=1)


def edges(face) -> np.ndarray:
    tri = face.mesh.welded_triangles
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0)


# --- size and topology --------------------------------------------------------------------------

@pytest.mark.parametrize("n", [561, 1071, 2091, 2172, 3111, 4131, 5151, 30000])
def test_welded_vertex_count_is_exact(n):
    geo = build_geometry(n)
    assert len(geo.rest) == n
    assert geo.weld.max() == n - 1 and len(np.unique(geo.weld)) == n


@pytest.mark.parametrize("n", [561, 2172])
def test_the_test_face_has_the_requested_vertices(n):
    project = make_test_face(n)
    assert project.mesh.n_welded == n
    for pose in project.poses:
        assert pose.positions.shape == (n, 3)


def test_project_basics(face):
    assert face.name == "Sample face"
    assert [p.name for p in face.poses] == POSES
    assert face.textures.diffuse.shape == (1024, 1024, 3)
    assert face.textures.normal_wrinkled.shape == (1024, 1024, 3)
    assert face.influence.resolution == (512, 512)


def test_surface_is_closed_and_faces_outward(face):
    mesh = face.mesh
    tri = mesh.welded_triangles
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert (counts == 2).all()  # closed, manifold, no duplicate faces
    p = mesh.rest.astype(np.float64)
    p0, p1, p2 = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    assert (np.linalg.norm(normal, axis=1) > 0).all()
    volume = np.einsum("ij,ij->i", p0, np.cross(p1, p2)).sum() / 6.0
    assert volume > 0  # counter-clockwise seen from outside
    centre = (p0 + p1 + p2) / 3.0 - np.array([0.0, 0.0, -0.12])
    assert (np.einsum("ij,ij->i", normal, centre) > 0).mean() > 0.99


def test_head_is_upright_facing_z_about_two_units(face, marks):
    lo, hi = face.mesh.bounds()
    assert 1.8 < hi[1] - lo[1] < 2.6
    assert abs(hi[1] + lo[1]) < 0.4  # centred near the origin
    assert marks["nose tip"][2] > face.mesh.rest[:, 2].max() - 0.05  # the nose points to +Z
    assert marks["forehead"][1] > marks["between brows"][1] > marks["nose tip"][1]
    assert marks["nose tip"][1] > marks["mouth"][1] > marks["chin"][1]
    assert marks["eye corner right"][0] < 0 < marks["eye corner left"][0]


def test_uvs_cover_the_square_with_a_seam_at_the_back(face):
    mesh = face.mesh
    assert mesh.uvs.min() >= 0.0 and mesh.uvs.max() <= 1.0
    split = np.bincount(mesh.weld) > 1
    assert split.sum() > 10  # render vertices split at the seam (and the poles)
    seam = np.flatnonzero(split[mesh.weld] & (np.isin(mesh.uvs[:, 0], [0.0, 1.0])))
    assert len(seam) > 0 and (mesh.rest[mesh.weld[seam], 2] < 0).all()  # behind the head
    uvs = landmark_uvs()
    face_u = [uvs[n][0] for n in ("eye corner right", "eye corner left")]
    face_v = [uvs[n][1] for n in ("forehead", "chin")]
    assert face_u[1] - face_u[0] > 0.35 and face_v[0] - face_v[1] > 0.45  # the face is big


def test_landmarks_lie_on_the_surface(face, marks):
    assert set(marks) == LANDMARK_NAMES
    rest = face.mesh.rest
    spacing = np.median(np.linalg.norm(rest[edges(face)[:, 0]] - rest[edges(face)[:, 1]], axis=1))
    for name, point in marks.items():
        assert point.shape == (3,)
        assert np.linalg.norm(rest - point, axis=1).min() < 1.5 * spacing, name
        assert point[2] > 0.2, name  # on the face, not the back of the head
    # the same place on the face at any resolution
    fine = sample_landmarks(make_test_face(5151))
    for name in marks:
        assert np.linalg.norm(fine[name] - marks[name]) < 0.03, name


# --- key poses ----------------------------------------------------------------------------------

def test_poses_share_topology_and_are_finite(face):
    for pose in face.poses:
        assert pose.positions.shape == face.mesh.rest.shape
        assert np.isfinite(pose.positions).all()
        assert motion(face, pose.name).max() > 0.03  # clearly visible
        assert motion(face, pose.name).max() < 0.15  # a few % of a 2-unit head


def _mean_motion(face, pose, marks, name, radius=0.08):
    return motion(face, pose)[near(face.mesh.rest, marks[name], radius)].mean()


def test_single_brow_raises_move_their_own_side(face, marks):
    for pose, own, other in (("brow_raise_right", "forehead right", "forehead left"),
                             ("brow_raise_left", "forehead left", "forehead right")):
        mine = _mean_motion(face, pose, marks, own)
        theirs = _mean_motion(face, pose, marks, other)
        assert mine > 0.02 and mine > 5 * theirs, pose
        assert _mean_motion(face, pose, marks, "chin") < 1e-4
        assert _mean_motion(face, pose, marks, "mouth") < 1e-3
        up = face.pose(pose).positions - face.mesh.rest
        moved = near(face.mesh.rest, marks[own], 0.08)
        assert (up[moved, 1] > 0).all()  # upward


def test_poses_stay_in_their_regions(face, marks):
    assert _mean_motion(face, "surprise", marks, "chin") < 1e-3
    assert _mean_motion(face, "frown", marks, "chin") < 1e-3
    assert _mean_motion(face, "frown", marks, "between brows") > 0.01
    assert _mean_motion(face, "squeeze", marks, "eye corner right") > 0.01
    assert _mean_motion(face, "squeeze", marks, "eye corner left") > 0.01
    assert _mean_motion(face, "squeeze", marks, "forehead") < 0.003
    back = face.mesh.rest[:, 2] < -0.2
    for pose in POSES:
        assert motion(face, pose)[back].max() < 1e-6, pose


def _edge_ratio(face, pose, centre, radius, axis):
    """Mean length after / before of the edges near a point that run mostly along an axis."""
    e = edges(face)
    rest = face.mesh.rest.astype(np.float64)
    moved = face.pose(pose).positions.astype(np.float64)
    mid = 0.5 * (rest[e[:, 0]] + rest[e[:, 1]])
    d0 = rest[e[:, 1]] - rest[e[:, 0]]
    along = np.abs(d0[:, axis]) > 0.7 * np.linalg.norm(d0, axis=1)
    pick = (np.linalg.norm(mid - centre, axis=1) < radius) & along
    assert pick.sum() >= 3
    d1 = moved[e[pick, 1]] - moved[e[pick, 0]]
    return np.linalg.norm(d1, axis=1).sum() / np.linalg.norm(d0[pick], axis=1).sum()


def test_poses_compress_the_skin_where_wrinkles_form(face, marks):
    # horizontal forehead lines: the forehead shortens vertically
    assert _edge_ratio(face, "surprise", marks["forehead"], 0.15, axis=1) < 0.95
    assert _edge_ratio(face, "brow_raise_right", marks["forehead right"], 0.1, axis=1) < 0.95
    # vertical frown lines: the skin between the brows shortens horizontally
    assert _edge_ratio(face, "frown", marks["between brows"], 0.08, axis=0) < 0.95
    # crow's feet and under-eye lines
    for side in ("right", "left"):
        centre = marks[f"eye corner {side}"]
        ratio = min(_edge_ratio(face, "squeeze", centre, 0.06, axis=0),
                    _edge_ratio(face, "squeeze", centre, 0.06, axis=1))
        assert ratio < 0.9, side
        assert _edge_ratio(face, "squeeze", marks[f"under eye {side}"], 0.08, axis=1) < 0.97


# --- maps ---------------------------------------------------------------------------------------

def _back_of_head_uvs(face) -> np.ndarray:
    mesh = face.mesh
    return mesh.uvs[mesh.rest[mesh.weld, 2] < -0.2]


def _window(image, uv, radius=6):
    r, c = texel(image, uv)
    return image[max(r - radius, 0):r + radius + 1, max(c - radius, 0):c + radius + 1]


MAP_REGIONS = {  # the sample's two wrinkled maps, each with the regions whose wrinkles it holds
    "brow": ("forehead", "forehead right", "forehead left", "between brows"),
    "eyes and cheeks": ("eye corner right", "eye corner left", "under eye right",
                        "under eye left"),
}


def test_each_wrinkled_map_differs_only_where_its_wrinkles_are(face):
    neutral = face.textures.normal_neutral.astype(int)
    uvs = landmark_uvs()
    assert face.textures.wrinkle_map_names == list(MAP_REGIONS)
    for map_name, regions in MAP_REGIONS.items():
        wrinkled = face.textures.wrinkle_maps[map_name].astype(int)
        others = [r for other, rs in MAP_REGIONS.items() if other != map_name for r in rs]
        for name in regions:
            radius = 30 if name == "between brows" else 12  # frown lines flank the landmark
            diff = np.abs(_window(wrinkled, uvs[name], radius)
                          - _window(neutral, uvs[name], radius))
            assert diff.max() > 40, (map_name, name)  # clearly visible when fully blended
        for name in (*others, "chin", "nose tip"):
            diff = np.abs(_window(wrinkled, uvs[name]) - _window(neutral, uvs[name]))
            assert diff.max() <= 1, (map_name, name)
        # the back of the head has no wrinkles at all
        for uv in _back_of_head_uvs(face):
            assert (wrinkled[texel(wrinkled, uv)] == neutral[texel(neutral, uv)]).all()


def test_neutral_map_is_nearly_flat(face):
    n = face.textures.normal_neutral.astype(int)
    assert np.abs(n - [128, 128, 255]).mean() < 2.0
    assert np.abs(n - [128, 128, 255]).max() <= 12


def test_wrinkles_are_soft(face):
    """Anti-aliased: neighbouring texels never jump by more than a fraction of the range."""
    w = face.textures.normal_wrinkled.astype(int)
    for axis in (0, 1):
        jumps = np.abs(np.diff(w, axis=axis)).max(axis=2)
        assert jumps.max() < 100, axis
        assert np.percentile(jumps[jumps > 4], 99) < 70, axis


def test_diffuse_reads_as_a_face(face):
    d = face.textures.diffuse.astype(float)
    uvs = landmark_uvs()
    skin = _window(d, uvs["cheek right"]).reshape(-1, 3).mean(0)
    lips = _window(d, uvs["mouth"] + np.array([0.0, 0.012]), 2).reshape(-1, 3).mean(0)
    assert lips[0] / lips[1] > 1.3 * skin[0] / skin[1]  # redder lips
    forehead = _window(d, uvs["forehead"]).reshape(-1, 3).mean(0)
    # eyebrows: somewhere above each eye the colour is much darker than the forehead
    for side in ("right", "left"):
        eye = uvs[f"under eye {side}"]
        r0, c0 = texel(d, eye)
        column = d[r0 - 200:r0, c0].mean(axis=1)
        assert column.min() < 0.6 * forehead.mean(), side
    # eyes: whites and a dark pupil near each eye
    for side in ("right", "left"):
        r0, c0 = texel(d, uvs[f"under eye {side}"])
        patch = d[r0 - 80:r0, c0 - 60:c0 + 60]
        assert patch.min(axis=2).max() > 200 and patch.max(axis=2).min() < 40, side


# --- technique presets --------------------------------------------------------------------------

def test_influence_preset(face):
    setup = face.influence
    assert [a.name for a in setup.areas] == MASKS
    colours = {a.colour for a in setup.areas}
    assert len(colours) == len(MASKS)
    assert all(a.activation == 0.0 for a in setup.areas)
    assert setup.links == {
        "brow_raise_right": {"forehead right": 1.0},
        "brow_raise_left": {"forehead left": 1.0},
        "surprise": {"forehead right": 1.0, "forehead left": 1.0},
        "squeeze": {"eye corner right": 1.0, "eye corner left": 1.0, "under eye right": 1.0,
                    "under eye left": 1.0, "cheeks": 1.0},
        "frown": {"between brows": 1.0},
    }
    uvs = landmark_uvs()
    for area in setup.areas:
        m = area.mask
        assert m.dtype == np.float32 and m.shape == (512, 512)
        assert m.min() >= 0.0 and m.max() <= 1.0
        for name in MASK_LANDMARK[area.name]:
            assert m[texel(m, uvs[name])] > 0.9, (area.name, name)
        assert _window(m, uvs["chin"]).max() < 1e-3, area.name
        assert max(m[texel(m, uv)] for uv in _back_of_head_uvs(face)) == 0.0
        # soft edges: a band of partial values, not a hard cut-out
        assert ((m > 0.05) & (m < 0.95)).sum() > 0.2 * (m >= 0.95).sum(), area.name


def test_single_sided_masks_stay_on_their_side(face):
    uvs = landmark_uvs()
    masks = {a.name: a.mask for a in face.influence.areas}
    for side, other in (("right", "left"), ("left", "right")):
        for kind in ("forehead", "eye corner", "under eye"):
            m = masks[f"{kind} {side}"]
            name = f"{kind} {other}" if kind != "forehead" else f"forehead {other}"
            assert m[texel(m, uvs[name])] < 0.05, (kind, side)


def test_linked_pose_activates_its_areas(face):
    act = face.influence.activations({"brow_raise_right": 1.0})
    names = [a.name for a in face.influence.areas]
    assert act[names.index("forehead right")] == 1.0
    assert act[names.index("forehead left")] == 0.0


def test_wdv_preset(face, marks):
    wdv = face.wdv
    assert wdv.expression_factor == 1.0 and wdv.scale_free is True
    assert [(a.name, a.pose) for a in wdv.areas] == [
        ("forehead", "surprise"), ("eye corners", "squeeze"), ("between brows", "frown")]
    assert len({a.colour for a in wdv.areas}) == 3
    rest = face.mesh.rest
    region = {"forehead": ["forehead"], "eye corners": ["eye corner right", "eye corner left"],
              "between brows": ["between brows"]}
    for area in wdv.areas:
        assert area.cone_angle_deg == 20.0
        authored = area.authored
        assert authored.sum() >= 4, area.name
        length = np.linalg.norm(area.directions, axis=1)
        np.testing.assert_allclose(length[authored], 1.0, atol=1e-5)
        assert (area.directions[~authored] == 0).all() and (area.lengths[~authored] == 0).all()
        delta = face.pose(area.pose).positions.astype(np.float64) - rest
        np.testing.assert_allclose(area.lengths[authored],
                                   np.linalg.norm(delta[authored], axis=1), rtol=1e-4)
        cos = np.einsum("ij,ij->i", area.directions[authored], delta[authored])
        assert (cos > 0).all()
        for name in region[area.name]:  # authored around its landmark(s)
            assert authored[near(rest, marks[name], 0.06)].any(), (area.name, name)
        assert not authored[near(rest, marks["chin"], 0.2)].any()


# --- caching and speed --------------------------------------------------------------------------

def test_callers_get_independent_copies():
    a = make_test_face()
    a.mesh.rest[:] = 0.0
    a.textures.diffuse[:] = 0
    a.influence.areas[0].mask[:] = 1.0
    a.poses.pop()
    b = make_test_face()
    assert np.ptp(b.mesh.rest[:, 1]) > 1.0
    assert b.textures.diffuse.max() > 0
    assert b.influence.areas[0].mask.min() == 0.0
    assert len(b.poses) == 5


def test_rejects_too_few_vertices():
    with pytest.raises(ValueError):
        make_test_face(10)


# --- bump to normal -----------------------------------------------------------------------------

def encode(n):
    n = np.asarray(n, float) / np.linalg.norm(n)
    return np.floor((n * 0.5 + 0.5) * 255 + 0.5).astype(int)


def test_flat_height_gives_the_flat_normal():
    out = height_to_normal(np.full((8, 9), 3.25), strength=5.0)
    assert out.dtype == np.uint8 and out.shape == (8, 9, 3)
    assert (out == [128, 128, 255]).all()


def test_ramp_toward_u_tilts_the_normal_to_minus_x():
    h = np.tile(0.5 * np.arange(6, dtype=float), (5, 1))  # rises 0.5 per column (+u)
    out = height_to_normal(h, strength=1.0).astype(int)
    # interior: gx = h(x-1) - h(x+1) = -1 → n = (-0.7071, 0, 0.7071) → (37, 128, 218)
    assert (out[:, 1:-1] == encode([-1.0, 0.0, 1.0])).all()
    assert (out[:, 1:-1] == [37, 128, 218]).all()
    # clamped edges see half the difference: normalize(-0.5, 0, 1)
    assert (out[:, 0] == encode([-0.5, 0.0, 1.0])).all()
    assert (out[:, -1] == encode([-0.5, 0.0, 1.0])).all()
    # strength scales the slope
    strong = height_to_normal(h, strength=2.0).astype(int)
    assert (strong[:, 1:-1] == encode([-2.0, 0.0, 1.0])).all()


def test_ramp_toward_v_tilts_the_normal_to_minus_y():
    rows = np.arange(6, dtype=float)[::-1]  # row 0 (top, v = 1) is highest: rising toward +v
    h = np.tile(0.5 * rows[:, None], (1, 4))
    out = height_to_normal(h).astype(int)
    assert (out[1:-1] == encode([0.0, -1.0, 1.0])).all()
    assert (out[1:-1] == [128, 37, 218]).all()


def test_per_axis_strength_and_sixteen_bits():
    h = np.add.outer(np.arange(5)[::-1], np.arange(5)).astype(float) * 0.5
    out = height_to_normal(h, strength=(1.0, 2.0), bits=16).astype(float)
    n = np.array([-1.0, -2.0, 1.0]) / np.sqrt(6.0)
    np.testing.assert_allclose(out[2, 2], np.floor((n * 0.5 + 0.5) * 65535 + 0.5))


def test_flip_green():
    img = np.array([[[10, 20, 30], [128, 0, 255]]], dtype=np.uint8)
    flipped = flip_green(img)
    assert flipped.tolist() == [[[10, 235, 30], [128, 255, 255]]]
    assert img[0, 0, 1] == 20  # the input is untouched
    assert (flip_green(flipped) == img).all()
    wide = np.array([[[0, 1000, 0]]], dtype=np.uint16)
    assert flip_green(wide)[0, 0, 1] == 65535 - 1000
