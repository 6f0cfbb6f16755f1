"""The real shaders against the numpy references of their formulas, on a standalone EGL context,
over meshes and parameters drawn by hypothesis:

- technique 2's per-vertex visibility (shaders/face.vert ``wdv_visibility``), read back by
  transform feedback, against ``studio.core.wrinkles.wdv.visibility``;
- technique 1's compose pass (shaders/t1_compose.frag), the weight texture read back, against
  ``studio.core.wrinkles.mask_sparse.composed_weights``;
- the tangent frame's handedness on a mirrored UV island, in a render.

Tolerances: technique 2 within 0.01 (float32 ``acos`` on the GPU: near α = 0 its error is
about 5e-4 rad, over cones of at least 0.2 rad and magnitudes of at most 2); technique 1 within
2e-3 (the weight texture is float16).
"""

from __future__ import annotations

import moderngl
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.tangent_frames import TANGENT_FRAMES
from studio.core.project.model import Project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.mask_sparse import composed_weights, sparse_masks
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from studio.core.wrinkles.wdv import WdvSlots, visibility
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from studio.render.shaders import build_program

GPU_SETTINGS = settings(max_examples=25, deadline=None,
                        suppress_health_check=[HealthCheck.function_scoped_fixture])


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@st.composite
def wdv_cases(draw):
    """Vertices with motions and four slots each, many of them inside their cones."""
    n = draw(st.integers(1, 48))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    delta = rng.normal(size=(n, 3)) * rng.uniform(0.0, 1.0, (n, 1))
    delta[rng.random(n) < 0.1] = 0.0  # some vertices at rest
    dirs = np.zeros((n, 4, 4), np.float32)
    for s in range(4):
        # a direction near the motion (within ±1 rad) or anywhere
        towards = unit(delta + 1e-9 + rng.normal(scale=0.6, size=(n, 3)) * np.linalg.norm(
            delta, axis=1, keepdims=True))
        anywhere = unit(rng.normal(size=(n, 3)))
        dirs[:, s, :3] = np.where(rng.random((n, 1)) < 0.7, towards, anywhere)
        dirs[:, s, 3] = np.where(rng.random(n) < 0.15, 0.0, rng.uniform(0.5, 2.0, n))
    cones = rng.uniform(0.2, 1.5, (n, 4)).astype(np.float32)
    cones[rng.random((n, 4)) < 0.1] = 0.0  # an unused cone
    maps = rng.integers(0, 4, (n, 4)).astype(np.float32)
    expression = draw(st.floats(0.2, 1.0))
    scale_free = draw(st.booleans())
    return (delta.astype(np.float32), WdvSlots(dirs, cones, maps), expression, scale_free)


def gpu_visibility(ctx: moderngl.Context, delta: np.ndarray, slots: WdvSlots,
                   expression: float, scale_free: bool) -> np.ndarray:
    """v_weights from the real technique-2 vertex shader, per vertex, by transform feedback."""
    prog = build_program(ctx, "face.vert", None, ("TECHNIQUE_T2",), varyings=["v_weights"])
    n = len(delta)
    rest = np.random.default_rng(0).normal(size=(n, 3)).astype(np.float32)
    for name in ("u_view", "u_proj"):
        prog[name].write(np.eye(4, dtype="f4").tobytes())
    prog["u_expression"].value = expression
    prog["u_scale_free"].value = scale_free
    geometry = np.hstack([rest + delta, np.tile([0, 0, 1, 1, 0, 0, 1], (n, 1))])  # N, T
    static = np.hstack([np.zeros((n, 2)), rest, np.ones((n, 1))])
    wdv = np.hstack([slots.dirs.reshape(n, 16), slots.cones, slots.maps])
    buffers = [ctx.buffer(np.ascontiguousarray(a, np.float32).tobytes())
               for a in (geometry, static, wdv)]
    out = ctx.buffer(reserve=n * 16)
    target = ctx.simple_framebuffer((1, 1))  # a surfaceless EGL context captures nothing
    target.use()  # without a framebuffer bound
    vao = ctx.vertex_array(prog, [
        (buffers[0], "3f 3f 4f", "in_position", "in_normal", "in_tangent"),
        (buffers[1], "2f 3f 1f", "in_uv", "in_rest", "in_skin"),
        (buffers[2], "16f 4f 4f", "in_wdv", "in_cone", "in_slot_map"),
    ], skip_errors=True)
    vao.transform(out, mode=moderngl.POINTS, vertices=n)
    result = np.frombuffer(out.read(), np.float32).reshape(n, 4).copy()
    for obj in (vao, out, prog, target, *buffers):
        obj.release()
    return result


@GPU_SETTINGS
@given(case=wdv_cases())
def test_technique_2_visibility_on_the_gpu_is_the_formula(gl_context, case):
    delta, slots, expression, scale_free = case
    expected = visibility(delta, slots, expression, scale_free)
    got = gpu_visibility(gl_context, delta, slots, expression, scale_free)
    np.testing.assert_allclose(got, expected, atol=1e-2)


def test_technique_2_falloff_by_hand(gl_context):
    """One slot, θ = 0.5 rad, a motion of length 0.5 at α = 0.25 rad from the direction,
    authored length 1, k = 1: w = 0.5 · (1 − 0.25 / 0.5) = 0.25; outside the cone, 0."""
    a = 0.25
    delta = np.array([[0.5 * np.cos(a), 0.5 * np.sin(a), 0.0], [0.0, 0.5, 0.0]], np.float32)
    dirs = np.zeros((2, 4, 4), np.float32)
    dirs[:, 0] = (1.0, 0.0, 0.0, 1.0)
    cones = np.zeros((2, 4), np.float32)
    cones[:, 0] = 0.5
    slots = WdvSlots(dirs, cones, np.zeros((2, 4), np.float32))
    got = gpu_visibility(gl_context, delta, slots, 1.0, True)
    np.testing.assert_allclose(got[:, 0], [0.25, 0.0], atol=1e-4)
    np.testing.assert_allclose(visibility(delta, slots, 1.0, True)[:, 0], [0.25, 0.0], atol=1e-6)


@st.composite
def compose_cases(draw):
    n = draw(st.integers(1, 9))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    masks = rng.random((n, 12, 16)).astype(np.float32)
    masks[rng.random(masks.shape) < 0.4] = 0.0
    activations = rng.uniform(0.0, 1.6, n).astype(np.float32)  # sums over 1 show the clamp
    maps = rng.integers(0, 4, n)
    return masks, activations, maps


@GPU_SETTINGS
@given(case=compose_cases())
def test_technique_1_compose_pass_on_the_gpu_is_the_formula(gl_context, case):
    masks, activations, maps = case
    with OffscreenStudio(make_test_face(561, 64, 16), 32, 32, ctx=gl_context) as studio:
        renderer = studio.renderer
        renderer.set_masks(masks)
        renderer.set_area_maps(maps.astype(np.float32))
        renderer.set_activations(activations)
        got = renderer.read_t1_weights()
    expected = composed_weights(sparse_masks(masks), activations, maps)
    np.testing.assert_allclose(got, expected, atol=2e-3)
    assert got.max() <= 1.0  # clamped, as the reference


def mirrored_plane() -> Project:
    """Two quads side by side facing +Z; the right one's UVs mirrored (u runs from 1 to 0),
    so its tangent frame has handedness −1 — a UV seam down the middle."""
    rest = np.array([[-1, -1, 0], [0, -1, 0], [0, 1, 0], [-1, 1, 0], [1, -1, 0], [1, 1, 0]],
                    np.float32)
    weld = np.array([0, 1, 2, 3, 1, 4, 5, 2])  # render vertices 4–7: the right quad's
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [1, 0], [0, 0], [0, 1], [1, 1]],
                   np.float32)
    tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    neutral = flat_normal_map(8)
    neutral[...] = (128, 200, 210)  # tilted toward +v (tangent-space green)
    return Project("plane", FaceMesh(rest, tris, uvs, weld), [],
                   FaceTextures(np.full((8, 8, 3), 200, np.uint8), neutral, flat_normal_map()))


@pytest.mark.parametrize("frame", TANGENT_FRAMES)
def test_a_mirrored_uv_island_tilts_its_normals_the_same_way(gl_context, frame):
    """The normal map tilts every normal toward +v, which is +Y on both quads: the mirrored
    half must show the same normal colour. If the handedness were ignored, its bitangent would
    point to −Y and its normals would tilt down instead."""
    project = mirrored_plane()
    size = 120
    with OffscreenStudio(project, size, size, ctx=gl_context) as studio:
        studio.camera.yaw = studio.camera.pitch = 0.0
        studio.camera.frame(np.array([-1.2, -1.2, 0]), np.array([1.2, 1.2, 0]))
        image = studio.render(RenderSettings(technique="none", view="normals",
                                             tangent_frame=frame), {}).astype(int)
    left = image[size // 2 - 10:size // 2 + 10, size // 4 - 8:size // 4 + 8].reshape(-1, 3)
    right = image[size // 2 - 10:size // 2 + 10, 3 * size // 4 - 8:3 * size // 4 + 8]
    left_colour, right_colour = left.mean(axis=0), right.reshape(-1, 3).mean(axis=0)
    assert left_colour[1] > left_colour[0] + 30  # green up: the normals do tilt toward +Y
    np.testing.assert_allclose(right_colour, left_colour, atol=2.0)


@pytest.mark.parametrize("frame", TANGENT_FRAMES)
def test_a_wrinkle_across_a_uv_seam_and_a_mirrored_island_shades_alike(gl_context, frame):
    """Technique 2 revealing a wrinkled map over both quads of the mirrored plane: the UV seam
    down the middle is invisible (the columns either side match) and the mirrored half shows
    the same wrinkle, not an inverted one."""
    from studio.core.animation.poses import KeyPose
    from studio.core.wrinkles.wdv import WdvArea, WdvSetup

    project = mirrored_plane()
    project.textures.normal_neutral = flat_normal_map(8)
    tilted = flat_normal_map(8)
    tilted[...] = (128, 200, 210)  # the wrinkled map tilts toward +v
    project.textures.normal_wrinkled = tilted
    rest = project.mesh.rest
    project.poses = [KeyPose("lift", rest + np.float32([0.0, 0.1, 0.0]))]
    n = len(rest)
    project.wdv = WdvSetup([WdvArea("all", "lift", np.tile([0.0, 1.0, 0.0], (n, 1)),
                                    np.full(n, 0.1), cone_angle_deg=30.0)])
    size = 120
    with OffscreenStudio(project, size, size, ctx=gl_context) as studio:
        studio.camera.yaw = studio.camera.pitch = 0.0
        studio.camera.frame(np.array([-1.2, -1.2, 0]), np.array([1.2, 1.2, 0]))
        plain = studio.render(RenderSettings(technique="none", tangent_frame=frame),
                              {"lift": 1.0}).astype(int)
        shaded = studio.render(RenderSettings(technique="t2", tangent_frame=frame),
                               {"lift": 1.0}).astype(int)
    rows = slice(size // 2 - 15, size // 2 + 15)
    left = shaded[rows, size // 4 - 8:size // 4 + 8].reshape(-1, 3).mean(axis=0)
    right = shaded[rows, 3 * size // 4 - 8:3 * size // 4 + 8].reshape(-1, 3).mean(axis=0)
    assert np.abs(shaded - plain)[rows].max() > 8  # the wrinkled map shows
    np.testing.assert_allclose(right, left, atol=2.0)  # the same on the mirrored half
    centre = size // 2
    seam = np.abs(shaded[rows, centre - 3] - shaded[rows, centre + 2]).max()
    assert seam <= 3  # no seam
