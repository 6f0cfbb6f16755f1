"""More areas or larger maps than the GPU holds: a clear RenderError; the old data still draws."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import RenderError, StudioError
from studio.render.renderer import FaceRenderer


@pytest.fixture
def renderer(gl_context):
    r = FaceRenderer(gl_context)
    yield r
    r.release()


def test_more_areas_than_the_gpu_holds(renderer, gl_context):
    limit = int(gl_context.info["GL_MAX_ARRAY_TEXTURE_LAYERS"])
    renderer.set_masks(np.zeros((2, 8, 8), np.float32))
    with pytest.raises(RenderError, match=f"at most {limit} masks"):
        renderer.set_masks(np.zeros((limit + 1, 1, 1), np.float32))
    assert renderer.t1.area_count == 2 and renderer.t1.masks.size == (8, 8, 2)


def test_masks_larger_than_the_gpu_holds(renderer, gl_context):
    limit = int(gl_context.info["GL_MAX_TEXTURE_SIZE"])
    with pytest.raises(RenderError, match="largest texture") as caught:
        renderer.set_masks(np.zeros((1, 1, limit + 1), np.float32))
    assert isinstance(caught.value, StudioError)  # the GUI shows it in a dialog


def test_textures_larger_than_the_gpu_holds(renderer, gl_context, monkeypatch):
    from studio.core.sample.synthetic import make_test_face

    textures = make_test_face(561, texture_size=64, mask_size=32).textures
    renderer.set_textures(textures)
    before = dict(renderer.maps.textures)
    info = {**gl_context.info, "GL_MAX_TEXTURE_SIZE": 32}
    monkeypatch.setattr(type(gl_context), "info", property(lambda self: info))
    with pytest.raises(RenderError, match="diffuse map is 64×64 pixels"):
        renderer.set_textures(textures)
    assert renderer.maps.textures == before  # untouched: the face still draws


def test_a_driver_failure_becomes_a_render_error(renderer, gl_context, monkeypatch):
    import moderngl

    def fail(*args, **kwargs):
        raise moderngl.Error("out of memory")

    monkeypatch.setattr(type(gl_context), "texture_array", fail)
    with pytest.raises(RenderError, match="cannot hold 3 influence masks of 16×8 pixels"):
        renderer.set_masks(np.zeros((3, 8, 16), np.float32))
