"""A wrinkled normal map synthesised from the key poses (issue 10), on a flat test face whose
left half a pose squeezes along x: furrows there, running along y, and nowhere else."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.setup import wrinkle_synth as synth
from studio.core.wrinkles.skin_strain import triangle_strain
from studio.core.wrinkles.textures import flat_normal_map
from tests.test_auto_setup import grid_mesh, grid_project, squeezed

pytestmark = pytest.mark.core

SIZE = 128
SPACING = 8.0
OPTIONS = synth.SynthOptions(size=SIZE, spacing=SPACING, depth=2.0)


def rotation(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0, 0, 1.0]],
                    np.float32)


# --- the strain tensor per triangle --------------------------------------------------------------

def test_triangle_strain_by_hand():
    mesh = grid_mesh()
    strain = triangle_strain(mesh, squeezed(mesh.rest))
    left = mesh.rest[mesh.welded_triangles].mean(axis=1)[:, 0] < 0.0
    # stretches 0.9 along x and 1 along y: compression 0.1 across x, anisotropy 0.1
    assert np.allclose(strain.compression[left], 0.1, atol=1e-5)
    assert np.allclose(np.abs(strain.wave[left]), [1.0, 0.0], atol=1e-5)
    assert np.allclose(strain.anisotropy[left], 0.1, atol=1e-5)
    assert np.allclose(strain.compression[~left], 0.0, atol=1e-5)


def test_rigid_motion_compresses_nothing():
    mesh = grid_mesh()
    moved = mesh.rest @ rotation(30.0).T + np.float32([2.0, -1.0, 0.5])
    assert np.abs(triangle_strain(mesh, moved).compression).max() < 1e-5


def test_strain_is_measured_on_the_surface_not_in_uv_units():
    """UVs squashed 4× along u: the compression and its direction are those of the surface."""
    mesh = grid_mesh(uv_scale=(0.25, 1.0))
    strain = triangle_strain(mesh, squeezed(mesh.rest, 0.8))
    left = mesh.rest[mesh.welded_triangles].mean(axis=1)[:, 0] < 0.0
    assert np.allclose(strain.compression[left], 0.2, atol=1e-5)
    assert np.allclose(np.abs(strain.wave[left]), [1.0, 0.0], atol=1e-5)


def test_diagonal_compression_gives_a_diagonal_wave():
    """Squeezing along (1, 1)/√2 in 3-D: the wave vector in the image is (1, −1)/√2, because the
    image's y runs down (y = 1 − v)."""
    mesh = grid_mesh()
    d = np.float32([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    along = mesh.rest @ d
    moved = mesh.rest - 0.3 * along[:, None] * d  # lengths along d shrink to 70 %
    strain = triangle_strain(mesh, moved)
    assert np.allclose(strain.compression, 0.3, atol=1e-5)
    wave = strain.wave * np.sign(strain.wave[:, :1])
    assert np.allclose(wave, np.float32([1.0, -1.0]) / np.sqrt(2.0), atol=1e-5)


# --- the synthesised height ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def squeeze_height() -> np.ndarray:
    mesh = grid_mesh()
    return synth.synthesise_height(mesh, [squeezed(mesh.rest)], OPTIONS)


def test_furrows_only_in_the_compressed_half(squeeze_height):
    h = squeeze_height
    margin = int(2 * 1.5 * SPACING)  # the fields are smoothed over 1.5 spacings
    left, right = h[:, : SIZE // 2 - margin], h[:, SIZE // 2 + margin:]
    assert left.min() < -1.5 and (left < -0.5).mean() > 0.1  # real furrows, about 2 deep
    assert not right.any()
    # never deeper than asked; the skin between furrows bunches up a little, never more
    assert h.min() >= -OPTIONS.depth - 1e-6
    assert 0.0 < h.max() <= synth.BUNCH * OPTIONS.depth + 1e-6


def test_furrows_run_along_y_across_the_compression(squeeze_height):
    left = squeeze_height[:, : SIZE // 2 - 24]
    gy, gx = np.gradient(left)
    # (they wander a little along their length: no two furrows alike, none ruled)
    assert np.abs(gx).mean() > 3.0 * np.abs(gy).mean()
    # about one furrow per spacing along x: count the valley bottoms along each row
    bottoms = (left[:, 1:-1] < left[:, :-2]) & (left[:, 1:-1] <= left[:, 2:]) & (
        left[:, 1:-1] < -0.5)
    per_row = bottoms.sum(axis=1).mean()
    assert left.shape[1] / SPACING * 0.6 < per_row < left.shape[1] / SPACING * 1.4


def test_a_pose_that_only_moves_the_face_makes_no_furrows():
    mesh = grid_mesh()
    moved = mesh.rest @ rotation(-20.0).T + np.float32([0.5, 0.3, -0.2])
    assert not synth.synthesise_height(mesh, [moved], OPTIONS).any()


def test_several_poses_take_the_deepest_furrow(squeeze_height):
    mesh = grid_mesh()
    mirrored = mesh.rest.copy()  # the right half squeezed instead
    mirrored[:, 0] = np.where(mesh.rest[:, 0] > 0.0, mesh.rest[:, 0] * 0.9, mesh.rest[:, 0])
    right = synth.synthesise_height(mesh, [mirrored], OPTIONS)
    both = synth.synthesise_height(mesh, [squeezed(mesh.rest), mirrored], OPTIONS)
    # the deepest furrow over each texel, and the skin most bunched there
    deepest = np.minimum(np.minimum(squeeze_height, right), 0.0)
    bunched = np.maximum(np.maximum(squeeze_height, right), 0.0)
    assert np.array_equal(both, deepest + bunched)


def test_not_face_vertices_get_no_furrows():
    mesh = grid_mesh()
    skin = (mesh.rest[:, 1] < 0.0).astype(np.float32)  # the top half (image rows 0..63) is not
    h = synth.synthesise_height(mesh, [squeezed(mesh.rest)], OPTIONS, skin)
    assert not h[: SIZE // 2 - 24].any() and h[SIZE // 2 + 24:].min() < -1.5


def test_progress_counts_up_and_can_stop():
    mesh = grid_mesh()
    calls = []
    poses = [squeezed(mesh.rest), squeezed(mesh.rest)]
    h = synth.synthesise_height(mesh, poses, OPTIONS,
                                progress=lambda done, total: calls.append((done, total)) or True)
    assert h is not None and calls == [(1, 2), (2, 2)]
    assert synth.synthesise_height(mesh, poses, OPTIONS,
                                   progress=lambda done, total: done < 2) is None


def test_bad_options_are_refused():
    mesh = grid_mesh()
    for bad in (synth.SynthOptions(size=8), synth.SynthOptions(spacing=1.0),
                synth.SynthOptions(depth=0.0)):
        with pytest.raises(StudioError):
            synth.synthesise_height(mesh, [mesh.rest], bad)


# --- the normal map ------------------------------------------------------------------------------

def test_the_map_tilts_along_x_in_the_squeezed_half_and_keeps_the_neutral_elsewhere():
    mesh = grid_mesh()
    project = grid_project(squeeze=squeezed(mesh.rest), shift=mesh.rest + 1.0)
    neutral = flat_normal_map(SIZE)
    neutral[::2, ::2] = (120, 135, 250)  # "pores": detail to keep under and beside the furrows
    project.textures.normal_neutral = neutral
    result = synth.synthesise_wrinkle_map(project, ["squeeze", "shift"], OPTIONS)
    normal = result.normal
    assert normal.shape == (SIZE, SIZE, 3) and normal.dtype == np.uint8
    # texels more than a texel from any furrow keep the neutral map exactly (the normals are
    # central differences of the height, so a furrow's edge tilts its neighbours too)
    near = np.pad(result.height != 0.0, 1)
    near = near[:-2, 1:-1] | near[2:, 1:-1] | near[1:-1, :-2] | near[1:-1, 2:] | near[1:-1, 1:-1]
    untouched = ~near
    assert untouched.mean() > 0.35  # the right half and more: only the left is squeezed
    assert np.array_equal(normal[untouched], neutral[untouched])
    furrows = result.height < -0.2
    change = np.abs(normal[furrows].astype(int) - neutral[furrows])
    assert change[:, 0].max() > 40 and change[:, 0].mean() > 3 * change[:, 1].mean()
    assert not furrows[:, SIZE // 2 + 24:].any()
    bare = synth.synthesise_wrinkle_map(project, ["shift"], OPTIONS, over_neutral=False)
    assert (bare.normal == (128, 128, 255)).all()
    with pytest.raises(StudioError, match="none was chosen"):
        synth.synthesise_wrinkle_map(project, [], OPTIONS)


def test_sixteen_bit_neutral_maps_give_a_sixteen_bit_result():
    mesh = grid_mesh()
    project = grid_project(squeeze=squeezed(mesh.rest))
    project.textures.normal_neutral = flat_normal_map(32).astype(np.uint16) * 257
    result = synth.synthesise_wrinkle_map(project, None, synth.SynthOptions(size=64, spacing=6))
    assert result.normal.dtype == np.uint16 and result.normal.shape == (64, 64, 3)


def test_only_a_flat_placeholder_is_filled_in():
    mesh = grid_mesh()
    project = grid_project(squeeze=squeezed(mesh.rest))
    authored = flat_normal_map(16)
    authored[3, 4] = (100, 140, 250)
    project.textures.set_wrinkle_map("wrinkles", authored)
    project.textures.set_wrinkle_map("placeholder", flat_normal_map(4))
    small = synth.SynthOptions(size=64, spacing=6)
    assert synth.fill_placeholder(project, small) == {"placeholder": ["squeeze"]}
    assert project.textures.wrinkle_maps["wrinkles"] is authored
    filled = project.textures.wrinkle_maps["placeholder"]
    assert filled.shape == (64, 64, 3) and not synth.is_flat(filled)
    assert synth.fill_placeholder(project, small) == {}  # nothing flat is left
    assert synth.default_size(project.textures) == 1024


def test_poses_whose_furrows_cross_are_kept_apart():
    """Squeezing the left half along x (furrows along y) and along y (furrows along x) cross
    there: two maps. The same x-squeeze of the right half joins the first (no overlap), and a
    stronger x-squeeze of the left half too (parallel furrows)."""
    mesh = grid_mesh()
    left = mesh.rest[:, 0] < 0.0
    along_y = mesh.rest.copy()
    along_y[:, 1] = np.where(left, mesh.rest[:, 1] * 0.9, mesh.rest[:, 1])
    right = mesh.rest.copy()
    right[:, 0] = np.where(~left, mesh.rest[:, 0] * 0.9, mesh.rest[:, 0])
    targets = [squeezed(mesh.rest), along_y, right, squeezed(mesh.rest, 0.8), mesh.rest]
    fields = synth.furrow_fields(mesh, targets, OPTIONS)
    assert synth.crossing_groups(fields, 4, SIZE) == [[0, 2, 3], [1]]
    # with room for one map only, everything shares it
    assert synth.crossing_groups(fields, 1, SIZE) == [[0, 1, 2, 3]]
