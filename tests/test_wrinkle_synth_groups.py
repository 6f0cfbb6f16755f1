"""Synthesised wrinkle maps, the parts around the furrows themselves: poses whose furrows cross
go to separate maps ("<name> 2", …, as many as the shader has room for), the furrow fields'
orientation bins and their blend of the phasor bank (180° wraps to 0° conjugated), the bank's
Gabor filter (one frequency, oriented, its envelope widths), the map size a face gets, and the
small helpers (flat placeholders, encoding normals). Hand-built fields and a 21 × 21 grid face
at 32–64 texels keep every test fast."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.mesh.uv_tiles import SINGLE, TileLayout
from studio.core.project.model import Project
from studio.core.setup import wrinkle_synth as synth
from studio.core.setup.wrinkle_synth import FurrowField
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from tests.test_auto_setup import grid_mesh, squeezed

pytestmark = pytest.mark.core

def _field(
    index: list[int] | np.ndarray,
    degrees: list[float] | np.ndarray,
    amount: list[float] | np.ndarray | float = 1.0,
) -> FurrowField:
    """A furrow field on these texels, furrow waves at these orientations (degrees)."""
    index = np.asarray(index, np.int64)
    amount = np.broadcast_to(np.asarray(amount, np.float32), index.shape).copy()
    return FurrowField(index, amount, np.asarray(degrees, np.float32),
                       np.zeros(index.shape, np.float32))


# --------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("size", "expected"),
    [
        (1, 2),
        (2, 2),
        (3, 4),
        (5, 8),
        (1000, 1024),
        (1024, 1024),
        (1025, 2048),
    ],
)
def test_power_of_two_rounds_up(size: int, expected: int):
    assert synth._power_of_two(size) == expected


def _textures(size: int = 8) -> FaceTextures:
    return FaceTextures(flat_normal_map(size), flat_normal_map(size), flat_normal_map(size))


@pytest.mark.parametrize(
    ("layout", "expected"),
    [
        (None, 1024),
        (SINGLE, 1024),
        (TileLayout((1001, 1002), ((0.0, 0.0, 0.5), (0.5, 0.0, 0.5))), 2048),
        (TileLayout((1001, 1002), ((0.0, 0.0, 0.125), (0.5, 0.0, 0.0625))), 2048),
    ],
)
def test_the_default_map_size_keeps_1024_texels_across_a_skin_tile(
    layout: TileLayout | None, expected: int
):
    """1024 for a face on one tile; twice that for an atlas whose largest cell is half the
    square; never more than 2048."""
    project = SimpleNamespace(
        textures=_textures(), uv_tiles=None if layout is None else SimpleNamespace(layout=layout)
    )
    assert synth._default_map_size(project) == expected


def test_the_default_map_size_follows_large_maps_up_to_2048():
    textures = _textures()
    textures.diffuse = flat_normal_map(1500)
    assert synth._default_map_size(SimpleNamespace(textures=textures, uv_tiles=None)) == 2048
    textures.diffuse = flat_normal_map(2100)
    assert synth._default_map_size(SimpleNamespace(textures=textures, uv_tiles=None)) == 2048


def test_default_size_is_the_largest_map_side():
    textures = _textures(2)
    assert synth.default_size(textures, least=1) == 2
    textures.set_wrinkle_map("big", flat_normal_map(40))
    assert synth.default_size(textures, least=16) == 40
    assert synth.default_size(textures) == 1024


def test_a_one_texel_map_is_flat():
    assert synth.is_flat(flat_normal_map(1))
    image = flat_normal_map(3)
    assert synth.is_flat(image)
    image[0, 0] = (120, 128, 255)
    assert not synth.is_flat(image)


def test_encode_maps_minus_one_to_one_onto_the_full_range_and_clips():
    normals = np.array([-1.5, -1.0, 0.0, 1.0, 1.5])
    out = synth._encode(normals, np.uint8)
    assert out.dtype == np.uint8
    np.testing.assert_array_equal(out, [0, 0, 128, 255, 255])
    np.testing.assert_array_equal(synth._encode(normals, np.uint16), [0, 0, 32768, 65535, 65535])


# --------------------------------------------------------------------------------------------
# Furrows from a phase
# --------------------------------------------------------------------------------------------


def test_regions_are_labelled_by_their_smallest_texel() -> None:
    inside = np.zeros((6, 6), bool)
    inside[1:3, 1:3] = True  # a square
    inside[4:, 3:] = True  # a bar
    inside[0, 5] = True  # a lone texel
    labels = synth.label_regions(inside)
    assert (labels[1:3, 1:3] == 7).all() and (labels[4:, 3:] == 27).all() and labels[0, 5] == 5
    assert (labels[~inside] == -1).all()
    spiral = np.zeros((9, 9), bool)  # one long winding region: one label
    spiral[0, :] = spiral[:, 8] = spiral[8, :] = spiral[2:, 0] = spiral[2, :7] = True
    spiral[2:7, 6] = spiral[6, 2:7] = True
    assert len(np.unique(synth.label_regions(spiral)[spiral])) == 1


def test_the_potential_of_a_uniform_field_is_a_ramp_inside_it() -> None:
    fx, fy = np.zeros((96, 96)), np.zeros((96, 96))
    fy[20:76, 10:86] = 1.0  # waves along y in a wide band: furrows along x
    phi = synth._potential(fx, fy)
    slope = np.diff(phi[30:66, 48])
    assert (slope > 0).all()  # one way all along: no ring, no fold back
    assert np.ptp(phi[48, 30:66]) < 0.2 * np.ptp(phi[30:66, 48])  # and level across


def test_a_band_squeezed_across_gets_straight_furrows_at_the_spacing_one_at_its_peak() -> None:
    """Strength peaks along row 40 of a band squeezed along y: the phase advances 2π per
    spacing along y, is level along x, and is 0 (a furrow's bottom) on the peak row."""
    y = np.arange(96, dtype=np.float32)[:, None]
    strength = np.clip(1.0 - np.abs(y - 40.0) / 30.0, 0.0, 1.0) * np.ones((1, 96), np.float32)
    angle = np.full((96, 96), np.pi / 2, np.float32)  # wave along y
    spacing = 12.0
    phase, straight = synth.furrow_phase(strength, angle, 2 * np.pi / spacing)
    assert phase[40, 48] == pytest.approx(0.0, abs=0.01)
    per_texel = np.gradient(phase[25:56, 48])
    np.testing.assert_allclose(np.abs(per_texel), 2 * np.pi / spacing, rtol=0.25)
    assert np.ptp(phase[40, 20:76]) < 0.1
    assert straight[30:50, 20:76].min() > 0.99


def test_waves_toward_a_point_are_dropped_as_tight_rings() -> None:
    """Skin squeezed toward a point (waves radial): the rings near it are not furrows."""
    yy, xx = np.mgrid[0:96, 0:96].astype(np.float32)
    angle = np.mod(np.arctan2(yy - 48.0, xx - 48.0), np.pi)
    strength = np.ones((96, 96), np.float32)
    _, straight = synth.furrow_phase(strength, angle, 2 * np.pi / 12.0)
    assert straight[44:53, 44:53].max() < 0.05  # within a spacing of the centre
    parallel = np.full((96, 96), 0.3, np.float32)
    assert synth.furrow_phase(strength, parallel, 2 * np.pi / 12.0)[1][20:76, 20:76].min() > 0.99


def test_a_fields_depth_is_its_amount_in_a_valley_fading_away_from_the_first() -> None:
    f = FurrowField(np.arange(4), np.float32([1.0, 0.5, 1.0, 1.0]), np.zeros(4, np.float32),
                    np.float32([0.0, 0.0, np.pi, 2 * np.pi * 2]))  # the second furrow over
    fade = np.exp(-(2 / synth.FURROWS_EACH_SIDE) ** 2)
    between = np.exp(-(0.5 / synth.FURROWS_EACH_SIDE) ** 2)  # half a spacing from the first
    # midway between furrows the skin bunches up by BUNCH of their depth
    np.testing.assert_allclose(f.depth(), [1.0, 0.5, -synth.BUNCH * between, fade], atol=1e-6)
    f.variation = np.float32([0.6, 1.0, 1.0, 0.5])  # deeper and shallower along their length
    np.testing.assert_allclose(f.depth(), [0.6, 0.5, -synth.BUNCH * between, 0.5 * fade],
                               atol=1e-6)


def test_groups_get_one_depth_image_each_from_one_pass():
    a, b = _field([0, 1], [10.0, 10.0]), _field([1, 2], [100.0, 100.0])
    alone = [synth.furrow_depths([f], 32) for f in (a, b)]
    grouped = synth.furrow_depths([a, b], 32, groups=[[1], [0]])
    assert len(grouped) == 2
    np.testing.assert_array_equal(grouped[0], alone[1])
    np.testing.assert_array_equal(grouped[1], alone[0])
    both = synth.furrow_depths([a, b], 32)
    np.testing.assert_array_equal(both, np.maximum(*alone))


def test_anatomy_s_lines_give_way_to_a_pose_s_bare_skin_but_not_to_other_placed_lines():
    """Past the shader's four maps poses share one, and a pose's furrows give way where
    another of its map reveals the skin bare. A placed pose (anatomy's lines) reveals all
    the skin it moves around its small window: a cheek squint's would erase a smile's
    nasolabial fold (on the ICT head with all 53 expressions set up, 0.24 % of the render
    instead of 1.9 %). So placed lines give way to the bare skin of an ordinary pose only."""
    size = 32
    fold = _field(np.arange(64), np.zeros(64))
    fold.placed = True
    squint = _field([900], [0.0])
    squint.placed = True
    squint.bare = np.arange(64)  # it moves the fold's skin, its own lines elsewhere
    ordinary = _field([900], [0.0])
    ordinary.bare = np.arange(64)
    alone = synth.furrow_depths([fold], size)
    kept = synth.furrow_depths([fold, squint], size, groups=[[0, 1]])[0]
    np.testing.assert_array_equal(kept.ravel()[:64], alone.ravel()[:64])
    cut = synth.furrow_depths([fold, ordinary], size, groups=[[0, 1]])[0]
    assert cut.ravel()[20:44].max() < 0.5 * alone.ravel()[20:44].min()


# --------------------------------------------------------------------------------------------
# Which poses share a map
# --------------------------------------------------------------------------------------------

TEXELS = np.arange(100)


def test_furrows_more_than_30_degrees_apart_cross():
    """Same texels at 0° and 90° cross; at 0° and 20°, or 10° and 170° (20° apart across the
    wrap), they do not; 100° and 120° do not either."""

    def groups(*angles: float) -> list[list[int]]:
        return synth.crossing_groups([_field(TEXELS, [a] * 100) for a in angles], 4, 16)

    assert groups(0.0, 90.0) == [[0], [1]]
    assert groups(0.0, 20.0) == [[0, 1]]
    assert groups(10.0, 170.0) == [[0, 1]]
    assert groups(100.0, 120.0) == [[0, 1]]
    assert groups(0.0, 150.5) == [[0, 1]]  # 29.5° apart across the wrap
    assert groups(0.0, 149.0) == [[0], [1]]  # 31°


def test_a_pose_without_furrows_is_left_out_and_the_rest_still_grouped():
    empty = _field([], [])
    fields = [empty, _field(TEXELS, [0.0] * 100), empty, _field(TEXELS, [90.0] * 100)]
    assert synth.crossing_groups(fields, 4, 16) == [[1], [3]]
    assert synth.crossing_groups([empty], 4, 16) == [[]]


def test_crossing_on_up_to_five_percent_of_the_strong_texels_is_allowed():
    """20 strong texels: crossing on one (5 %) shares the map, on two does not."""
    base = _field(np.arange(20), [0.0] * 20)
    for crossing, expected in ((1, [[0, 1]]), (2, [[0], [1]]), (5, [[0], [1]])):
        other = _field(np.arange(20), [90.0] * crossing + [0.0] * (20 - crossing))
        assert synth.crossing_groups([base, other], 4, 16) == expected
    # 100 strong texels allow 5 crossings
    other = _field(TEXELS, [90.0] * 5 + [0.0] * 95)
    assert synth.crossing_groups([_field(TEXELS, [0.0] * 100), other], 4, 16) == [[0, 1]]


def test_only_texels_stronger_than_a_quarter_count():
    """Texels at exactly the strong share (0.25) neither clash nor count toward the 5 %."""
    weak_map = _field(TEXELS, [0.0] * 100, 0.25)
    assert synth.crossing_groups([weak_map, _field(TEXELS, [90.0] * 100)], 4, 16) == [[0, 1]]
    weak_pose = _field(TEXELS, [90.0] * 100, 0.25)
    assert synth.crossing_groups([_field(TEXELS, [0.0] * 100), weak_pose], 4, 16) == [[0, 1]]
    # 40 strong texels (20 at exactly 0.25 do not count): 3 crossings are over 5 % of 40
    amounts = [1.0] * 40 + [0.25] * 60
    other = _field(TEXELS, [90.0] * 3 + [0.0] * 97, amounts)
    assert synth.crossing_groups([_field(TEXELS, [0.0] * 100), other], 4, 16) == [[0], [1]]


def test_a_map_keeps_the_strongest_orientation_of_its_poses():
    """0° at 0.5, then 20° at 0.5 (not stronger: the map still says 0°), then 45° crosses 0°."""
    fields = [
        _field(TEXELS, [0.0] * 100, 0.5),
        _field(TEXELS, [20.0] * 100, 0.5),
        _field(TEXELS, [45.0] * 100, 1.0),
    ]
    assert synth.crossing_groups(fields, 4, 16) == [[0, 1], [2]]
    # a stronger 20° takes over, and 45° is then within 30° of the map
    fields[1] = _field(TEXELS, [20.0] * 100, 0.8)
    assert synth.crossing_groups(fields, 4, 16) == [[0, 1, 2]]


def test_past_the_last_map_a_pose_joins_the_one_it_crosses_least():
    """Two maps (0° and 90°); a third pose at 45° on half its texels and 70° on the rest
    crosses the 0° map everywhere and the 90° map on half: it joins the 90° map."""
    fields = [
        _field(TEXELS, [0.0] * 100),
        _field(TEXELS, [90.0] * 100),
        _field(TEXELS, [45.0] * 50 + [70.0] * 50),
    ]
    assert synth.crossing_groups(fields, 2, 16) == [[0], [1, 2]]
    assert synth.crossing_groups(fields, 3, 16) == [[0], [1], [2]]


# --------------------------------------------------------------------------------------------
# Filling a flat placeholder with one map per group of poses
# --------------------------------------------------------------------------------------------

OPTIONS = synth.SynthOptions(size=32, spacing=4.0, depth=1.0)


def _crossing_project(*authored: str) -> Project:
    """The grid face with its left half squeezed along x ("squeeze", furrows along y) and
    along y ("along_y", crossing them), a flat "wrinkles" placeholder, these authored maps,
    and its top row of vertices not face."""
    mesh = grid_mesh()
    along_y = mesh.rest.copy()
    along_y[:, 1] = np.where(mesh.rest[:, 0] < 0.0, mesh.rest[:, 1] * 0.9, mesh.rest[:, 1])
    maps = {"wrinkles": flat_normal_map(4)}
    for name in authored:
        image = flat_normal_map(4)
        image[1, 1] = (100, 140, 250)
        maps[name] = image
    textures = FaceTextures(flat_normal_map(8), flat_normal_map(32), wrinkle_maps=maps)
    not_face = mesh.rest[:, 1] > 0.9
    return Project(
        "grid",
        mesh,
        [KeyPose("squeeze", squeezed(mesh.rest)), KeyPose("along_y", along_y)],
        textures,
        not_face=not_face,
    )


def test_crossing_poses_fill_the_placeholder_and_a_second_map():
    """Each map is what synthesising from its own poses gives (same seed, same skin); the
    second is named after the first, and progress counts every step against one total."""
    project = _crossing_project()
    calls: list[tuple[int, int]] = []
    made = synth.fill_placeholder(project, OPTIONS, lambda d, t: calls.append((d, t)) or True)
    assert made == {"wrinkles": ["squeeze"], "wrinkles 2": ["along_y"]}
    maps = project.textures.wrinkle_maps
    assert list(maps) == ["wrinkles", "wrinkles 2"]
    for name, poses in made.items():
        alone = synth.synthesise_wrinkle_map(project, poses, OPTIONS)
        np.testing.assert_array_equal(maps[name], alone.normal)
    total = 2
    assert calls[0] == (1, total) and calls[1] == (2, total)
    assert {t for _, t in calls} == {total}
    assert [d for d, _ in calls] == list(range(1, len(calls) + 1))


def test_a_second_map_gets_a_name_not_taken():
    project = _crossing_project("wrinkles 2")
    made = synth.fill_placeholder(project, OPTIONS)
    assert made == {"wrinkles": ["squeeze"], "wrinkles 2 2": ["along_y"]}


def test_with_no_room_for_another_map_crossing_poses_share_the_placeholder():
    """Four maps already (the shader's most): both poses go into the placeholder."""
    project = _crossing_project("a", "b", "c")
    made = synth.fill_placeholder(project, OPTIONS)
    assert made == {"wrinkles": ["squeeze", "along_y"]}
    assert len(project.textures.wrinkle_maps) == 4


def test_with_room_for_one_more_map_the_crossing_pose_gets_it():
    project = _crossing_project("a", "b")
    made = synth.fill_placeholder(project, OPTIONS)
    assert made == {"wrinkles": ["squeeze"], "wrinkles 2": ["along_y"]}


def test_stopping_during_the_furrows_stops_the_fill():
    project = _crossing_project()
    before = project.textures.wrinkle_maps["wrinkles"].copy()
    assert synth.fill_placeholder(project, OPTIONS, lambda d, t: d < 2) is None
    np.testing.assert_array_equal(project.textures.wrinkle_maps["wrinkles"], before)


@pytest.mark.core
def test_bare_skin_is_blurred_around_itself_as_over_the_whole_map():
    """``_bare_image`` blurs only around the bare skin, as far as the blur reaches: the same
    image, to the bit, as the whole map blurred (a patch in the middle, and one touching the
    map's corner, where the blur clamps at the edge)."""
    from studio.core.setup import wrinkle_synth as ws
    from studio.core.wrinkles import mask_ops

    size = 512
    for rows, cols in ((slice(200, 230), slice(300, 420)), (slice(0, 12), slice(0, 40))):
        bare = np.zeros((size, size), np.float32)
        bare[rows, cols] = 1.0
        field = ws.FurrowField(np.zeros(0, np.int64), np.zeros(0, np.float32),
                               np.zeros(0, np.float32), np.zeros(0, np.float32),
                               np.flatnonzero(bare.ravel()))
        whole = mask_ops.blur(bare, ws.BARE_SOFTNESS * size)
        every = np.arange(size * size)
        assert np.array_equal(ws._bare_image(field, size).at(every, size).reshape(size, size),
                              whole)
        assert whole[rows.start - 4 if rows.start >= 4 else rows.stop + 3, cols.start + 2] > 0.0
