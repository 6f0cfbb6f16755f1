"""Renderer behaviour on a standalone EGL context, judged in named regions of the sample face."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from studio.core.wrinkles.influence import InfluenceArea
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.regions import landmark_pixels, region_difference

W, H = 400, 300
CHANGED = 4.0  # region difference (0-255, see regions.py) that counts as a visible change
SAME = 0.5  # ... and below which a region counts as unchanged


@pytest.fixture
def studio(sample, gl_context):
    s = OffscreenStudio(sample, W, H, ctx=gl_context)
    yield s
    s.release()


def render(studio: OffscreenStudio, technique: str, weights=None, **kwargs) -> np.ndarray:
    return studio.render(RenderSettings(technique=technique, **kwargs), weights or {})


def marks(studio: OffscreenStudio) -> dict[str, tuple[int, int]]:
    return landmark_pixels(studio.scene.project, studio.camera, W, H)


def test_the_face_fills_the_view_and_has_features(studio):
    image = render(studio, "none")
    background = np.array([41, 43, 48])  # RenderSettings' background in sRGB bytes
    face = np.abs(image.astype(int) - background).sum(axis=2) > 12
    assert 0.15 < face.mean() < 0.9
    m = marks(studio)
    for name in ("forehead", "chin", "nose tip", "eye corner left", "mouth"):
        x, y = m[name]
        assert 0 <= x < W and 0 <= y < H and face[y, x], name


def test_t2_in_surprise_changes_forehead_not_chin(studio):
    weights = {"surprise": 1.0}
    none, t2 = render(studio, "none", weights), render(studio, "t2", weights)
    m = marks(studio)
    assert region_difference(none, t2, m["forehead"]) > CHANGED
    assert region_difference(none, t2, m["chin"]) < SAME


def test_t2_in_squeeze_changes_eye_corners_not_chin(studio):
    studio.camera.yaw = 0.0  # from the front, both corners face the camera alike
    weights = {"squeeze": 1.0}
    none, t2 = render(studio, "none", weights), render(studio, "t2", weights)
    m = marks(studio)
    assert region_difference(none, t2, m["eye corner left"]) > CHANGED
    assert region_difference(none, t2, m["eye corner right"]) > CHANGED
    assert region_difference(none, t2, m["chin"]) < SAME


@pytest.mark.parametrize("technique", ["t1", "t2"])
def test_neutral_pose_shows_no_wrinkles(studio, technique):
    assert np.array_equal(render(studio, technique), render(studio, "none"))


def test_t1_with_every_activation_zero_equals_none_even_when_posed(studio):
    weights = {"surprise": 1.0}
    none = render(studio, "none", weights)
    studio.scene.set_pose_weights(weights)
    studio.renderer.set_activations(np.zeros(len(studio.scene.project.influence.areas)))
    t1 = studio.render(RenderSettings(technique="t1"))
    assert np.array_equal(t1, none)


def test_t1_surprise_links_raise_the_forehead_areas(studio):
    weights = {"surprise": 1.0}
    none, t1 = render(studio, "none", weights), render(studio, "t1", weights)
    m = marks(studio)
    assert region_difference(none, t1, m["forehead left"]) > CHANGED
    assert region_difference(none, t1, m["forehead right"]) > CHANGED
    assert region_difference(none, t1, m["chin"]) < SAME


def coverage_of(project, mask: np.ndarray, gl_context) -> np.ndarray:
    """Pixels whose surface point lies where ``mask`` is non-zero: render the mask as colour."""
    shown = copy.deepcopy(project)
    nonzero = (mask > 0).astype(np.uint8) * 255
    shown.textures.diffuse = np.repeat(nonzero[:, :, None], 3, axis=2)
    s = OffscreenStudio(shown, W, H, ctx=gl_context)
    image = s.render(RenderSettings(technique="none", ambient=1.0, specular=0.0))
    s.release()
    return image.max(axis=2) > 60


def test_one_area_at_full_activation_changes_only_its_mask(studio, gl_context):
    project = studio.scene.project
    index = [a.name for a in project.influence.areas].index("eye corner left")
    none = render(studio, "none")
    activations = np.zeros(len(project.influence.areas), np.float32)
    activations[index] = 1.0
    studio.renderer.set_activations(activations)
    t1 = studio.render(RenderSettings(technique="t1"))
    changed = np.abs(t1.astype(int) - none.astype(int)).max(axis=2) > 0
    covered = coverage_of(project, project.influence.areas[index].mask, gl_context)
    grown = covered.copy()  # one pixel of slack for texture filtering and anti-aliasing
    grown[1:] |= covered[:-1]
    grown[:-1] |= covered[1:]
    grown[:, 1:] |= grown[:, :-1]
    grown[:, :-1] |= grown[:, 1:]
    assert changed.sum() > 200
    assert not (changed & ~grown).any()


def test_the_number_of_areas_is_not_fixed_by_the_shader(studio):
    project = studio.scene.project
    mask = project.influence.areas[0].mask
    weights = {"surprise": 1.0}
    studio.scene.set_pose_weights(weights)
    images = []
    for count in (1, 9, 40):
        stack = np.zeros((count, *mask.shape), np.float32)
        stack[count - 1] = mask
        studio.renderer.set_masks(stack)
        activations = np.zeros(count, np.float32)
        activations[count - 1] = 1.0
        studio.renderer.set_activations(activations)
        images.append(studio.render(RenderSettings(technique="t1")))
    none = render(studio, "none", weights)
    assert not np.array_equal(images[0], none)
    assert np.array_equal(images[0], images[1])
    assert np.array_equal(images[0], images[2])


def test_expression_factor_zero_hides_technique_2(studio):
    weights = {"surprise": 1.0}
    none = render(studio, "none", weights)
    studio.renderer.expression_factor = 0.0
    assert np.array_equal(render(studio, "t2", weights), none)


@pytest.mark.parametrize("view", ["heat", "normals", "uv"])
def test_debug_views_show_something_else(studio, view):
    weights = {"surprise": 1.0}
    shaded = render(studio, "t2", weights)
    debug = render(studio, "t2", weights, view=view)
    assert np.abs(shaded.astype(int) - debug.astype(int)).mean() > 5


def test_heat_map_is_hot_on_the_forehead_in_surprise(studio):
    heat = render(studio, "t2", {"surprise": 1.0}, view="heat")
    cold = render(studio, "t2", {}, view="heat")
    m = marks(studio)
    x, y = m["forehead"]
    hot_red = heat[y - 3:y + 4, x - 3:x + 4, 0].mean()
    cold_red = cold[y - 3:y + 4, x - 3:x + 4, 0].mean()
    assert hot_red > cold_red + 40


def test_wireframe_draws_edges(studio):
    plain = render(studio, "none")
    wired = render(studio, "none", wireframe=True)
    assert np.abs(plain.astype(int) - wired.astype(int)).mean() > 1


def test_an_area_added_to_the_project_reaches_the_gpu(studio):
    """Technique 1 ignores motion: an all-covering area at 1 shows wrinkles in the neutral pose."""
    project = studio.scene.project
    before = render(studio, "t1")
    area = InfluenceArea("everywhere", np.ones_like(project.influence.areas[0].mask))
    area.activation = 1.0
    project.influence.areas.append(area)
    studio.scene.reload_masks()
    after = render(studio, "t1")
    assert region_difference(before, after, marks(studio)["forehead"]) > CHANGED


def test_strain_mode_wrinkles_the_forehead_in_surprise_and_nothing_in_neutral(studio):
    weights = {"surprise": 1.0}
    none, strain = render(studio, "none", weights), render(studio, "strain", weights)
    m = marks(studio)
    assert region_difference(none, strain, m["forehead"]) > CHANGED
    assert region_difference(none, strain, m["chin"]) < SAME
    assert np.array_equal(render(studio, "strain"), render(studio, "none"))


def test_state_left_by_an_overlay_does_not_break_technique_1(studio, gl_context):
    """The viewport's overlays may leave blending on; the compose pass must not inherit it."""
    weights = {"surprise": 1.0}
    clean = render(studio, "t1", weights)
    studio.renderer.set_activations(np.zeros(len(studio.scene.project.influence.areas)))
    render(studio, "t1")  # compose once more so the next change recomposes
    gl_context.enable(gl_context.BLEND)
    gl_context.blend_func = gl_context.SRC_ALPHA, gl_context.ONE_MINUS_SRC_ALPHA
    assert np.array_equal(render(studio, "t1", weights), clean)
    gl_context.disable(gl_context.BLEND)


def test_a_painted_rectangle_recomposes_like_a_full_upload(sample, gl_context):
    """After a dab only its rectangle is recomposed; the picture must equal a fresh renderer's."""
    weights = {"squeeze": 1.0}
    painted = OffscreenStudio(sample, W, H, ctx=gl_context)
    painted.render(RenderSettings(technique="t1"), weights)  # composed once, whole
    area = sample.influence.areas[3]
    h, w = area.mask.shape
    patch = np.ones((h // 4, w // 4), np.float32)
    area.mask[h // 3:h // 3 + h // 4, w // 3:w // 3 + w // 4] = patch
    painted.renderer.update_mask_region(3, w // 3, h // 3, patch)
    assert painted.renderer.t1.dirty_rect == (w // 3, h // 3, w // 4, h // 4)
    after_dab = painted.render(RenderSettings(technique="t1"))  # same pose: only the dab
    assert painted.renderer.t1.dirty_rect is None
    painted.release()
    fresh = OffscreenStudio(sample, W, H, ctx=gl_context)
    expected = fresh.render(RenderSettings(technique="t1"), weights)
    fresh.release()
    assert np.array_equal(after_dab, expected)


def test_recomposing_only_the_changed_areas_equals_a_full_recompose(sample, gl_context):
    """Activations change a few areas a frame; only their masks' boxes are recomposed, and the
    picture must equal a renderer that recomposed everything."""
    weights = [{"surprise": 1.0}, {"surprise": 0.4, "squeeze": 0.7}, {"frown": 1.0}, {}]
    animated = OffscreenStudio(sample, W, H, ctx=gl_context)
    try:
        for w in weights:
            image = animated.render(RenderSettings(technique="t1"), w)
            fresh = OffscreenStudio(sample, W, H, ctx=gl_context)
            try:
                assert np.array_equal(image, fresh.render(RenderSettings(technique="t1"), w))
            finally:
                fresh.release()
    finally:
        animated.release()
