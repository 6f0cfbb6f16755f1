"""Whole-mask operations and the auto mask, hand-checked."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles import mask_ops

pytestmark = pytest.mark.core


def test_fill_invert_levels():
    m = np.array([[0.0, 0.25], [0.5, 1.0]], np.float32)
    assert mask_ops.fill(m, 0.3).tolist() == [[pytest.approx(0.3)] * 2] * 2
    assert mask_ops.invert(m).tolist() == [[1.0, 0.75], [0.5, 0.0]]
    lv = mask_ops.levels(m, black=0.25, white=0.75)
    assert lv.tolist() == [[0.0, 0.0], [0.5, 1.0]]
    g = mask_ops.levels(m, gamma=2.0)
    assert g[1, 0] == pytest.approx(0.5 ** 0.5)


def test_blur_keeps_mass_and_softens_an_edge():
    m = np.zeros((64, 64), np.float32)
    m[24:40, 24:40] = 1.0
    b = mask_ops.blur(m, 4.0)
    assert b.sum() == pytest.approx(m.sum(), rel=1e-3)
    assert 0.0 < b[32, 24] < 1.0 and b[32, 32] == pytest.approx(1.0)
    assert b[0, 0] == 0.0


def test_resample_sizes_and_values():
    m = np.zeros((512, 512), np.float32)
    m[:, 256:] = 1.0
    up = mask_ops.resample(m, 1024)
    down = mask_ops.resample(m, (128, 64))
    assert up.shape == (1024, 1024) and down.shape == (64, 128)
    assert up[10, 1000] == 1.0 and up[10, 10] == 0.0
    assert down[5, 100] == 1.0 and down[5, 10] == 0.0


def test_mirror_u():
    m = np.zeros((4, 6), np.float32)
    m[1, 0] = 1.0
    out = mask_ops.mirror_u(m, "left")
    assert out[1, 5] == 1.0 and out[1, 0] == 1.0
    out = mask_ops.mirror_u(m, "right")
    assert out[1, 0] == 0.0


def test_overlap_finds_sums_over_one_and_gaps():
    masks = np.zeros((2, 4, 4), np.float32)
    masks[0, :, :3] = 0.8
    masks[1, :, 1:3] = 0.5
    over, none = mask_ops.overlap(masks, np.array([1.0, 1.0]))
    assert over[:, 1:3].all() and not over[:, 0].any() and not over[:, 3].any()
    assert none[:, 3].all() and not none[:, :3].any()
    over, _ = mask_ops.overlap(masks, np.array([1.0, 0.2]))
    assert not over.any()


def test_rasterise_one_triangle_interpolates_and_covers_half_the_square():
    uvs = np.array([[0, 0], [1, 0], [0, 1]], np.float32)  # lower-left half in UV
    img, cov = mask_ops.rasterise_uv(uvs, np.array([[0, 1, 2]]), np.array([0.0, 1.0, 0.0]), 16)
    assert cov.sum() == pytest.approx(16 * 17 / 2, abs=16)
    assert cov[15, 0] and not cov[0, 15]  # row 15 is v≈0
    assert img[15, 14] == pytest.approx(14.5 / 16, abs=0.05)  # value follows u


def _strip_mesh():
    # a 5×5 grid of vertices on z = 0, UVs equal to x, y in [0, 1]
    xs, ys = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    rest = np.c_[xs.ravel(), ys.ravel(), np.zeros(25)].astype(np.float32)
    tris = []
    for j in range(4):
        for i in range(4):
            a = j * 5 + i
            tris += [[a, a + 1, a + 6], [a, a + 6, a + 5]]
    return FaceMesh(rest, np.array(tris), rest[:, :2].copy(), np.arange(25))


def test_vertex_compression_is_relative_edge_shortening():
    mesh = _strip_mesh()
    posed = mesh.rest.copy()
    posed[:, 0] *= 0.5  # every x-edge halves: compression 0.5 on them
    comp = mask_ops.vertex_compression(mesh.rest, posed, mesh.welded_triangles)
    assert (comp > 0.1).all() and comp.max() <= 0.5 + 1e-6
    stretch = mesh.rest.copy()
    stretch[:, 0] *= 2.0
    assert mask_ops.vertex_compression(mesh.rest, stretch, mesh.welded_triangles).max() == 0.0


def test_auto_mask_is_nonzero_where_the_pose_compresses_and_zero_elsewhere():
    mesh = _strip_mesh()
    posed = mesh.rest.copy()
    right = mesh.rest[:, 0] >= 0.74  # squeeze the right column of quads toward x = 0.75
    posed[right, 0] = 0.75 + (posed[right, 0] - 0.75) * 0.3
    mask = mask_ops.auto_mask(mesh, posed, 64, softness=2.0)
    assert mask.shape == (64, 64)
    assert mask[:, 56:].mean() > 0.5  # u ≈ 0.9: compressed
    assert mask[:, :28].max() == 0.0  # u < 0.44: no compressed vertex nearby (blur leaks ~2 px)
    assert mask.max() <= 1.0


def test_auto_mask_on_the_sample_squeeze_lands_near_the_eyes():
    from studio.core.sample.synthetic import landmark_uvs, make_test_face

    project = make_test_face()
    mask = mask_ops.auto_mask(project.mesh, project.pose("squeeze").positions, 256)
    uv = landmark_uvs()
    def at(name):
        u, v = uv[name]
        return mask[int((1 - v) * 256), int(u * 256)]
    assert max(at("eye corner left"), at("eye corner right"), at("under eye left")) > 0.05
    assert at("chin") == 0.0 and at("forehead") == 0.0
