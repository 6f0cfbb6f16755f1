"""Rendering without a screen: a standalone EGL context and an anti-aliased offscreen target."""

from __future__ import annotations

from collections.abc import Mapping

import moderngl
import numpy as np

from studio.core.mesh.camera import OrbitCamera
from studio.core.project.model import Project
from studio.core.setup.face_frame import aim
from studio.render.gl_info import create_standalone_context
from studio.render.renderer import FaceRenderer
from studio.render.scene import ProjectScene
from studio.render.settings import RenderSettings

__all__ = ["OffscreenStudio", "OffscreenTarget", "create_standalone_context", "default_camera"]


class OffscreenTarget:
    """A multisampled colour+depth framebuffer resolved into a readable one."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int, samples: int = 4) -> None:
        self.ctx = ctx
        self.size = (width, height)
        samples = min(samples, ctx.max_samples)
        self.fbo = ctx.framebuffer(
            color_attachments=[ctx.renderbuffer(self.size, 4, samples=samples)],
            depth_attachment=ctx.depth_renderbuffer(self.size, samples=samples))
        self.resolved = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size, 4)])

    def read(self) -> np.ndarray:
        """The rendered image, (H, W, 3) uint8, top row first."""
        self.ctx.copy_framebuffer(self.resolved, self.fbo)
        data = self.resolved.read(components=3, alignment=1)
        w, h = self.size
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()

    def release(self) -> None:
        self.fbo.release()
        self.resolved.release()


def default_camera(project: Project, frame: str = "face") -> OrbitCamera:
    """The project's saved camera, else one looking at the face from its front and framing
    the face (``frame="face"``) or the whole mesh (``"all"``), whatever the head's axes."""
    camera = OrbitCamera.from_dict(project.view.get("camera", {}))
    if "camera" not in project.view:
        aim(camera, project, frame)
    return camera


class OffscreenStudio:
    """Renders a project's frames to images: the command line's and the tests' renderer."""

    def __init__(self, project: Project, width: int, height: int, samples: int = 4,
                 ctx: moderngl.Context | None = None) -> None:
        self._owns_context = ctx is None
        self.ctx = ctx or create_standalone_context()
        self.target = OffscreenTarget(self.ctx, width, height, samples)
        self.renderer = FaceRenderer(self.ctx)
        self.scene = ProjectScene(self.renderer, project)
        self.camera = default_camera(project)

    def render(self, settings: RenderSettings, weights: Mapping[str, float] | None = None
               ) -> np.ndarray:
        if weights is not None:
            self.scene.set_pose_weights(weights)
        self.renderer.render(self.target.fbo, self.camera, settings)
        return self.target.read()

    def release(self) -> None:
        """Free the GPU objects, and the context if this studio made it (a standalone context
        left current would stop Qt's viewport from drawing in the same process)."""
        self.renderer.release()
        self.target.release()
        if self._owns_context:
            self.ctx.release()

    def __enter__(self) -> OffscreenStudio:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.release()
