"""Deformation on the GPU against the numpy reference: blended positions, normals, tangents in
both frames, the strain mode's weights and the picture, on random poses of a small bumpy sheet
with a mirrored UV island (a seam down its middle), a UV-degenerate triangle and a vertex that
no triangle uses."""

from __future__ import annotations

import moderngl
import numpy as np
import pytest

from studio.core.animation.poses import KeyPose, PoseBlender
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache
from studio.core.mesh.tangent_frames import TANGENT_FRAMES
from studio.core.wrinkles.strain import StrainField
from studio.core.wrinkles.wdv import SLOTS, WdvSlots, visibility
from studio.render import deform_pass
from studio.render.gpu_deform import GpuDeformPass
from studio.render.programs import Programs

COLUMNS, ROWS = 7, 5  # grid points; the UV mirror line runs down the middle column
SEAM_ROWS = 2  # its lowest points are split into a copy per side (a seam), the others shared


def mirrored_sheet() -> tuple[FaceMesh, list[KeyPose]]:
    """A bumpy grid whose right half's UVs are mirrored (u runs backwards) about its middle
    column: split into two render vertices per position at the lowest rows (a seam), shared
    by both sides above (whose corners lie on both sides of the mirror); plus a triangle whose
    UVs are one point (hung off the sheet's corner on render vertices of its own) and a
    position no triangle uses. Three poses, each moving part of the sheet."""
    x, y = np.meshgrid(np.linspace(-1, 1, COLUMNS), np.linspace(-0.7, 0.7, ROWS))
    z = 0.15 * np.sin(2.1 * x) * np.cos(1.7 * y)
    grid = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    n = len(grid)
    rest = np.vstack([grid, [[-1.2, -1.0, 0.3], [1.3, 0.9, 0.1]]]).astype(np.float32)
    idx = np.arange(n).reshape(ROWS, COLUMNS)
    middle = COLUMNS // 2
    copies = idx[:SEAM_ROWS, middle]  # render vertices n, n + 1, …: the mirrored half's seam
    degenerate = [idx[0, 0], idx[0, 1], n]  # welded positions of the UV-degenerate triangle
    weld = np.concatenate([idx.ravel(), copies, degenerate, [n + 1]])
    uvs = np.column_stack([(rest[weld, 0] + 1) / 2, (rest[weld, 1] + 0.7) / 1.4])
    mirrored = np.zeros(len(weld), bool)
    mirrored[:n] = x.ravel() > 0
    mirrored[n:n + SEAM_ROWS] = True
    uvs[mirrored, 0] = 1.0 - uvs[mirrored, 0]
    first_degenerate = n + SEAM_ROWS
    uvs[first_degenerate:first_degenerate + 3] = (0.9, 0.9)
    seam = {int(i): n + r for r, i in enumerate(copies)}
    triangles = []
    for r in range(ROWS - 1):
        for c in range(COLUMNS - 1):
            def at(rr: int, cc: int, right: bool = c >= middle) -> int:
                i = int(idx[rr, cc])
                return seam.get(i, i) if right else i

            a, b, d, e = at(r, c), at(r, c + 1), at(r + 1, c), at(r + 1, c + 1)
            triangles += [[a, b, e], [a, e, d]]
    triangles.append([first_degenerate, first_degenerate + 1, first_degenerate + 2])
    mesh = FaceMesh(rest, np.array(triangles), uvs.astype(np.float32), weld)
    rng = np.random.default_rng(3)
    poses = []
    for k, region in enumerate((x.ravel() < 0.3, y.ravel() > -0.2, np.hypot(x, y).ravel() < 0.6)):
        moved = rest.copy()
        moved[:n][region] += rng.normal(0, 0.06, (region.sum(), 3)).astype(np.float32)
        poses.append(KeyPose(f"pose {k}", moved))
    return mesh, poses


@pytest.fixture(scope="module")
def sheet():
    return mirrored_sheet()


def gpu_frame(ctx, mesh, poses, weights, frame) -> np.ndarray:
    deform = GpuDeformPass(ctx, Programs(ctx), mesh, poses)
    try:
        deform.set_weights(np.float32(weights))
        deform.upload(frame)
        return np.frombuffer(deform.buffer.read(), np.float32).reshape(-1, 10).copy()
    finally:
        deform.release()


@pytest.mark.parametrize("frame", TANGENT_FRAMES)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_positions_normals_and_tangents_are_numpy_s(gl_context, sheet, frame, seed):
    """Random weights (some zero, some above 1 or negative): the GPU's vertex buffer is the
    numpy reference's to float32 rounding; the handedness exactly."""
    mesh, poses = sheet
    weights = np.random.default_rng(seed).uniform(-0.5, 1.5, len(poses))
    weights[seed % len(poses)] = 0.0
    blender = PoseBlender(mesh.rest, poses)
    positions = blender.blend(dict(zip((p.name for p in poses), weights.tolist(), strict=True)))
    expected = DeformCache(mesh, frame).update(positions)
    got = gpu_frame(gl_context, mesh, poses, weights, frame)
    np.testing.assert_allclose(got[:, :3], expected[:, :3], atol=2e-6)
    np.testing.assert_allclose(got[:, 3:9], expected[:, 3:9], atol=2e-5)
    np.testing.assert_array_equal(got[:, 9], expected[:, 9])


@pytest.mark.parametrize("frame", TANGENT_FRAMES)
def test_the_mirrored_island_seam_and_degenerate_cases_by_hand(gl_context, sheet, frame):
    mesh, poses = sheet
    got = gpu_frame(gl_context, mesh, poses, np.zeros(len(poses)), frame)
    weld = mesh.weld
    grid = ROWS * COLUMNS
    seam = np.arange(grid, grid + SEAM_ROWS)  # the mirrored half's copies
    originals = weld[seam]
    # welded normals: both copies of a seam position shade alike
    np.testing.assert_allclose(got[seam, 3:6], got[originals, 3:6], atol=1e-6)
    # the mirrored half (right of the middle) has handedness -1, the left +1
    x = mesh.rest[weld, 0]
    on_sheet = np.arange(len(weld)) < grid
    assert (got[on_sheet & (x > 0.01), 9] == -1).all()
    assert (got[on_sheet & (x < -0.01), 9] == 1).all()
    assert (got[seam, 9] == -1).all() and (got[originals, 9] == 1).all()
    # tangents are unit and perpendicular to the normals everywhere, never NaN
    assert np.isfinite(got).all()
    np.testing.assert_allclose(np.linalg.norm(got[:, 6:9], axis=1), 1.0, atol=1e-5)
    assert np.abs(np.einsum("ij,ij->i", got[:, 3:6], got[:, 6:9])).max() < 1e-5
    # the position no triangle uses: normal (0, 0, 1), some perpendicular tangent, w = +1
    lonely = len(weld) - 1
    np.testing.assert_array_equal(got[lonely, 3:6], [0, 0, 1])
    np.testing.assert_allclose(got[lonely, 6:10], [0, 1, 0, 1], atol=1e-7)  # (0, 0, 1) × x


def test_strain_weights_are_numpy_s_and_a_stretch_shows_none(gl_context, sheet):
    mesh, poses = sheet
    squeezed = mesh.rest * np.float32([0.9, 1.0, 1.0])  # 10 % shorter along x
    stretched = mesh.rest * np.float32([1.2, 1.2, 1.2])
    cases = [*poses, KeyPose("squeeze", squeezed), KeyPose("stretch", stretched)]
    deform = GpuDeformPass(gl_context, Programs(gl_context), mesh, cases)
    target = gl_context.buffer(reserve=mesh.n_vertices * 4)
    field = StrainField(mesh)
    try:
        for weights in (np.eye(len(cases))[k] for k in range(len(cases))):
            deform.set_weights(np.float32(weights))
            deform.upload("mikktspace")
            _, may_show = deform.write_strain(target, 0.12)
            got = np.frombuffer(target.read(), np.float32)
            positions = mesh.rest + sum(w * (p.positions - mesh.rest)
                                        for w, p in zip(weights, cases, strict=True))
            expected = field.weights(positions.astype(np.float32), 0.12)[mesh.weld]
            np.testing.assert_allclose(got, expected, atol=1e-5)
            assert (may_show[expected > 0] > 0).all()  # the split draw never hides a wrinkle
        assert got.max() == 0.0  # the last case, stretched: nothing compressed
        # squeezed by 10 % along x: a vertex inside the sheet has four x-ish edges of its six
        deform.set_weights(np.float32(np.eye(len(cases))[-2]))
        deform.upload("mikktspace")
        deform.write_strain(target, 0.12)
        got = np.frombuffer(target.read(), np.float32)
        assert got[3 * COLUMNS + 3] > 0.3
    finally:
        target.release()
        deform.release()


@pytest.mark.parametrize("technique", ["t2", "strain", "none"])
def test_the_studio_draws_the_same_face_deformed_either_way(gl_context, monkeypatch, technique):
    """The whole renderer, GPU deformation against numpy, on the procedural face posed: the
    same picture (the split draw's choice of triangles included)."""
    from studio.core.sample.synthetic import make_test_face
    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    project = make_test_face(561)
    weights = {p.name: 0.3 + 0.2 * k for k, p in enumerate(project.poses[:3])}
    images = {}
    for deform in ("cpu", "gpu"):
        monkeypatch.setenv("WRINKLE_DEFORM", deform)
        with OffscreenStudio(project, 96, 96, ctx=gl_context) as studio:
            assert studio.renderer.deforms_on_gpu == (deform == "gpu")
            settings = RenderSettings(technique=technique, view="heat")
            studio.render(settings, weights)  # one pose, then another: the caches move on
            held = {**weights, project.poses[0].name: 0.9}
            images[deform] = studio.render(settings, held)
            assert not studio.scene.set_pose_weights(held)  # a held pose: nothing to redo
            assert np.array_equal(studio.render(settings), images[deform])
    assert images["cpu"].std() > 5  # a picture, not a blank
    difference = np.abs(images["cpu"].astype(int) - images["gpu"].astype(int))
    assert difference.max() <= 2


def test_a_bad_deform_choice_is_one_error(monkeypatch):
    from studio.core.files.errors import RenderError
    from studio.render.renderer import deform_choice

    monkeypatch.setenv("WRINKLE_DEFORM", "quantum")
    with pytest.raises(RenderError, match="WRINKLE_DEFORM=quantum: choose auto, gpu, cpu"):
        deform_choice()


def random_slots(n_welded: int, seed: int) -> WdvSlots:
    """Four slots per vertex, as pack_slots makes them: random unit directions, authored
    lengths, cones of 20–90° and wrinkled maps 0–3; a quarter of the slots unused."""
    rng = np.random.default_rng(seed)
    dirs = rng.normal(size=(n_welded, SLOTS, 3))
    dirs /= np.linalg.norm(dirs, axis=2, keepdims=True)
    lengths = rng.uniform(0.02, 0.12, (n_welded, SLOTS)) * (rng.random((n_welded, SLOTS)) > 0.25)
    return WdvSlots(np.concatenate([dirs, lengths[..., None]], axis=2).astype(np.float32),
                    np.radians(rng.uniform(20.0, 90.0, (n_welded, SLOTS))).astype(np.float32),
                    rng.integers(0, 4, (n_welded, SLOTS)).astype(np.float32))


@pytest.mark.parametrize("scale_free", [True, False])
@pytest.mark.parametrize("seed", [0, 1])
def test_technique_2_weights_from_gpu_positions_are_numpy_s(gl_context, sheet, seed, scale_free):
    """Technique 2's per-vertex weights as the face's vertex shader computes them from the
    positions the GPU blended (captured by transform feedback), against ``wdv.visibility`` of
    the numpy blend: every map's weight, each slot's cone, scale-free or not."""
    mesh, poses = sheet
    weights = np.random.default_rng(seed).uniform(0.2, 1.4, len(poses))
    slots = random_slots(mesh.n_welded, seed)
    # the motion is the poses' own, so some vertices fall inside their slots' cones
    blended = PoseBlender(mesh.rest, poses).blend(
        dict(zip((p.name for p in poses), weights.tolist(), strict=True)))
    delta = blended - mesh.rest
    moving = np.linalg.norm(delta, axis=1) > 0
    slots.dirs[moving, 0, :3] = delta[moving] / np.linalg.norm(delta[moving], axis=1)[:, None]
    slots.dirs[moving, 0, :3] += np.float32(0.2) * slots.dirs[moving, 1, :3]  # off-centre
    slots.dirs[..., :3] /= np.linalg.norm(slots.dirs[..., :3], axis=2, keepdims=True)
    k = 1.7 if scale_free else 12.0  # motions of a few hundredths: weights up to 1 either way
    expected = visibility(delta, slots, k, scale_free)[mesh.weld]
    shown = expected.max(axis=1)
    assert 0.15 < (shown > 0).mean() < 0.9 and (shown == 1).any()
    assert ((expected > 0.05) & (expected < 0.95)).sum() >= 5  # in the cones, not clamped
    assert len(np.unique(np.argmax(expected, axis=1)[shown > 0])) > 1  # to more than one map

    ctx = gl_context
    programs = Programs(ctx)
    deform = GpuDeformPass(ctx, programs, mesh, poses)
    weld = mesh.weld
    static = ctx.buffer(np.hstack([mesh.uvs, mesh.rest[weld]]).astype("f4").tobytes())
    packed = np.hstack([slots.dirs.reshape(mesh.n_welded, -1)[weld], slots.cones[weld],
                        slots.maps[weld]]).astype("f4")
    wdv = ctx.buffer(packed.tobytes())
    skin = ctx.buffer(np.ones(mesh.n_vertices, "f4").tobytes())
    out = ctx.buffer(reserve=mesh.n_vertices * 16)
    try:
        deform.set_weights(np.float32(weights))
        deform.upload("mikktspace")
        prog = programs.feedback("face.vert", ("v_weights",), ("TECHNIQUE_T2",))
        for name in ("u_view", "u_proj"):
            prog[name].write(np.eye(4, dtype="f4").tobytes())
        prog["u_expression"].value = k
        prog["u_scale_free"].value = scale_free
        vao = ctx.vertex_array(prog, [(deform.buffer, deform_pass.ATTRIBUTES, *deform_pass.NAMES),
                                      (static, "2f 3f", "in_uv", "in_rest"),
                                      (skin, "1f", "in_skin"),
                                      (wdv, "16f 4f 4f", "in_wdv", "in_cone", "in_slot_map")],
                               skip_errors=True)
        vao.transform(out, moderngl.POINTS, vertices=mesh.n_vertices)
        got = np.frombuffer(out.read(), np.float32).reshape(-1, 4)
        vao.release()
    finally:
        for buffer in (static, wdv, skin, out):
            buffer.release()
        deform.release()
        programs.release()
    # float32 positions and the GPU's acos: within a quarter of one 8-bit level of the heat view
    np.testing.assert_allclose(got, expected, atol=1e-3)


def fallback_and_right_angle_mesh() -> FaceMesh:
    """Two kinds of vertex the random sheet hardly has. Lone triangles whose UVs are one
    point, so every corner's tangent falls back to a perpendicular of its normal, facing every
    way (the smallest normal component x, y or z, and ties). And a flat grid on exact
    coordinates, so corners of exactly 90° (a dot product of exactly 0), with its UVs
    perturbed so each triangle's +u direction differs and the corner angles weigh."""
    rng = np.random.default_rng(11)
    normals = [(0, 0, 1), (1, 0, 0), (0, 1, 0), (1, 1, 1), (0.2, 0.9, 0.4), (0.9, 0.2, 0.4),
               (0.4, 0.2, 0.9), (-0.3, 0.3, 0.9), (0.5, -0.5, 0.2), (0, 0.6, -0.8)]
    rest, uvs, triangles = [], [], []
    for k, n in enumerate(normals):
        n = np.asarray(n, float) / np.linalg.norm(n)
        u = np.cross(n, [0.3, 0.5, 0.7])
        u /= np.linalg.norm(u)
        v = np.cross(n, u)  # (u, v, n) right-handed: the triangle faces n
        centre = np.array([3.0 * k, 5.0, 0.0])
        rest += [centre, centre + u, centre + v]
        uvs += [(0.2, 0.2)] * 3
        triangles.append([3 * k, 3 * k + 1, 3 * k + 2])
    first = len(rest)
    x, y = np.meshgrid(np.arange(5.0), np.arange(4.0))
    idx = first + np.arange(x.size).reshape(x.shape)
    rest += list(np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]))
    uvs += list(np.column_stack([x.ravel(), y.ravel()]) / 5.0
                + rng.uniform(-0.05, 0.05, (x.size, 2)))
    for r in range(3):
        for c in range(4):
            a, b, d, e = idx[r, c], idx[r, c + 1], idx[r + 1, c], idx[r + 1, c + 1]
            triangles += [[a, b, e], [a, e, d]]  # right angles at b and at d
    rest = np.asarray(rest, np.float32)
    return FaceMesh(rest, np.asarray(triangles), np.asarray(uvs, np.float32),
                    np.arange(len(rest)))


@pytest.mark.parametrize("frame", TANGENT_FRAMES)
def test_fallback_tangents_and_right_angled_corners_are_numpy_s(gl_context, frame):
    mesh = fallback_and_right_angle_mesh()
    pose = KeyPose("shift", mesh.rest + np.float32([0.0, 0.0, 0.01]))
    got = gpu_frame(gl_context, mesh, [pose], np.zeros(1), frame)
    expected = DeformCache(mesh, frame).update(mesh.rest)
    lone = np.arange(30)  # the lone triangles' vertices: every tangent a fallback
    assert (expected[lone, 9] == 1).all()
    assert np.abs(np.einsum("ij,ij->i", expected[lone, 3:6], expected[lone, 6:9])).max() < 1e-6
    np.testing.assert_allclose(got[:, 3:9], expected[:, 3:9], atol=2e-5)
    np.testing.assert_array_equal(got[:, 9], expected[:, 9])
