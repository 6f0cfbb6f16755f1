"""The renderer reads the normal maps in the tangent frame its settings name (standalone EGL)."""

from __future__ import annotations

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.project.view_settings import ViewSettings
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings, render_settings


def curved_mirrored_sheet(n: int = 16) -> Project:
    """A bent, unevenly spaced sheet facing +Z whose right half has mirrored UVs (u = 1 − x),
    the seam column shared by both halves; its normal map tilts every normal along u and v.
    There the two frames differ: the thesis's sums both halves' opposite tangents at the seam
    and weights triangles by area, MikkTSpace takes one side and weights by angle."""
    x, y = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1))
    idx = np.arange(x.size).reshape(x.shape)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    xs = np.sign(x) * np.abs(x) ** 1.5
    rest = np.stack([xs, y + 0.15 * np.sin(3 * x), -0.4 * xs ** 2 - 0.2 * y ** 2], -1)
    u = 0.5 - 0.5 * np.abs(x)  # mirrored about x = 0
    uvs = np.stack([u, 0.5 + 0.5 * y], -1).reshape(-1, 2)
    neutral = flat_normal_map(8)
    neutral[...] = (200, 170, 200)  # tilted toward +u and +v
    return Project("sheet", FaceMesh(rest.reshape(-1, 3), tris, uvs, np.arange(x.size)), [],
                   FaceTextures(np.full((8, 8, 3), 200, np.uint8), neutral, flat_normal_map()))


def test_a_render_differs_between_the_frames_and_follows_the_settings(gl_context):
    size = 96
    with OffscreenStudio(curved_mirrored_sheet(), size, size, ctx=gl_context) as studio:
        studio.camera.yaw = studio.camera.pitch = 0.0
        studio.camera.frame(np.array([-1.1, -1.1, -0.6]), np.array([1.1, 1.1, 0.0]))

        def draw(**changes) -> np.ndarray:
            return studio.render(RenderSettings(technique="none", **changes), {}).astype(int)

        thesis, mikk, default = draw(tangent_frame="thesis"), draw(tangent_frame="mikktspace"), \
            draw()
        again = draw(tangent_frame="thesis")
    assert np.abs(thesis - mikk).max() > 20  # the frames shade the sheet visibly apart
    np.testing.assert_array_equal(default, mikk)  # MikkTSpace is the default
    np.testing.assert_array_equal(again, thesis)  # switching back rebuilds the tangents


def test_the_view_model_s_frame_reaches_the_renderer_s_settings():
    assert ViewSettings().tangent_frame == "mikktspace"
    for frame in ("thesis", "mikktspace"):
        assert render_settings(ViewSettings(tangent_frame=frame)).tangent_frame == frame
    assert ViewSettings.from_dict({"tangent_frame": "bogus"}).tangent_frame == "mikktspace"
