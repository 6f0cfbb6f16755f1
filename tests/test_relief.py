"""Wrinkles in depth (issue 10): wrinkle heights from normal maps, displacement that shows in the
silhouette, and parallax mapping; rendered on standalone EGL and judged in named regions."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import RenderError
from studio.core.sample.synthetic import sample_landmarks
from studio.core.wrinkles.normalmap import height_to_normal
from studio.core.wrinkles.relief import height_from_normals, relief_image, wrinkle_heights
from studio.core.wrinkles.textures import flat_normal_map
from studio.render import relief_pass
from studio.render.offscreen import OffscreenStudio
from studio.render.renderer import FaceRenderer
from studio.render.settings import RenderSettings
from tests.regions import landmark_pixels, region_difference

W, H = 400, 600
BACKGROUND = (1.0, 0.0, 1.0)  # magenta: nothing on the face has this colour


def correlation(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.corrcoef(a.ravel(), b.ravel())[0, 1])


# --- wrinkle height from normal maps (numpy) ---------------------------------------------------

@pytest.mark.core
@pytest.mark.parametrize("periods", [(3.0, 2.0), (2.5, 1.5)])  # whole, and cut at the borders
def test_a_sinusoidal_height_is_recovered_from_its_normal_map(periods):
    rows, cols = 96, 128
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float64)
    height = (np.sin(2 * np.pi * periods[0] * x / cols)
              + 0.5 * np.cos(2 * np.pi * periods[1] * y / rows))
    normals = height_to_normal(height, 4.0, bits=16)
    recovered = height_from_normals(normals)
    assert correlation(recovered, height) > 0.99  # equal up to a constant and a scale


@pytest.mark.core
def test_up_and_down_are_not_swapped():
    """A bump rising toward +u (right) and +v (up the image) comes back as a bump."""
    y, x = np.mgrid[0:64, 0:64].astype(np.float64)
    bump = np.exp(-((x - 40) ** 2 + (y - 20) ** 2) / 30.0)
    recovered = height_from_normals(height_to_normal(bump, 8.0, bits=16))
    assert np.unravel_index(np.argmax(recovered), recovered.shape) == (20, 40)


@pytest.mark.core
def test_a_flat_map_has_no_height_and_no_wrinkles():
    flat = flat_normal_map(32)
    assert np.abs(height_from_normals(flat)).max() < 1e-6
    heights = wrinkle_heights(flat, [flat, flat])
    assert heights.shape == (2, 32, 32) and not heights.any()


@pytest.mark.core
def test_wrinkle_height_is_a_valley_where_only_the_wrinkled_map_has_it():
    rng = np.random.default_rng(1)
    pores = rng.standard_normal((80, 80)) * 0.02
    x = np.arange(80)[None, :]
    valley = -np.exp(-0.5 * ((x - 30) / 2.0) ** 2) * np.ones((80, 1))
    neutral = height_to_normal(pores, 6.0)
    wrinkled = height_to_normal(pores + valley, 6.0)
    shallow = height_to_normal(pores + 0.5 * valley, 6.0)
    heights = wrinkle_heights(neutral, [wrinkled, shallow, neutral])
    deep = heights[0]
    assert deep.min() == pytest.approx(-1.0)  # the deepest wrinkle of all maps is -1
    assert np.all(deep[:, 30] < -0.9)  # the valley's floor runs down column 30
    assert np.abs(deep[:, 50:]).max() < 0.05  # beside it the skin stays at 0; pores cancel
    assert heights[1].min() == pytest.approx(-0.5, abs=0.06)  # scaled jointly with map 0
    assert not heights[2].any()  # the neutral map itself: no wrinkle
    image = relief_image(neutral, [wrinkled, shallow])
    assert image.shape == (80, 80, 4) and image.dtype == np.float16
    assert not image[..., 2:].any()


@pytest.mark.core
def test_large_maps_give_heights_at_a_fraction_of_their_size_with_every_wrinkle():
    x = np.arange(300)[None, :]
    valley = -np.exp(-0.5 * ((x - 151) / 1.5) ** 2) * np.ones((300, 1))  # 5 texels wide
    neutral = height_to_normal(0 * valley, bits=16)
    wrinkled = height_to_normal(valley, 2.0, bits=16)
    full = wrinkle_heights(neutral, [wrinkled])[0]
    small = wrinkle_heights(neutral, [wrinkled], max_size=100)[0]
    assert full.shape == (300, 300) and small.shape == (100, 100)
    assert small[:, 50].max() < -0.9 and np.abs(small[:, :40]).max() < 0.05
    assert correlation(small, full.reshape(100, 3, 100, 3).mean(axis=(1, 3))) > 0.98


# --- rendering ---------------------------------------------------------------------------------

@pytest.fixture
def studio(sample, gl_context):
    """The sample face in profile (yaw 90°), level, framed on the face from forehead to chin."""
    s = OffscreenStudio(sample, W, H, ctx=gl_context)
    s.camera.yaw, s.camera.pitch = 90.0, 0.0
    s.camera.frame(*sample.mesh.bounds())
    marks = sample_landmarks(sample)
    s.camera.target = (marks["forehead"] + marks["chin"]) / 2.0 + [0.0, 0.1, 0.0]
    s.camera.distance *= 0.55
    yield s
    s.release()


def render(studio: OffscreenStudio, technique: str, weights: dict, **kwargs) -> np.ndarray:
    settings = RenderSettings(technique=technique, background=BACKGROUND, **kwargs)
    return studio.render(settings, weights)


def face_mask(image: np.ndarray) -> np.ndarray:
    """Pixels covered by the face (anything but the pure background, edges included)."""
    return np.abs(image.astype(int) - (255, 0, 255)).max(axis=2) > 0


def rows_around(studio: OffscreenStudio, name: str, half: int) -> slice:
    _, y = landmark_pixels(studio.scene.project, studio.camera, W, H)[name]
    return slice(y - half, y + half + 1)


@pytest.mark.parametrize("technique", ["t2", "t1"])
def test_displaced_wrinkles_change_the_profile_at_the_forehead_not_the_chin(studio, technique):
    surprise = {"surprise": 1.0}
    off = face_mask(render(studio, technique, surprise))
    shown = face_mask(render(studio, technique, surprise, relief="displace"))
    forehead, chin = rows_around(studio, "forehead", 40), rows_around(studio, "chin", 20)
    changed_rows = (off[forehead] != shown[forehead]).any(axis=1)
    assert changed_rows.sum() >= 10  # notches all along the forehead's outline
    assert (off[forehead] & ~shown[forehead]).sum() >= 5  # valleys cut into it
    assert np.array_equal(off[chin], shown[chin])


@pytest.mark.parametrize("technique", ["t2", "t1", "strain"])
def test_displacement_changes_nothing_in_the_neutral_pose(studio, technique):
    off = render(studio, technique, {})
    shown = render(studio, technique, {}, relief="displace")
    assert np.array_equal(face_mask(shown), face_mask(off))
    # the same triangles, drawn through the tessellator: at most rounding in a few pixels (its
    # patches' texture derivatives differ slightly, and trilinear filtering, a software
    # renderer's, turns that into a level or two)
    difference = np.abs(shown.astype(int) - off).max(axis=-1)
    assert difference.max() <= 2 and (difference > 1).mean() < 0.001


def test_displacement_follows_the_depth(studio):
    surprise = {"surprise": 1.0}
    forehead = rows_around(studio, "forehead", 40)
    off = face_mask(render(studio, "t2", surprise))[forehead]
    changed = [(off != face_mask(render(studio, "t2", surprise, relief="displace",
                                        relief_depth=d))[forehead]).sum()
               for d in (0.0, 0.03, 0.06)]
    assert changed[0] <= 2  # depth 0: the plain outline (but for rounding in a pixel or two)
    assert changed[0] + 10 < changed[1] < changed[2]


def test_the_displaced_surface_has_no_pinholes(sample, gl_context):
    """Close on the forehead, where the most segments are, and without multisampling (which
    would blur a pinhole away): no pixel may show the far side of the head through a crack
    between patches (seen as a normal facing away, in the normals view)."""
    with OffscreenStudio(sample, W, H, samples=0, ctx=gl_context) as studio:
        studio.camera.yaw, studio.camera.pitch = 90.0, 0.0
        studio.camera.frame(*sample.mesh.bounds())
        studio.camera.target = sample_landmarks(sample)["forehead"].astype(float)
        studio.camera.distance *= 0.25
        for technique in ("t1", "t2"):
            image = render(studio, technique, {"surprise": 1.0}, relief="displace",
                           view="normals")
            inside = face_mask(image)
            for axis in (0, 1):  # away from the outline, where grazing normals are fine
                inside &= np.roll(inside, 4, axis) & np.roll(inside, -4, axis)
            facing_away = image[..., 2] < 100  # view-space normal z below about -0.2
            assert (inside & facing_away).sum() == 0, technique


def test_parallax_moves_the_forehead_wrinkles_not_the_chin(sample, gl_context):
    with OffscreenStudio(sample, W, H, ctx=gl_context) as studio:
        studio.camera.frame(*sample.mesh.bounds())  # the whole head, as these figures were set
        studio.camera.yaw = 50.0  # oblique: parallax shifts with the view angle
        marks = landmark_pixels(sample, studio.camera, W, H)
        surprise = {"surprise": 1.0}
        off = render(studio, "t2", surprise)
        parallax = render(studio, "t2", surprise, relief="parallax")
        assert region_difference(off, parallax, marks["forehead"]) > 4.0
        assert region_difference(off, parallax, marks["chin"]) == 0.0
        assert np.array_equal(face_mask(off), face_mask(parallax))  # not in the silhouette
        assert np.array_equal(render(studio, "t2", {}, relief="parallax"),
                              render(studio, "t2", {}))


def test_relief_settings_are_checked_and_select_programs():
    with pytest.raises(ValueError, match="relief"):
        RenderSettings(relief="bumpy")
    with pytest.raises(ValueError, match="depth"):
        RenderSettings(relief="displace", relief_depth=-0.1)
    assert "RELIEF_DISPLACE" in RenderSettings(technique="t1", relief="displace").program_key()
    assert "RELIEF_PARALLAX" in RenderSettings(technique="strain", relief="parallax").program_key()
    # no wrinkles to raise: the plain program, whatever the relief
    assert RenderSettings(technique="none", relief="displace").program_key() == \
        RenderSettings(technique="none").program_key()
    # the depth is a uniform, not another program
    assert RenderSettings(relief="parallax", relief_depth=0.1).program_key() == \
        RenderSettings(relief="parallax").program_key()


def test_without_opengl_4_displacement_is_refused_with_a_clear_message(studio, monkeypatch):
    monkeypatch.setattr(FaceRenderer, "can_displace", property(lambda self: False))
    with pytest.raises(RenderError, match=r"OpenGL 4\.0.*parallax"):
        render(studio, "t2", {"surprise": 1.0}, relief="displace")
    render(studio, "t2", {"surprise": 1.0}, relief="parallax")  # the offered fallback draws


def test_wrinkle_heights_are_made_once_per_set_of_maps_not_per_frame(studio, monkeypatch):
    calls = []
    real = relief_pass.relief_image
    monkeypatch.setattr(relief_pass, "relief_image",
                        lambda *a: calls.append(1) or real(*a))
    project = studio.scene.project
    for pose in ("surprise", "squeeze", "frown"):
        render(studio, "t2", {pose: 1.0}, relief="displace")
        render(studio, "t1", {pose: 1.0}, relief="parallax")
    studio.scene.reload_textures()  # the same maps again: nothing to redo
    render(studio, "t2", {"surprise": 1.0}, relief="displace")
    assert len(calls) == 1
    for name in project.textures.wrinkle_map_names:  # "wrinkled" maps with no wrinkles
        project.textures.set_wrinkle_map(name, project.textures.normal_neutral.copy())
    studio.scene.reload_textures()
    flat = render(studio, "t2", {"surprise": 1.0}, relief="displace")
    assert len(calls) == 2
    # no map has wrinkles now: the forehead's outline is back to the plain one (finely
    # tessellated still, so a pixel or two may round the other way)
    forehead = rows_around(studio, "forehead", 40)
    plain = render(studio, "t2", {"surprise": 1.0})
    assert (face_mask(flat)[forehead] != face_mask(plain)[forehead]).sum() <= 2
