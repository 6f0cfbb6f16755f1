"""The real fragment stage (shaders/face.frag) against its numpy reference
(studio/core/wrinkles/shading.py), pixel by pixel, on a standalone EGL context.

The face is tests/hand_faces.py's flat grid seen straight on, so every pixel's inputs are
known: the plane point under the pixel's centre gives the view position and the UV, the
tangent frame is view space's axes. Its maps are 32² texels in 8 × 8 cells of one value each
(seeded random: neutral and three wrinkled maps, the diffuse, four technique-1 masks at random
activations revealing the three maps, so several maps' weights meet and often sum past 1);
the left two columns of vertices are not face, so the skin runs from 0 to 1 across the second
column of cells. Pixels are compared where the textures' bilinear filter reads one cell only
(at least ``MARGIN`` texels from a cell's edge) and the quad covers the pixel.

Tolerance: ``TOLERANCE`` levels of 255. The GPU works in float32 and writes 8 bits; the
technique-1 weight texture is float16 (the reference rounds the weights the same way).
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.camera import OrbitCamera
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.mask_sparse import quantise
from studio.core.wrinkles.shading import Fragment, Lighting, fragment_colour
from studio.core.wrinkles.skin_light import RIG_NAMES, light_rig
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.hand_faces import front_camera, grid_face

PIXELS = 96
TEXELS = 32
CELLS = 8  # cells a side: each TEXELS / CELLS texels
MARGIN = 0.75  # texels from a cell's edge, beyond the bilinear filter's reach (0.5)
TOLERANCE = 1.5  # measured: at most 0.84 on llvmpipe
MAPS = ("brow", "smile", "squint")
VIEWS = ("shaded", "heat", "heat-shows", "normals", "uv")
LIGHTS = {"default": (0.45, 0.5, 0.75), "grazing": (0.9, -0.2, 0.35)}


def cell_image(values: np.ndarray) -> np.ndarray:
    """(CELLS, CELLS, ...) cell values blown up to (TEXELS, TEXELS, ...)."""
    k = TEXELS // CELLS
    return np.repeat(np.repeat(values, k, axis=0), k, axis=1)


class Case:
    """The hand-built face and, per cell, what its pixels' inputs are."""

    def __init__(self, seed: int, tone: bool = True) -> None:
        rng = np.random.default_rng(seed)
        shape = (CELLS, CELLS)
        # normal maps: x, y well inside the unit disc (z > 0), some cells flat
        def normal_cells() -> np.ndarray:
            xy = rng.integers(60, 196, (*shape, 2))
            xy[rng.random(shape) < 0.2] = 128
            return np.dstack([xy, np.full(shape, 255)]).astype(np.uint8)

        self.neutral = normal_cells()
        self.wrinkled = [normal_cells() for _ in MAPS]
        self.diffuse = rng.integers(40, 250, (*shape, 3)).astype(np.uint8)
        masks = rng.integers(0, 256, (4, *shape))
        masks[rng.random((4, *shape)) < 0.3] = 0
        self.masks = masks.astype(np.float32) / 255.0
        self.activations = np.array([1.0, 0.8, 0.65, 0.9]) * rng.uniform(0.7, 1.0, 4)
        self.area_maps = (0, 1, 2, 0)
        self.project = grid_face({name: cell_image(m) for name, m in zip(
            MAPS, self.wrinkled, strict=True)}, neutral=cell_image(self.neutral),
            diffuse=cell_image(self.diffuse), cells=CELLS)
        # each map's colour (around the unchanged 128) and cavity (open 255 to deep): issue 46
        self.tone = np.stack([np.dstack([rng.integers(90, 170, (*shape, 3)),
                                         rng.integers(110, 256, shape)]) for _ in MAPS]
                             ).astype(np.uint8)
        for name, cells in zip(MAPS, self.tone if tone else (), strict=False):
            self.project.textures.set_tone(name, cell_image(cells[..., 3]),
                                           cell_image(cells[..., :3]))
        self.project.influence.areas = [
            InfluenceArea(f"area {i}", cell_image(self.masks[i]), activation=float(a),
                          wrinkle_map=MAPS[m])
            for i, (a, m) in enumerate(zip(self.activations, self.area_maps, strict=True))]
        rest = self.project.mesh.rest
        self.project.not_face = rest[:, 0] < -0.6  # the vertex columns at x = -1 and -0.75

    @property
    def has_tone(self) -> bool:
        return self.project.textures.has_tone

    def weights(self, t1_mode: str) -> np.ndarray:
        """(CELLS, CELLS, 4) technique 1's per-map weights: Σ mask · activation, clamped."""
        masks = quantise(self.masks).astype(np.float64) / 255.0
        w = np.zeros((CELLS, CELLS, 4))
        for mask, a, m in zip(masks, self.activations.astype(np.float32), self.area_maps,
                              strict=True):
            w[..., m] += mask * a
        w = np.clip(w, 0.0, 1.0)
        return w.astype(np.float16).astype(np.float64) if t1_mode == "composed" else w


def plane_points(camera: OrbitCamera) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) the model-space point on the plane z = 0 under each pixel's centre, and the
    view-space position there."""
    inverse = np.linalg.inv(camera.view_projection(PIXELS, PIXELS))
    centres = (np.arange(PIXELS) + 0.5) / PIXELS * 2.0 - 1.0
    ndc_x, ndc_y = np.meshgrid(centres, -centres)
    ends = []
    for depth in (-1.0, 1.0):
        clip = np.stack([ndc_x, ndc_y, np.full_like(ndc_x, depth), np.ones_like(ndc_x)], -1)
        world = clip @ inverse.T
        ends.append(world[..., :3] / world[..., 3:])
    near, far = ends
    t = near[..., 2] / (near[..., 2] - far[..., 2])
    point = near + (far - near) * t[..., None]
    view = camera.view_matrix()
    return point, point @ view[:3, :3].T + view[:3, 3]


def reference(case: Case, camera: OrbitCamera, settings: RenderSettings
              ) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) the reference's colours in 0..255, and (H, W) which pixels to compare."""
    point, view_pos = plane_points(camera)
    u, v = (point[..., 0] + 1) / 2, (point[..., 1] + 1) / 2
    texel = np.stack([(1 - v) * TEXELS, u * TEXELS], -1)  # row, column
    per_cell = TEXELS / CELLS
    offset = np.mod(texel, per_cell)
    inside = (texel >= 0).all(-1) & (texel < TEXELS).all(-1)
    compared = inside & (np.minimum(offset, per_cell - offset) >= MARGIN).all(-1)
    cell = np.clip((texel // per_cell).astype(int), 0, CELLS - 1)
    rows, cols = cell[..., 0], cell[..., 1]
    weights = case.weights(settings.t1_mode)[rows, cols]
    weights = weights if settings.technique == "t1" else np.zeros_like(weights)
    tbn = camera.view_matrix()[:3, :3]  # columns: the grid's tangent +X, bitangent +Y, +Z
    fragment = Fragment(
        weights=weights,
        skin=np.clip((point[..., 0] + 0.75) / 0.25, 0.0, 1.0),
        neutral=case.neutral[rows, cols, :2] / 255.0,
        wrinkled=np.stack([m[rows, cols, :2] for m in case.wrinkled], -2) / 255.0,
        albedo=case.diffuse[rows, cols] / 255.0,
        tbn=np.broadcast_to(tbn, (PIXELS, PIXELS, 3, 3)),
        view_pos=view_pos, texcoord=np.stack([u, 1 - v], -1),
        tone=np.stack([t[rows, cols] for t in case.tone], -2) / 255.0 if case.has_tone else None)
    lighting = Lighting(settings.light_dir, settings.ambient, settings.specular,
                        settings.shininess)
    rig = light_rig(settings.light_rig, settings.light_dir) if settings.look == "skin" else None
    colour = fragment_colour(fragment, blend=settings.blend, view=settings.view,
                             lighting=lighting, rig=rig)
    return colour * 255.0, compared


@pytest.fixture(scope="module")
def rendered(gl_context):
    """Renders of one seeded face, drawn once per setting."""
    yield from renders(gl_context, Case(seed=28))


@pytest.fixture(scope="module")
def rendered_without_tone(gl_context):
    """The same face without colour and cavity maps: a project made before issue 46."""
    yield from renders(gl_context, Case(seed=28, tone=False))


def renders(gl_context, case: Case):
    images: dict[RenderSettings, np.ndarray] = {}
    with OffscreenStudio(case.project, PIXELS, PIXELS, samples=0, ctx=gl_context) as studio:
        studio.camera = front_camera()

        def draw(**kwargs) -> tuple[Case, RenderSettings, np.ndarray]:
            settings = RenderSettings(**kwargs)
            key = tuple(sorted(kwargs.items()))
            if key not in images:
                images[key] = studio.render(settings, {}).astype(np.float64)
            return case, settings, images[key]

        yield draw, studio.camera


def assert_matches(draw_result, camera: OrbitCamera) -> None:
    case, settings, image = draw_result
    expected, compared = reference(case, camera, settings)
    assert compared.sum() > 1000  # most cells' middles
    error = np.abs(image - expected).max(axis=-1)[compared]
    assert error.max() <= TOLERANCE, (
        f"{settings.view}/{settings.blend}: {int((error > TOLERANCE).sum())} pixels off by up "
        f"to {error.max():.1f} of 255")


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("blend", ["colour", "normal"])
def test_every_view_in_both_blends_is_the_reference(rendered, view, blend):
    draw, camera = rendered
    assert_matches(draw(technique="t1", view=view, blend=blend), camera)


@pytest.mark.parametrize("light", list(LIGHTS))
@pytest.mark.parametrize("t1_mode", ["composed", "direct"])
def test_shading_under_other_lights_and_both_technique_1_modes(rendered, light, t1_mode):
    draw, camera = rendered
    assert_matches(draw(technique="t1", t1_mode=t1_mode, light_dir=LIGHTS[light],
                        specular=0.5, shininess=8.0), camera)


@pytest.mark.parametrize("rig", RIG_NAMES)
@pytest.mark.parametrize("blend", ["colour", "normal"])
def test_the_skin_look_under_each_light_rig_is_the_reference(rendered, rig, blend):
    """Issue 46: shaders/skin.glsl (scattering diffuse per channel, two GGX lobes, the rig's
    three lights) against skin_light.py, in both blends of the wrinkled maps."""
    draw, camera = rendered
    assert_matches(draw(technique="t1", look="skin", light_rig=rig, blend=blend,
                        light_dir=LIGHTS["grazing"]), camera)


@pytest.mark.parametrize("blend", ["colour", "normal"])
def test_a_face_without_colour_and_cavity_maps_draws_as_before(rendered_without_tone,
                                                               rendered, blend):
    """Issue 46: a project without them (an older file) is the reference without tone, and
    the maps are what changes the face that has them (both in the skin look only)."""
    settings = {"technique": "t1", "look": "skin", "blend": blend}
    draw, camera = rendered_without_tone
    plain = draw(**settings)
    assert_matches(plain, camera)
    toned = rendered[0](**settings)
    assert np.abs(toned[2] - plain[2]).max() > 20
    clay = {"technique": "t1", "blend": blend}
    assert np.array_equal(draw(**clay)[2], rendered[0](**clay)[2])  # clay ignores them


def test_no_wrinkles_is_the_reference_at_zero_weight(rendered):
    draw, camera = rendered
    assert_matches(draw(technique="none", blend="colour"), camera)


def test_the_hand_built_face_has_what_the_comparison_needs(rendered):
    """Cells where the maps' weights sum past 1 (the 1 / W scaling), several maps meeting,
    a flat wrinkled cell under a weight, the not-face ramp: each inside the compared pixels."""
    draw, camera = rendered
    case, settings, _ = draw(technique="t1", view="shaded", blend="colour")
    w = case.weights("composed")
    assert (w.sum(-1) > 1.2).sum() >= 5
    assert ((w > 0.1).sum(-1) >= 3).sum() >= 5
    flat = np.stack([(m[..., :2] == case.neutral[..., :2]).all(-1) for m in case.wrinkled], -1)
    assert ((w[..., :3] > 0.3) & flat).any()
    _, compared = reference(case, camera, settings)
    point, _ = plane_points(camera)
    ramp = compared & (point[..., 0] > -0.75) & (point[..., 0] < -0.5)
    assert ramp.sum() > 20
