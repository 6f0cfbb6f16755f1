"""The GL side of the viewport's drawing: a moderngl context on the one Qt made current, and the
multisampled framebuffer a frame is drawn into before it is resolved into Qt's.

Why here and not in the widget: neither needs Qt, and both are moderngl objects the widget only
asks for (render has no Qt; the viewport only decides when to draw).
"""

from __future__ import annotations

import moderngl

from studio.core.files.errors import RenderError
from studio.render.gl_info import gl_version


def attach_to_current_context() -> moderngl.Context:
    """A fresh moderngl context on the one Qt made current, whether Qt uses EGL or GLX.

    (``moderngl.create_context`` detects through GLX only once a default context exists, which
    fails for a second viewport when Qt runs on EGL; ``init_context`` always re-detects.)
    """
    try:
        moderngl.init_context()
        ctx = moderngl.get_context()
    except Exception as exc:  # the GL loaders raise plain Exception
        raise RenderError(f"OpenGL is not available, so the viewport cannot draw ({exc}). "
                          "Update the graphics driver (or install Mesa).") from None
    if ctx.version_code < 330:
        raise RenderError(f"the viewport needs OpenGL 3.3; this driver offers {gl_version(ctx)}")
    return ctx


class MsaaTarget:
    """A multisampled framebuffer, made again only when the size or the sample count changes."""

    def __init__(self) -> None:
        self.fbo: moderngl.Framebuffer | None = None
        self._key: tuple[int, int, int] | None = None

    def framebuffer(self, ctx: moderngl.Context, size: tuple[int, int], samples: int
                    ) -> moderngl.Framebuffer | None:
        """The framebuffer to draw ``size`` at ``samples`` per pixel (None under 2: draw
        straight into the window's)."""
        if samples < 2:
            return None
        key = (*size, samples)
        if self._key != key:
            self.release()
            colour = ctx.renderbuffer(size, 4, samples=samples)
            depth = ctx.depth_renderbuffer(size, samples=samples)
            self.fbo, self._key = ctx.framebuffer([colour], depth), key
        return self.fbo

    def release(self) -> None:
        if self.fbo is not None:
            for attachment in (*self.fbo.color_attachments, self.fbo.depth_attachment):
                attachment.release()
            self.fbo.release()
        self.fbo, self._key = None, None
