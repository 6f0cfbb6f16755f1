"""The tessellation stage (shaders/face.tesc, face.tese, relief.glsl) against its formula, on
depth: relief "displace" moves the surface along its normal by
``depth · Σ_m w_m h_m / max(Σ_m w_m, 1)`` — the wrinkle weights of several maps scaled to sum
at most 1, as the fragment stage shades with them, times each map's wrinkle height.

The face is tests/hand_faces.py's flat grid seen straight on, so the surface's distance from
the camera under every pixel is known. Each map's height is made constant here (the height
texture is replaced), and technique 1's masks are constant per map: every pixel of the skin
should then sit at one known depth, whatever the tessellation level and the filtering, and
the not-face columns (skin 0) stay on the plane.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.mask_sparse import quantise
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.hand_faces import grid_face

PIXELS = 64
TEXELS = 16
MAPS = ("brow", "smile", "squint", "chin")  # the shader's four
HEIGHTS = (-0.75, -0.5, 0.625, -0.25)  # per map; exact in float16
DEPTH = 0.25  # model units; the grid is 2 across


def heights_of(*_maps) -> np.ndarray:
    """The relief texture: each map's height, the same everywhere."""
    return np.broadcast_to(np.float16(HEIGHTS), (TEXELS, TEXELS, 4)).copy()


def grid_with_masks(masks: tuple[float, ...]):
    """The grid with one technique-1 area per map, its mask ``masks[m]`` everywhere; the
    vertex columns at x = −1 and −0.75 are not face."""
    flat = np.zeros((TEXELS, TEXELS, 3), np.uint8) + np.uint8([128, 128, 255])
    project = grid_face(dict.fromkeys(MAPS, flat), cells=8)
    project.influence.areas = [
        InfluenceArea(f"area {m}", np.full((TEXELS, TEXELS), value, np.float32),
                      activation=1.0, wrinkle_map=MAPS[m])
        for m, value in enumerate(masks)]
    project.not_face = project.mesh.rest[:, 0] < -0.6
    return project


def expected_lift(masks: tuple[float, ...]) -> float:
    """How far the skin moves toward the camera: the formula, with the masks quantised to
    8 bits and the weights to float16 as the renderer stores them."""
    w = np.zeros(4)
    w[:len(masks)] = quantise(np.float32(masks)).astype(np.float64) / 255.0
    return lift_of(np.clip(w, 0.0, 1.0).astype(np.float16).astype(np.float64))


def lift_of(w: np.ndarray) -> float:
    """depth · Σ w_m h_m / max(Σ w_m, 1): the formula."""
    total = w.sum()
    return DEPTH * float(w @ np.float64(HEIGHTS)) / max(total, 1.0) if total > 0 else 0.0


def view_distance(studio: OffscreenStudio) -> np.ndarray:
    """(H, W) each pixel's distance along the view axis, from the depth buffer (top row
    first); NaN where nothing was drawn."""
    w, h = studio.target.size
    raw = studio.target.fbo.read(components=1, attachment=-1, dtype="f4", alignment=1)
    depth = np.frombuffer(raw, np.float32).reshape(h, w)[::-1]
    proj = studio.camera.projection_matrix(w / h)
    ndc = depth * 2.0 - 1.0
    distance = proj[2, 3] / (ndc + proj[2, 2])  # −z_view from z_ndc = (A z + B) / −z
    return np.where(depth < 1.0, distance, np.nan)


@pytest.fixture
def constant_heights(monkeypatch):
    monkeypatch.setattr("studio.render.relief_pass.relief_image", heights_of)


def lifted(before: np.ndarray, after: np.ndarray, want: float) -> None:
    """The skin (clear of the not-face edge and the grid's rim) moved toward the camera by
    ``want``; the not-face columns (skin 0) did not move, and are still drawn."""
    columns = (np.arange(PIXELS) + 0.5) / PIXELS * 2.0 - 1.0  # about x under each column
    skin = np.isfinite(before) & (columns > -0.4)[None, :]
    skin[:, -3:] = skin[:3] = skin[-3:] = False
    not_face = np.isfinite(before) & (columns < -0.8)[None, :]
    assert skin.sum() > 1000 and not_face.sum() > 100
    lift = before - after
    assert abs(want) > 0.02  # each case moves the skin
    np.testing.assert_allclose(lift[skin], want, atol=2e-3)
    np.testing.assert_allclose(lift[not_face], 0.0, atol=2e-3)


@pytest.mark.parametrize("masks", [(0.7, 0.6, 0.3, 0.2), (0.3, 0.25, 0.2, 0.1),
                                   (0.0, 0.0, 0.9, 0.0), (0.0, 0.8, 0.0, 0.0),
                                   (0.0, 0.0, 0.0, 0.6)])
def test_the_skin_moves_by_the_weighted_heights_and_the_rest_stays(gl_context, constant_heights,
                                                                     masks):
    """Four maps whose weights sum past 1 (scaled back), below 1 (kept), one map alone a
    raise, others alone a valley."""
    project = grid_with_masks(masks)
    with OffscreenStudio(project, PIXELS, PIXELS, samples=0, ctx=gl_context) as studio:
        plain = RenderSettings(technique="t1")
        studio.render(plain)
        before = view_distance(studio)
        studio.render(RenderSettings(technique="t1", relief="displace", relief_depth=DEPTH))
        after = view_distance(studio)
    lifted(before, after, expected_lift(masks))


@pytest.mark.parametrize("maps", [(0,), (1, 3), (0, 1, 2)])
def test_technique_2_s_vertex_weights_move_the_skin_the_same_way(gl_context, constant_heights,
                                                                   maps):
    """A pose lifts the grid by ``s`` along +z; one technique-2 area per map in ``maps``
    points along that motion with authored length ``s``: each weight is 1 at full pose, so
    the skin moves by the mean of those maps' heights (their sum scaled back to 1)."""
    from studio.core.animation.poses import KeyPose
    from studio.core.wrinkles.wdv import WdvArea

    project = grid_with_masks(())
    rest = project.mesh.rest
    lift = np.float32(0.05)
    project.poses = [KeyPose("lift", rest + np.float32([0.0, 0.0, lift]))]
    up = np.tile(np.float32([0.0, 0.0, 1.0]), (len(rest), 1))
    project.wdv.areas = [WdvArea(f"area {m}", "lift", up, np.full(len(rest), lift, np.float32),
                                 wrinkle_map=MAPS[m]) for m in maps]
    weights = np.zeros(4)
    weights[list(maps)] = 1.0
    with OffscreenStudio(project, PIXELS, PIXELS, samples=0, ctx=gl_context) as studio:
        studio.render(RenderSettings(technique="t2"), {"lift": 1.0})
        before = view_distance(studio)
        studio.render(RenderSettings(technique="t2", relief="displace", relief_depth=DEPTH))
        after = view_distance(studio)
    lifted(before, after, lift_of(weights))
