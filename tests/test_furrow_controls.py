"""The furrow controls (issue 45, point 6): depth, spacing and sharpness shape the synthesised
furrows as computed by hand, the default leaves today's maps alone, a control remakes only its
pose's maps, and a project file keeps them (and reads files made before them)."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import ProjectError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.setup import wrinkle_synth as synth
from studio.core.setup.furrow_maps import FurrowMaps
from studio.core.wrinkles.furrow_controls import FurrowControls, FurrowSettings
from studio.core.wrinkles.normal_tilt import decode_normals
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map

pytestmark = pytest.mark.core

SIZE = 256
OPTIONS = synth.SynthOptions(size=SIZE, spacing=8.0, depth=1.6)
N = 49  # vertices along each side of the hand-made strip
HALF = 60.0  # mm: the strip spans ±60 mm across and up (Z up, as a production head)
UV0, UV_SPAN = np.float32([0.12, 0.07]), np.float32([0.78, 0.86])  # an off-centre UV box


def strip_mesh() -> FaceMesh:
    """A flat patch of skin in the x–z plane, in millimetres, Z up, its UVs in a box that
    neither starts at 0 nor is square: u along x, v along z."""
    s = np.linspace(-HALF, HALF, N)
    x, z = np.meshgrid(s, s)
    rest = np.c_[x.ravel(), np.zeros(N * N), z.ravel()].astype(np.float32)
    idx = np.arange(N * N).reshape(N, N)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    uvs = UV0 + (rest[:, [0, 2]] + HALF) / (2.0 * HALF) * UV_SPAN
    return FaceMesh(rest, np.r_[np.c_[a, b, c], np.c_[a, c, d]], uvs.astype(np.float32),
                    np.arange(N * N))


BAND = 20.0  # mm: the strip of skin a brow raise squeezes


def raised(rest: np.ndarray) -> np.ndarray:
    """A brow raise on the strip: the skin from z = 0 up to ``BAND`` squeezed by 15 % along
    z, the skin above it carried down with it, the skin below still — lines across z (along
    x) on that strip only."""
    out = rest.copy()
    z = rest[:, 2]
    out[:, 2] = np.where(z > BAND, z - 0.15 * BAND, np.where(z > 0.0, 0.85 * z, z))
    return out


COLUMNS = np.s_[:, 60:200]  # texel columns well inside the strip's u range


def valleys_per_column(depth: np.ndarray) -> float:
    """Furrow bottoms met walking down each column (local maxima of depth, not faint)."""
    d = depth[COLUMNS]
    bottoms = (d[1:-1] > d[:-2]) & (d[1:-1] >= d[2:]) & (d[1:-1] > 0.1 * float(d.max()))
    return float(bottoms.sum(axis=0).mean())


@pytest.fixture(scope="module")
def strip_fields():
    mesh = strip_mesh()
    return mesh, {factor: synth.furrow_fields(mesh, [raised(mesh.rest)], OPTIONS,
                                              spacings=[factor]) for factor in (1.0, 2.0)}


def depth_of(fields, **controls: float) -> np.ndarray:
    return synth.furrow_depths(synth.controlled(fields, [FurrowControls(**controls)]), SIZE)


def test_twice_the_spacing_lays_half_as_many_lines_across_the_squeezed_strip(strip_fields):
    _, fields = strip_fields
    once = valleys_per_column(depth_of(fields[1.0]))
    twice = valleys_per_column(depth_of(fields[2.0]))
    assert once >= 5.0  # a few lines, the strip's compression smoothed over 1.5 spacings
    assert twice / once == pytest.approx(0.5, abs=0.1)


def test_twice_the_depth_doubles_the_height_and_steepens_the_walls_as_computed(strip_fields):
    _, fields = strip_fields
    once, twice = depth_of(fields[1.0]), depth_of(fields[1.0], depth=2.0)
    assert once.max() > 0.5 and np.array_equal(twice, 2.0 * once)  # exactly, texel by texel
    tilts = []
    for depth in (once, twice):
        height = (-OPTIONS.depth * depth).astype(np.float32)
        normal = synth.height_to_map(height, flat_normal_map(SIZE), over_neutral=False)
        tilt = np.degrees(np.arccos(np.clip(decode_normals(normal)[..., 2], -1.0, 1.0)))
        # by hand: central differences over two texels (strength 0.5), eased toward 35°
        gy, gx = np.gradient(height.astype(np.float64))
        limit = np.tan(np.radians(synth.MAX_TILT))
        slope = limit * np.tanh(np.hypot(gx, gy) / limit)
        inside = np.s_[8:-8, 8:-8]
        assert np.abs(tilt[inside] - np.degrees(np.arctan(slope[inside]))).max() < 1.5
        tilts.append(float(np.percentile(tilt[COLUMNS][depth[COLUMNS] != 0.0], 90)))
        assert tilt.max() <= synth.MAX_TILT + 0.5  # however deep, never a cliff
    assert tilts[1] > tilts[0] + 5.0  # p90 of the walls: about 21° → 31°, under 35°


def test_sharper_furrows_are_narrower_between_flatter_skin(strip_fields):
    _, fields = strip_fields
    widths = []
    for sharpness in (1.0, 2.0):
        d = depth_of(fields[1.0], sharpness=sharpness)[COLUMNS]
        widths.append(float((d > 0.5 * d.max()).sum()))
    # the valley ((1 + cos φ)/2)^s is above half its depth over |φ| < acos(2·0.5^(1/s) − 1):
    # 41.6 % of a period at the synthesis's s = 1.5, 30.0 % at 3
    share = [np.arccos(2.0 * 0.5 ** (1.0 / s) - 1.0) / np.pi for s in (1.5, 3.0)]
    assert widths[1] / widths[0] == pytest.approx(share[1] / share[0], abs=0.1)


def test_pose_controls_apply_on_top_of_those_for_all_poses():
    settings = FurrowSettings().with_controls(None, FurrowControls(depth=2.0, spacing=1.5))
    settings = settings.with_controls("Brow_Up", FurrowControls(depth=0.5, sharpness=2.0))
    assert settings.of("Brow_Up") == FurrowControls(depth=1.0, spacing=1.5, sharpness=2.0)
    assert settings.of("Jaw_Open") == FurrowControls(depth=2.0, spacing=1.5)
    with pytest.raises(ValueError, match=r"spacing must be a number from 0\.25 to 4"):
        FurrowControls(spacing=0.0)


# --- a project's synthesised maps ------------------------------------------------------------

def strip_project() -> Project:
    """The strip with two poses whose lines cross (so ``new --auto`` gives them a map each),
    a flat placeholder to fill, and a neutral map of its own with some detail."""
    mesh = strip_mesh()
    sideways = mesh.rest.copy()
    sideways[:, 0] = np.where(mesh.rest[:, 0] < 0.0, mesh.rest[:, 0] * 0.85, mesh.rest[:, 0])
    rng = np.random.default_rng(3)
    neutral = flat_normal_map(SIZE)
    neutral[..., :2] = (128 + rng.integers(-6, 7, (SIZE, SIZE, 2))).astype(np.uint8)
    textures = FaceTextures(np.full((SIZE, SIZE, 3), 200, np.uint8), neutral,
                            flat_normal_map(SIZE))
    return Project("strip", mesh, [KeyPose("Forehead_Raise", raised(mesh.rest)),
                                   KeyPose("Cheek_Pinch_L", sideways)], textures)


@pytest.fixture(scope="module")
def synthesised():
    project = strip_project()
    made = synth.fill_placeholder(project, OPTIONS)
    return project, made


def test_auto_synthesis_records_its_maps_and_default_controls_make_them_again(synthesised):
    project, made = synthesised
    assert sorted(p for poses in made.values() for p in poses) == ["Cheek_Pinch_L",
                                                                   "Forehead_Raise"]
    assert {name: list(r.poses) for name, r in project.furrows.maps.items()} == made
    maps = FurrowMaps()
    for name in made:  # the default controls are the look as synthesised, to the byte
        assert np.array_equal(maps.made(project, name), project.textures.wrinkle_maps[name])


def test_a_pose_control_remakes_only_that_pose_s_map(synthesised):
    project, made = synthesised
    project = _copy(project)
    before = dict(project.textures.wrinkle_maps)
    maps = FurrowMaps()
    maps.adopt(project)
    project.furrows = project.furrows.with_controls("Forehead_Raise", FurrowControls(depth=2.0))
    changed = maps.remake(project, list(project.furrows.maps))
    mine = next(n for n, poses in made.items() if "Forehead_Raise" in poses)
    assert changed == [mine]
    assert not np.array_equal(project.textures.wrinkle_maps[mine], before[mine])
    assert all(project.textures.wrinkle_maps[n] is before[n] for n in made if n != mine)
    # back to 1: the map as synthesised again, to the byte (what an undo shows)
    project.furrows = project.furrows.with_controls("Forehead_Raise", FurrowControls())
    assert maps.remake(project, list(project.furrows.maps)) == [mine]
    assert np.array_equal(project.textures.wrinkle_maps[mine], before[mine])


def test_a_map_the_user_replaced_is_left_alone(synthesised):
    project, made = synthesised
    project = _copy(project)
    name = next(iter(made))
    painted = flat_normal_map(SIZE)
    project.textures.set_wrinkle_map(name, painted)
    project.furrows = project.furrows.with_controls(None, FurrowControls(depth=3.0))
    maps = FurrowMaps()
    assert name not in maps.remake(project, [name])
    assert project.textures.wrinkle_maps[name] is painted


def test_maps_made_off_the_gui_thread_can_stop_and_never_overwrite_a_map_replaced_meanwhile(
        synthesised):
    project, made = synthesised
    project = _copy(project)
    maps = FurrowMaps()
    maps.adopt(project)
    project.furrows = project.furrows.with_controls(None, FurrowControls(spacing=1.5))
    pending = maps.pending(project)
    assert sorted(pending) == sorted(made)  # every map: all poses' spacing changed
    assert maps.make(project, project.furrows, list(pending), stop=lambda: True) is None
    images = maps.make(project, project.furrows, list(pending))
    name, other = sorted(images)
    painted = flat_normal_map(SIZE)
    project.textures.set_wrinkle_map(name, painted)  # loaded by the user while it ran
    assert maps.apply(project, {n: (images[n], pending[n]) for n in images}) == [other]
    assert project.textures.wrinkle_maps[name] is painted
    assert project.textures.wrinkle_maps[other] is images[other]
    assert maps.pending(project) == {}  # nothing left to make: the painted map is not ours


def test_the_project_file_keeps_the_controls_and_what_remakes_the_maps(synthesised, tmp_path):
    project, made = synthesised
    project = _copy(project)
    project.furrows = project.furrows.with_controls(None, FurrowControls(sharpness=1.5))
    project.furrows = project.furrows.with_controls("Forehead_Raise",
                                                    FurrowControls(depth=0.5, spacing=2.0))
    FurrowMaps().remake(project, list(project.furrows.maps))
    path = tmp_path / "strip.wrinkle"
    save_project(project, path)
    loaded = load_project(path)
    assert loaded.furrows.all == FurrowControls(sharpness=1.5)
    assert loaded.furrows.poses == {"Forehead_Raise": FurrowControls(depth=0.5, spacing=2.0)}
    assert loaded.furrows.maps == project.furrows.maps
    maps = FurrowMaps()
    for name in made:  # the file holds all it takes to make its maps again
        assert np.array_equal(loaded.textures.wrinkle_maps[name],
                              project.textures.wrinkle_maps[name])
        assert np.array_equal(maps.made(loaded, name), loaded.textures.wrinkle_maps[name])


def test_a_file_from_before_the_controls_opens_with_them_at_one(synthesised, tmp_path):
    project, _ = synthesised
    path = tmp_path / "old.wrinkle"
    save_project(_copy(project), path)
    _edit_json(path, lambda doc: (doc.pop("furrows"), doc.update(version=2)))
    loaded = load_project(path)
    assert loaded.furrows.all == FurrowControls() and not loaded.furrows.poses
    assert not loaded.furrows.maps  # made before records: kept as it is, like a painted map


def test_a_damaged_control_is_one_message_naming_the_file(synthesised, tmp_path):
    project, _ = synthesised
    path = tmp_path / "bad.wrinkle"
    save_project(_copy(project), path)
    _edit_json(path, lambda doc: doc["furrows"].update(all={"depth": -1}))
    with pytest.raises(ProjectError, match="depth must be a number from 0 to 4") as caught:
        load_project(path)
    assert "bad.wrinkle" in str(caught.value)


def _copy(project: Project) -> Project:
    import copy

    return copy.deepcopy(project)


def _edit_json(path, edit) -> None:
    with zipfile.ZipFile(path) as z:
        members = {i.filename: z.read(i.filename) for i in z.infolist()}
    doc = json.loads(members["project.json"])
    edit(doc)
    members["project.json"] = json.dumps(doc).encode()
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)


def test_a_map_made_again_brings_its_cavity_with_it(synthesised):
    """Issue 46: a map's cavity map (how deep each texel lies in a crease) follows its
    furrows when a control makes them again, and comes back with them."""
    from studio.core.setup.skin_tone_maps import add_tone_maps
    from studio.core.wrinkles.skin_tone import cavity_map

    project, made = synthesised
    project = _copy(project)
    add_tone_maps(project, made)
    before = dict(project.textures.cavity_maps)
    colour = dict(project.textures.colour_maps)
    maps = FurrowMaps()
    maps.adopt(project)
    project.furrows = project.furrows.with_controls("Forehead_Raise",
                                                    FurrowControls(sharpness=3.0))
    mine = next(n for n, poses in made.items() if "Forehead_Raise" in poses)
    assert maps.remake(project, list(project.furrows.maps)) == [mine]
    cavity = project.textures.cavity_maps[mine]
    assert not np.array_equal(cavity, before[mine])
    assert np.array_equal(cavity, cavity_map(project.textures.normal_neutral,
                                             project.textures.wrinkle_maps[mine]))
    assert project.textures.colour_maps[mine] is colour[mine]  # the strain did not change
    project.furrows = project.furrows.with_controls("Forehead_Raise", FurrowControls())
    maps.remake(project, list(project.furrows.maps))
    assert np.array_equal(project.textures.cavity_maps[mine], before[mine])
