"""The face renderer: any moderngl context, any framebuffer, no Qt.

It keeps GPU copies of the mesh, textures, masks and wrinkle direction vectors and re-uploads only
what a ``set_*`` call marked dirty; the per-frame work is the pose's positions, normals and
tangents (one interleaved buffer write) and the draw.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from studio.core.camera import OrbitCamera
from studio.core.geometry import DeformCache
from studio.core.mesh import FaceMesh
from studio.core.textures import FaceTextures
from studio.core.wdv import SLOTS
from studio.render.shaders import build_program

TECHNIQUES = ("flat", "none", "t1", "t2")
VIEW_MODES = {"shaded": 0, "heat": 1, "normals": 2, "uv": 3}

_UNIT = {"diffuse": 0, "normal_neutral": 1, "normal_wrinkled": 2, "masks": 3, "activations": 4}


@dataclass
class RenderSettings:
    technique: str = "t2"  # flat | none | t1 | t2
    view: str = "shaded"  # shaded | heat | normals | uv
    wireframe: bool = False
    light_dir: tuple[float, float, float] = (0.45, 0.5, 0.75)  # view space, toward the light
    ambient: float = 0.1
    specular: float = 0.12
    shininess: float = 20.0
    background: tuple[float, float, float] = (0.16, 0.17, 0.19)

    def __post_init__(self) -> None:
        if self.technique not in TECHNIQUES:
            raise ValueError(f"unknown technique '{self.technique}' (choose from {TECHNIQUES})")
        if self.view not in VIEW_MODES:
            raise ValueError(f"unknown view '{self.view}' (choose from {tuple(VIEW_MODES)})")


def _texture_dtype(image: np.ndarray) -> str:
    return "nu2" if image.dtype == np.uint16 else "f1"


class FaceRenderer:
    """Draws one face with technique none, 1 or 2 (or flat shading, the benchmark's floor)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.mesh: FaceMesh | None = None
        self._programs: dict[str, moderngl.Program] = {}
        self._vaos: dict[str, moderngl.VertexArray] = {}
        self._textures: dict[str, moderngl.Texture] = {}
        self._masks: moderngl.TextureArray | None = None
        self._activations: moderngl.Texture | None = None
        self._buffers: list[moderngl.Buffer] = []
        self._positions: np.ndarray | None = None
        self._geometry_dirty = False
        self.expression_factor = 1.0
        self.scale_free = True
        self.set_masks(np.zeros((0, 1, 1), np.float32))

    # --- scene data ---------------------------------------------------------------------------
    def set_mesh(self, mesh: FaceMesh) -> None:
        """New topology: rebuild every vertex buffer (positions start at the neutral pose)."""
        self._release_geometry()
        self.mesh = mesh
        self._deform = DeformCache(mesh)
        v = mesh.n_vertices
        self._ibo = self.ctx.buffer(mesh.triangles.astype("i4").tobytes())
        self._dynamic = self.ctx.buffer(reserve=v * 10 * 4, dynamic=True)
        static = np.hstack([mesh.uvs, mesh.rest[mesh.weld]]).astype("f4")
        self._static = self.ctx.buffer(static.tobytes())
        self._wdv = self.ctx.buffer(np.zeros((v, 4 * SLOTS + SLOTS), "f4").tobytes())
        self._buffers = [self._ibo, self._dynamic, self._static, self._wdv]
        self._positions = mesh.rest.copy()
        self._geometry_dirty = True

    def set_positions(self, welded_positions: np.ndarray) -> None:
        """The pose of this frame (welded positions); normals and tangents follow at draw."""
        np.copyto(self._positions, welded_positions)
        self._geometry_dirty = True

    def set_textures(self, textures: FaceTextures) -> None:
        for name in ("diffuse", "normal_neutral", "normal_wrinkled"):
            image = getattr(textures, name)
            old = self._textures.pop(name, None)
            if old is not None:
                old.release()
            h, w = image.shape[:2]
            tex = self.ctx.texture((w, h), 3, image.tobytes(), dtype=_texture_dtype(image))
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            tex.anisotropy = 8.0
            tex.repeat_x = tex.repeat_y = False
            self._textures[name] = tex

    def set_masks(self, masks: np.ndarray) -> None:
        """Technique 1 masks, (N, H, W) in [0, 1]; any N (an empty stack becomes one zero layer)."""
        masks = np.asarray(masks, np.float32)
        if len(masks) == 0:
            masks = np.zeros((1, 1, 1), np.float32)
        n, h, w = masks.shape
        data = np.round(np.clip(masks, 0.0, 1.0) * 255.0).astype(np.uint8)
        if self._masks is not None and self._masks.size == (w, h, n):
            self._masks.write(data.tobytes())
        else:
            if self._masks is not None:
                self._masks.release()
            self._masks = self.ctx.texture_array((w, h, n), 1, data.tobytes(), dtype="f1")
            self._masks.repeat_x = self._masks.repeat_y = False
            self._masks.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._area_count = n
        self.set_activations(np.zeros(n, np.float32))

    def update_mask_region(self, layer: int, x: int, y: int, patch: np.ndarray) -> None:
        """Upload only a painted rectangle of one mask (image coordinates, top row first)."""
        data = np.round(np.clip(patch, 0.0, 1.0) * 255.0).astype(np.uint8)
        h, w = data.shape
        self._masks.write(data.tobytes(), viewport=(x, y, layer, w, h, 1))

    def set_activations(self, activations: np.ndarray) -> None:
        values = np.zeros(max(self._area_count, 1), np.float32)
        values[: len(activations)] = activations
        if self._activations is None or self._activations.width != len(values):
            if self._activations is not None:
                self._activations.release()
            self._activations = self.ctx.texture((len(values), 1), 1, dtype="f4")
            self._activations.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._activations.write(values.tobytes())

    def set_wdv(self, dirs: np.ndarray, cones: np.ndarray, expression_factor: float = 1.0,
                scale_free: bool = True) -> None:
        """Technique 2 slots per welded vertex (see ``WdvSetup.pack_slots``)."""
        weld = self.mesh.weld
        packed = np.hstack([dirs.reshape(len(dirs), -1)[weld], cones[weld]]).astype("f4")
        self._wdv.write(packed.tobytes())
        self.expression_factor = float(expression_factor)
        self.scale_free = bool(scale_free)

    # --- drawing ------------------------------------------------------------------------------
    def render(self, fbo: moderngl.Framebuffer, camera: OrbitCamera, settings: RenderSettings,
               viewport: tuple[int, int, int, int] | None = None) -> None:
        """Draw the face into ``fbo`` (within ``viewport``, x y w h in device pixels)."""
        if self.mesh is None:
            raise RuntimeError("FaceRenderer.render called before set_mesh")
        if self._geometry_dirty:
            self._dynamic.write(self._deform.update(self._positions))
            self._geometry_dirty = False
        ctx = self.ctx
        viewport = viewport or (0, 0, *fbo.size)
        fbo.use()
        ctx.viewport = viewport
        ctx.scissor = viewport
        fbo.clear(*settings.background, 1.0, depth=1.0)
        ctx.scissor = None
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE)
        view = camera.view_matrix()
        proj = camera.projection_matrix(viewport[2] / max(viewport[3], 1))
        prog = self._program(settings.technique)
        self._set_uniforms(prog, view, proj, settings)
        self._bind_textures()
        self._vao(settings.technique).render(moderngl.TRIANGLES)
        if settings.wireframe:
            self._draw_wireframe(view, proj)

    def _draw_wireframe(self, view: np.ndarray, proj: np.ndarray) -> None:
        prog = self._program("wire")
        self._write_matrix(prog, "u_view", view)
        self._write_matrix(prog, "u_proj", proj)
        prog["u_colour"].value = (0.05, 0.05, 0.05, 0.55)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.wireframe = True
        self.ctx.polygon_offset = (-1.0, -1.0)
        self._vao("wire").render(moderngl.TRIANGLES)
        self.ctx.polygon_offset = (0.0, 0.0)
        self.ctx.wireframe = False
        self.ctx.disable(moderngl.BLEND)

    def _program(self, kind: str) -> moderngl.Program:
        if kind not in self._programs:
            if kind == "wire":
                self._programs[kind] = build_program(self.ctx, "wire.vert", "wire.frag")
            else:
                self._programs[kind] = build_program(
                    self.ctx, "face.vert", "face.frag", [f"TECHNIQUE_{kind.upper()}"])
        return self._programs[kind]

    def _vao(self, kind: str) -> moderngl.VertexArray:
        if kind not in self._vaos:
            content = [
                (self._dynamic, "3f 3f 4f", "in_position", "in_normal", "in_tangent"),
                (self._static, "2f 3f", "in_uv", "in_rest"),
                (self._wdv, "16f 4f", "in_wdv", "in_cone"),
            ]
            self._vaos[kind] = self.ctx.vertex_array(
                self._program(kind), content, self._ibo, index_element_size=4, skip_errors=True)
        return self._vaos[kind]

    @staticmethod
    def _write_matrix(prog: moderngl.Program, name: str, matrix: np.ndarray) -> None:
        prog[name].write(matrix.T.astype("f4").tobytes())

    def _set_uniforms(self, prog: moderngl.Program, view: np.ndarray, proj: np.ndarray,
                      settings: RenderSettings) -> None:
        self._write_matrix(prog, "u_view", view)
        self._write_matrix(prog, "u_proj", proj)
        light = np.asarray(settings.light_dir, float)
        values = {
            "u_light_dir": tuple(light / np.linalg.norm(light)),
            "u_ambient": settings.ambient,
            "u_specular": settings.specular,
            "u_shininess": settings.shininess,
            "u_view_mode": VIEW_MODES[settings.view],
            "u_expression": self.expression_factor,
            "u_scale_free": self.scale_free,
        }
        values.update({f"u_{name}": unit for name, unit in _UNIT.items()})
        for name, value in values.items():
            if name in prog:
                prog[name].value = value

    def _bind_textures(self) -> None:
        for name, tex in self._textures.items():
            tex.use(_UNIT[name])
        self._masks.use(_UNIT["masks"])
        self._activations.use(_UNIT["activations"])

    def _release_geometry(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        for buf in self._buffers:
            buf.release()
        self._buffers = []

    def release(self) -> None:
        self._release_geometry()
        for prog in self._programs.values():
            prog.release()
        for tex in [*self._textures.values(), self._masks, self._activations]:
            if tex is not None:
                tex.release()
