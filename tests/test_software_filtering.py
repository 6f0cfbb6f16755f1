"""On a software renderer the face maps are filtered trilinearly, never anisotropically.

Mesa's llvmpipe (and softpipe) filter anisotropically by walking every texel of a pixel's
footprint ellipse, however low the maximum anisotropy; on a sliver triangle that ellipse is
thousands of texels long, and one such pixel of the ICT head made a frame take 3.5 to 6 seconds
(issue #28). ``scripts/frame_sweep.py`` measures the frames; these tests hold the rule that keeps
them even.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.textures import FaceTextures
from studio.render import gl_info
from studio.render.renderer import FaceRenderer

SOFTWARE = ["llvmpipe (LLVM 15.0.6, 256 bits)", "Gallium 0.4 on softpipe",
            "Software Rasterizer", "Microsoft Basic Render Driver",
            "Google SwiftShader", "ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero)))"]
HARDWARE = ["NVIDIA H200/PCIe/SSE2", "AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 16.0.6)",
            "Mesa Intel(R) UHD Graphics 620 (KBL GT2)", "Apple M2"]


@pytest.mark.parametrize("name", SOFTWARE)
def test_a_software_renderer_gets_trilinear_maps(name):
    assert gl_info.is_software_name(name)
    assert gl_info.map_anisotropy(name) == 1.0


@pytest.mark.parametrize("name", HARDWARE)
def test_a_gpu_keeps_anisotropic_maps(name):
    assert not gl_info.is_software_name(name)
    assert gl_info.map_anisotropy(name) == 8.0


def small_textures() -> FaceTextures:
    """A 16 × 16 diffuse map and flat normal maps: enough for the renderer to upload."""
    diffuse = np.full((16, 16, 3), 180, np.uint8)
    flat = np.zeros((16, 16, 3), np.uint8)
    flat[..., :2], flat[..., 2] = 128, 255
    return FaceTextures(diffuse=diffuse, normal_neutral=flat, wrinkle_maps={"w": flat.copy()})


def test_the_renderer_filters_the_maps_as_its_driver_allows(gl_context):
    """The maps the face is drawn with follow the rule for the context's own renderer (the
    tests' context is Mesa's llvmpipe where there is no GPU: trilinear there)."""
    renderer = FaceRenderer(gl_context)
    try:
        renderer.set_textures(small_textures())
        wanted = gl_info.map_anisotropy(gl_context.info["GL_RENDERER"])
        assert wanted == (1.0 if gl_info.is_software(gl_context) else 8.0)
        textures = renderer.maps.textures
        assert textures["diffuse"].anisotropy == wanted
        assert textures["normals"].anisotropy == wanted
        assert textures["more_maps"].anisotropy == 1.0
    finally:
        renderer.release()
