"""Mirroring a whole mask through the mesh (studio.core.wrinkles.surface_mirror.mirror_mask) and
an area to the other side of the face (studio.core.setup.mirror_area.mirrored_area).

The surfaces are flat rectangles (z = 0) with an affine UV layout, so every texel's mirror image
is a hand-computed column (or row) of the mask: texel centres sit at ((c + ½) / w, 1 − (r + ½) / h)
in UV.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.setup.mirror_area import mirrored_area
from studio.core.wrinkles.influence import InfluenceArea, InfluenceSetup
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.surface_mirror import (
    SurfaceMirror,
    footprint_ring,
    mirror_mask,
    reflect,
)
from studio.core.wrinkles.textures import FaceTextures
from tests.test_surface_mirror import strip, uv_left, uv_right

pytestmark = pytest.mark.core

UvOf = Callable[[float, float], tuple[float, float]]


def flat(x0: float, x1: float, y0: float, y1: float, uv_of: UvOf | None = None,
         n: int = 2) -> FaceMesh:
    """The rectangle [x0, x1] × [y0, y1] at z = 0 in n × n quads; by default its UVs fill the
    UV square (u along x, v along y)."""
    if uv_of is None:
        def uv_of(x: float, y: float) -> tuple[float, float]:
            return (x - x0) / (x1 - x0), (y - y0) / (y1 - y0)
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    rest = np.array([(x, y, 0.0) for y in ys for x in xs])
    uvs = np.array([uv_of(x, y) for x, y, _ in rest])
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, \
                (j + 1) * (n + 1) + i
            tris += [(a, b, c), (a, c, d)]
    return FaceMesh(rest, np.array(tris), uvs, np.arange(len(rest)))


def numbered(h: int, w: int) -> np.ndarray:
    """A mask whose texels all differ (and are all painted): 1/(h·w), 2/(h·w), … 1."""
    return (np.arange(1, h * w + 1, dtype=np.float32) / (h * w)).reshape(h, w)


# --------------------------------------------------------------------------- mirror_mask

H, W = 8, 12  # not square: rows and columns cannot be mixed up


@pytest.mark.parametrize(("rect", "axis", "rows", "cols"), [
    # symmetric about x = 0: column c ↔ 11 − c, rows stay
    ((-1.0, 1.0, 0.0, 1.0), 0, range(H), [11 - c for c in range(W)]),
    # symmetric about y = 0, mirrored across it: row r ↔ 7 − r, columns stay
    ((0.0, 1.0, -1.0, 1.0), 1, [7 - r for r in range(H)], range(W)),
    # x ∈ [−1, 0.6]: u' = 1.25 − u, column 14 − c; the images of columns 0-2 lie past the
    # right edge of the mask, and the edge column stands in for them
    ((-1.0, 0.6, 0.0, 1.0), 0, range(H), [min(14 - c, 11) for c in range(W)]),
    # x ∈ [−0.6, 1]: u' = 0.75 − u, column 8 − c; columns 9-11 look past the left edge
    ((-0.6, 1.0, 0.0, 1.0), 0, range(H), [max(8 - c, 0) for c in range(W)]),
    # y ∈ [−1, 0.6]: v' = 1.25 − v, row 5 − r; rows 6-7 look past the top edge
    ((0.0, 1.0, -1.0, 0.6), 1, [max(5 - r, 0) for r in range(H)], range(W)),
    # y ∈ [−0.6, 1]: v' = 0.75 − v, row 9 − r; rows 0-1 look past the bottom edge
    ((0.0, 1.0, -0.6, 1.0), 1, [min(9 - r, 7) for r in range(H)], range(W)),
])
def test_each_texel_takes_the_value_at_its_mirror_image(rect, axis, rows, cols) -> None:
    """Every texel reads the mask at its mirror image, the nearest edge texel when the image
    falls off the mask."""
    mask = numbered(H, W)
    out = mirror_mask(mask, SurfaceMirror(flat(*rect), axis=axis))
    assert out.dtype == np.float32 and out.shape == (H, W)
    np.testing.assert_array_equal(out, mask[np.ix_(list(rows), list(cols))])


@pytest.mark.parametrize(("rect", "axis", "plane", "rows", "cols"), [
    ((0.0, 2.0, 0.0, 1.0), 0, 1.0, range(H), [11 - c for c in range(W)]),  # about x = 1
    ((0.0, 1.0, 1.0, 3.0), 1, 2.0, [7 - r for r in range(H)], range(W)),  # about y = 2
])
def test_the_mirror_plane_can_lie_anywhere(rect, axis, plane, rows, cols) -> None:
    """A face whose symmetry plane is not at 0 mirrors about that plane."""
    mask = numbered(H, W)
    out = mirror_mask(mask, SurfaceMirror(flat(*rect), axis=axis, plane=plane))
    np.testing.assert_array_equal(out, mask[np.ix_(list(rows), list(cols))])


def test_a_dab_lands_only_at_its_mirror_image() -> None:
    """Two small dabs far apart are both mirrored, each to its own place, and nothing else."""
    h, w = 4, 40
    mask = np.zeros((h, w), np.float32)
    mask[1, 2], mask[2, 30], mask[3, 3] = 0.75, 0.5, 1.0
    out = mirror_mask(mask, SurfaceMirror(flat(-1.0, 1.0, 0.0, 1.0, n=4)))
    expected = np.zeros((h, w), np.float32)
    expected[1, 37], expected[2, 9], expected[3, 36] = 0.75, 0.5, 1.0
    np.testing.assert_array_equal(out, expected)


# the chart covers only the middle of the UV square: u, v ∈ [0.25, 0.75]
def _middle(x: float, y: float) -> tuple[float, float]:
    return 0.5 + 0.25 * x, 0.5 + 0.25 * y


# a fully painted 16 × 16 mask mirrored on it: the chart's 8 × 8 texels and a rim of two texels
# (the lookup's reach, 2/16 in UV, rounded at the corners) around it; nothing further out
BLEED = """
................
................
...##########...
..############..
..############..
..############..
..############..
..############..
..############..
..############..
..############..
..############..
..############..
...##########...
................
................
"""


def test_texels_off_the_chart_are_filled_two_texels_deep_and_no_further() -> None:
    """Around a chart the mirrored mask reaches two texels past its edge, then stops."""
    out = mirror_mask(np.ones((16, 16), np.float32),
                      SurfaceMirror(flat(-1.0, 1.0, -1.0, 1.0, _middle)))
    expected = np.array([[c == "#" for c in line] for line in BLEED.split()], np.float32)
    np.testing.assert_array_equal(out, expected)


def test_paint_off_every_chart_has_no_mirror_image() -> None:
    """Texels painted where no chart is near mirror to nothing: the result is empty."""
    mask = np.zeros((16, 16), np.float32)
    mask[0, 0] = mask[15, 14] = 1.0
    out = mirror_mask(mask, SurfaceMirror(flat(-1.0, 1.0, -1.0, 1.0, _middle)))
    assert not out.any() and out.shape == (16, 16)


def test_an_empty_mask_mirrors_to_an_empty_mask() -> None:
    """Nothing painted: nothing mirrored."""
    out = mirror_mask(np.zeros((H, W), np.float32), SurfaceMirror(flat(-1.0, 1.0, 0.0, 1.0)))
    assert out.shape == (H, W) and not out.any()


def test_a_mask_of_many_painted_texels_mirrors_whole() -> None:
    """A large painted region (bounded from a sample of its texels) still mirrors completely."""
    size = 150  # 22 500 painted texels
    mask = np.zeros((size, size), np.float32)
    mask[:, : size // 2] = 1.0
    mask[:, size // 2:] = 0.5
    out = mirror_mask(mask, SurfaceMirror(flat(-1.0, 1.0, 0.0, 1.0, n=1)))
    np.testing.assert_array_equal(out, mask[:, ::-1])


# --------------------------------------------------------------------------- mirrored_area

MH, MW = 6, 8


def _project(areas: list[InfluenceArea], links: dict[str, dict[str, float]],
             curves: dict[str, dict[str, ResponseCurve]] | None = None) -> Project:
    mesh = flat(-1.0, 1.0, 0.0, 1.0)
    poses = [KeyPose(name, mesh.rest) for name in
             ("browDown_L", "browDown_R", "browInnerUp", "jawOpen", "cheekPuff")]
    image = np.zeros((2, 2, 3), np.uint8)
    return Project("face", mesh, poses, FaceTextures(image, image, image),
                   InfluenceSetup(areas, links, curves or {}))


def _mask() -> np.ndarray:
    """A mask painted on the left (low columns): three texels of different values."""
    mask = np.zeros((MH, MW), np.float32)
    mask[1, 1], mask[2, 2], mask[4, 3] = 1.0, 0.5, 0.25
    return mask


STEEP = ResponseCurve("ease_in")
STEP = ResponseCurve("smooth_step", 0.2, 0.6)


def _mirror(project: Project) -> SurfaceMirror:
    return SurfaceMirror(project.mesh)


def test_an_area_of_one_side_becomes_its_pair_with_its_poses_paired() -> None:
    """brow_L, with no brow_R yet, gives a new brow_R: same settings, mirrored mask, the paired
    poses' links and curves; a pose without a pair keeps driving it."""
    brow = InfluenceArea("brow_L", _mask(), (10, 20, 30), 0.3, False, "frown")
    other = InfluenceArea("mouth", np.zeros((MH, MW)), (1, 2, 3), 0.9, True, "")
    links = {"browDown_L": {"brow_L": 0.8, "mouth": 0.1}, "browInnerUp": {"brow_L": 0.5},
             "jawOpen": {"mouth": 1.0}, "cheekPuff": {"brow_L": 0.2}}
    curves = {"browDown_L": {"brow_L": STEEP, "mouth": STEP}, "jawOpen": {"mouth": STEP},
              "cheekPuff": {"mouth": STEEP}}
    project = _project([brow, other], links, curves)
    result = mirrored_area(project, 0, _mirror(project))
    area = result.area
    assert result.replaces is None
    assert (area.name, area.colour, area.activation, area.visible, area.wrinkle_map) == (
        "brow_R", (10, 20, 30), 0.3, False, "frown")
    np.testing.assert_array_equal(area.mask, _mask()[:, ::-1])
    assert result.links == {"browDown_R": 0.8, "browInnerUp": 0.5, "cheekPuff": 0.2}
    assert result.curves == {"browDown_R": STEEP}


def test_an_area_whose_pair_exists_replaces_the_pairs_mask_and_keeps_its_settings() -> None:
    """brow_R already there: the result replaces it, keeping its name, colour, activation,
    visibility and wrinkle map, with the mirrored mask of brow_L."""
    brow_l = InfluenceArea("brow_L", _mask(), (10, 20, 30), 0.3, False, "frown")
    mouth = InfluenceArea("mouth", np.zeros((MH, MW)), (1, 2, 3), 0.9, True, "")
    brow_r = InfluenceArea("brow_R", np.zeros((MH, MW)), (200, 100, 50), 0.7, True, "smile")
    project = _project([mouth, brow_l, brow_r], {"browDown_L": {"brow_L": 0.6}})
    result = mirrored_area(project, 1, _mirror(project))
    area = result.area
    assert result.replaces == 2
    assert (area.name, area.colour, area.activation, area.visible, area.wrinkle_map) == (
        "brow_R", (200, 100, 50), 0.7, True, "smile")
    np.testing.assert_array_equal(area.mask, _mask()[:, ::-1])
    assert result.links == {"browDown_R": 0.6} and result.curves == {}


def test_an_area_without_a_side_gets_a_mirrored_copy_under_a_new_name() -> None:
    """An area named for no side is copied as "<name> mirrored" (numbered if that is taken),
    added rather than replacing anything."""
    forehead = InfluenceArea("forehead", _mask(), (5, 6, 7), 0.1, True, "lines")
    project = _project([forehead], {"browInnerUp": {"forehead": 1.0}},
                       {"browInnerUp": {"forehead": STEP}})
    result = mirrored_area(project, 0, _mirror(project))
    assert result.replaces is None
    assert (result.area.name, result.area.colour, result.area.activation, result.area.visible,
            result.area.wrinkle_map) == ("forehead mirrored", (5, 6, 7), 0.1, True, "lines")
    np.testing.assert_array_equal(result.area.mask, _mask()[:, ::-1])
    assert result.links == {"browInnerUp": 1.0} and result.curves == {"browInnerUp": STEP}

    taken = InfluenceArea("forehead mirrored", np.zeros((MH, MW)))
    project = _project([taken, forehead], {})
    result = mirrored_area(project, 1, _mirror(project))
    assert result.area.name == "forehead mirrored 2" and result.replaces is None
    assert result.links == {} and result.curves == {}


# --------------------------------------------------------------------------- dabs

def right_uv(density: float, turn: tuple[float, float], x: float, y: float) -> list[float]:
    """The right chart: ``density`` UV per unit, turned by (cos, sin) = ``turn``."""
    c, s = turn
    return [0.6 + density * (c * x - s * y), 0.6 + density * (s * x + c * y)]


def two_charts(density: float, turn: tuple[float, float] = (1.0, 0.0)) -> FaceMesh:
    """The strip x ∈ [−1, 1], y ∈ [0, 1] cut at x = 0 into two unwelded charts, its quads of
    unequal sizes: the left at 0.4 UV per unit, u = 0.05 + 0.4·(x + 1), v = 0.1 + 0.4·y; the
    right at ``density`` UV per unit, possibly turned (``right_uv``)."""
    rest, uvs, tris = [], [], []
    for xs, uv in (([-1.0, -0.5, 0.0], lambda x, y: (0.05 + 0.4 * (x + 1), 0.1 + 0.4 * y)),
                   ([0.0, 0.25, 1.0], lambda x, y: right_uv(density, turn, x, y))):
        base = len(rest)
        for y in (0.0, 1.0):
            for x in xs:
                rest.append((x, y, 0.0))
                uvs.append(uv(x, y))
        for i in range(2):
            a, b, c, d = base + i, base + i + 1, base + i + 4, base + i + 3
            tris += [(a, b, c), (a, c, d)]
    return FaceMesh(np.array(rest), np.array(tris), np.array(uvs), np.arange(len(rest)))


@pytest.mark.parametrize(("density", "turn", "scales"), [
    (0.2, (1.0, 0.0), [0.5, 0.5, 2.0]),  # half the UV per unit on the right: half the radius
    (0.2, (0.6, 0.8), [0.5, 0.5, 2.0]),  # the same, the chart turned by 53°
    (0.05, (1.0, 0.0), [0.2, 0.2, 5.0]),  # an eighth (and 8×): limited to 0.2 and 5
])
def test_dabs_are_mirrored_into_the_other_chart_with_its_scale(density, turn, scales) -> None:
    """Each dab lands at its mirror point in the other chart, its radius scaled by the ratio of
    the charts' UV per unit (within SCALE_LIMITS), on any triangle (the first one included)."""
    mirror = SurfaceMirror(two_charts(density, turn))
    # (−0.75, 0.25) and (−0.6, 0.1) (on triangle 0) on the left, (0.5, 0.5) on the right
    uvs = np.array([[0.15, 0.2], [0.21, 0.14], right_uv(density, turn, 0.5, 0.5)])
    owner, uv, scale = mirror.mirror_uv(uvs, reach=0.01)
    assert owner.tolist() == [0, 1, 2]
    assert uv == pytest.approx(np.array([
        right_uv(density, turn, 0.75, 0.25), right_uv(density, turn, 0.6, 0.1), [0.25, 0.3]]),
        abs=1e-6)
    assert scale == pytest.approx(scales)


def test_the_brush_mirror_works_in_mask_pixels() -> None:
    """As the brush calls it: dab centres in pixels (row 0 = v 1) and a radius in pixels; a
    dab off every chart has no image."""
    mirror = SurfaceMirror(two_charts(0.2))
    # UV (0.15, 0.2), (0.7, 0.7) and (0.95, 0.95) in a 100 × 200 mask
    owner, centres, scale = mirror(np.array([[30.0, 80.0], [140.0, 30.0], [190.0, 5.0]]),
                                   (100, 200), radius=2.0)
    assert owner.tolist() == [0, 1]
    assert centres == pytest.approx(np.array([[150.0, 35.0], [50.0, 70.0]]), abs=1e-4)
    assert scale == pytest.approx([0.5, 2.0])


def test_a_dab_off_every_chart_has_no_image_nor_scale() -> None:
    """Off the charts: empty owners, images and scales alike."""
    owner, uv, scale = SurfaceMirror(two_charts(0.2)).mirror_uv(np.array([[0.95, 0.05]]), 0.01)
    assert owner.shape == (0,) and uv.shape == (0, 2) and scale.shape == (0,)


@pytest.mark.parametrize(("x", "main", "extra"), [
    (-0.02, uv_right(np.array([0.02, 0.5])), uv_left(np.array([0.02, 0.5]))),
    (0.02, uv_left(np.array([-0.02, 0.5])), uv_right(np.array([-0.02, 0.5]))),
])
def test_beside_a_seam_either_way_the_image_is_in_both_charts(x, main, extra) -> None:
    """A dab just beside the seam, on either side, mirrors into the chart across the seam and,
    extrapolated, into its own chart too (a freshly built mirror)."""
    mirror = SurfaceMirror(strip())
    p = np.array([x, 0.5, 0.0])
    uv = uv_left(p) if x < 0 else uv_right(p)
    owner, images, _ = mirror.mirror_uv(uv[None], reach=0.02)
    assert owner.tolist() == [0, 0]
    assert images == pytest.approx(np.array([main, extra]), abs=1e-6)


def test_reflect_mirrors_across_any_plane_and_leaves_its_input_alone() -> None:
    """Only the chosen axis is reflected, about the plane, in float64; the input is kept."""
    points = np.array([[1.0, 2.0, 3.0], [-0.5, 0.0, 4.0]])
    out = reflect(points, axis=0, plane=0.25)
    assert out.tolist() == [[-0.5, 2.0, 3.0], [1.0, 0.0, 4.0]]
    assert points.tolist() == [[1.0, 2.0, 3.0], [-0.5, 0.0, 4.0]]
    assert reflect(np.array([[1, 2, 3]]), axis=1, plane=0.25).tolist() == [[1.0, -1.5, 3.0]]
    assert reflect(points).tolist() == [[-1.0, 2.0, 3.0], [0.5, 0.0, 4.0]]  # x = 0 by default


def test_the_brush_footprint_follows_the_circle_around_from_plus_u() -> None:
    """The ring starts at +u and turns toward +v, with its own radius per axis."""
    corners = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    uv_corners = np.array([uv_left(c) for c in corners])
    # centre UV (0.25, 0.2) is (−0.5, 0.25); 0.04 in u is 0.1 in x, 0.02 in v is 0.05 in y
    ring = footprint_ring((0.25, 0.2), (0.04, 0.02), uv_corners, corners, segments=4)
    assert ring == pytest.approx(np.array([[-0.4, 0.25, 0.0], [-0.5, 0.3, 0.0],
                                           [-0.6, 0.25, 0.0], [-0.5, 0.2, 0.0]]), abs=1e-9)
    assert footprint_ring((0.25, 0.2), (0.04, 0.02), uv_corners, corners).shape == (48, 3)


def test_a_split_vertex_that_is_no_uv_seam_gives_one_image() -> None:
    """A vertex split in two render vertices with the same UV (a hard edge, not a UV seam)
    does not give a dab beside it a second, identical mirror image."""
    mesh = flat(-1.0, 1.0, 0.0, 1.0)  # 3 × 3 vertices; 4 is the centre (0, 0.5)
    tris = mesh.triangles.copy()
    right = np.isin(tris, [2, 5, 8]).any(axis=1)  # the triangles of the right half
    tris[right] = np.where(tris[right] == 4, 9, tris[right])
    split = FaceMesh(mesh.rest, tris, np.r_[mesh.uvs, mesh.uvs[4:5]], np.r_[mesh.weld, 4])
    mirror = SurfaceMirror(split)
    assert mirror.seams.seam_welded.tolist() == [False] * 4 + [True] + [False] * 4
    owner, uv, scale = mirror.mirror_uv(np.array([[0.4975, 0.5]]), reach=0.02)
    assert owner.tolist() == [0]
    assert uv == pytest.approx(np.array([[0.5025, 0.5]]), abs=1e-6)
    assert scale == pytest.approx([1.0])


def test_an_eye_over_the_skin_in_uv_is_never_a_dab_or_its_mirror_image() -> None:
    """A symmetric face over [−1, 1] × [0, 1] (UV = its position) and an eye shell in front
    of its left half whose UVs cover the face's right half: a dab on the skin's left half is
    mirrored onto the skin's right half (u → 1 − u), not onto or from the eye."""
    face = flat(-1.0, 1.0, 0.0, 1.0)
    eye = flat(-0.9, -0.1, 0.1, 0.9, lambda x, y: (0.55 + 0.4 * (x + 0.9) / 0.8, y))
    shift = len(face.rest)
    in_front = eye.rest + np.array([0.0, 0.0, 0.2])
    mesh = FaceMesh(np.r_[face.rest, in_front],  # the eye's triangles first
                    np.r_[eye.triangles + shift, face.triangles], np.r_[face.uvs, eye.uvs],
                    np.arange(shift + len(eye.rest)))
    skin = np.arange(mesh.n_triangles) >= eye.n_triangles
    dabs = np.array([[0.2, 0.5], [0.3, 0.3], [0.8, 0.6]])  # the last under the eye's UVs
    owner, uv, _ = SurfaceMirror(mesh, skin=skin).mirror_uv(dabs, 0.01)
    np.testing.assert_array_equal(owner, [0, 1, 2])
    np.testing.assert_allclose(uv, np.c_[1.0 - dabs[:, 0], dabs[:, 1]], atol=1e-6)
    tri, _ = SurfaceMirror(mesh, skin=skin).locate_uv(dabs, 0.01)
    assert skin[tri].all()
    _, taken, _ = SurfaceMirror(mesh).mirror_uv(dabs, 0.01)  # the eye in the search
    assert np.abs(taken - np.c_[1.0 - dabs[:, 0], dabs[:, 1]]).max() > 0.05
