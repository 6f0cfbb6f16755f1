"""The face renderer: any moderngl context, any framebuffer, no Qt.

It keeps GPU copies of the mesh, textures, masks and wrinkle direction vectors in its passes and
re-uploads only what a ``set_*`` call marked dirty; the per-frame work is the pose's positions,
normals and tangents (one interleaved buffer write) and the draw.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import moderngl
import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import RenderError
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.textures import FaceTextures
from studio.core.wrinkles.wdv import WdvSlots
from studio.render.deform_pass import DeformPass
from studio.render.face_maps import FaceMaps
from studio.render.face_pass import FacePass
from studio.render.gl_info import gl_version, is_software, map_anisotropy
from studio.render.gpu_deform import GpuDeformPass
from studio.render.programs import Programs
from studio.render.relief_pass import ReliefPass
from studio.render.settings import RenderSettings
from studio.render.t1_pass import T1ComposePass

DISPLACE_GL = 400  # tessellation shaders: OpenGL 4.0
DEFORMS = ("auto", "gpu", "cpu")


def deform_choice() -> str:
    """Where the face is deformed: ``WRINKLE_DEFORM`` (auto, gpu or cpu; auto when unset)."""
    choice = os.environ.get("WRINKLE_DEFORM", "auto").strip().lower() or "auto"
    if choice not in DEFORMS:
        raise RenderError(f"WRINKLE_DEFORM={choice}: choose {', '.join(DEFORMS)}")
    return choice


class FaceRenderer:
    """Draws one face with technique none, 1 or 2 (or flat shading, the benchmark's floor).

    A thin composition of passes, each with its own GPU objects and dirty flags: the deform pass
    (pose → normals and tangents → vertex buffer), the face maps and relief heights, technique
    1's compose pass, and the face draw. Overlays and picking are WdvOverlay's
    (render/wdv_overlay.py), drawn by the viewport after the face.
    """

    def __init__(self, ctx: moderngl.Context, deform: str | None = None) -> None:
        """``deform``: ``gpu`` (transform feedback), ``cpu`` (numpy) or ``auto`` (default from
        ``deform_choice``): the GPU, except on a software renderer such as Mesa's llvmpipe,
        which runs vertex shaders on the calling thread, slower than numpy does the same
        work (30,000 vertices, 52 poses: about 21 ms a frame against 14)."""
        self.ctx = ctx
        deform = deform or deform_choice()
        self.deforms_on_gpu = deform == "gpu" or (deform == "auto" and not is_software(ctx))
        self.programs = Programs(ctx)
        self.maps = FaceMaps(ctx, map_anisotropy(str(ctx.info.get("GL_RENDERER", ""))))
        self.relief = ReliefPass(ctx)
        self.t1 = T1ComposePass(ctx, self.programs)
        self.mesh: FaceMesh | None = None
        self.deform: DeformPass | GpuDeformPass | None = None
        self.face: FacePass | None = None
        self.expression_factor = 1.0
        self.scale_free = True
        # plain shading for triangles that cannot wrinkle (the same picture): it pays where
        # every branch of a shader runs on every pixel (llvmpipe: technique 2 1.08 × `none`
        # against 1.17 × whole); on a GPU the extra draw and its lists cost more than they save
        # (H200: technique 2 0.83 ms split, 0.55 ms whole), so there it is off
        self.split_draws = is_software(ctx)
        # triangles nearest first (less overdraw); False: the mesh's order, for small frames
        # drawn while the user moves (vertex reuse on a software renderer; same picture)
        self.nearest_first = True
        self.set_masks(np.zeros((0, 1, 1), np.float32))

    @property
    def can_displace(self) -> bool:
        """Whether relief "displace" can draw here (tessellation shaders, OpenGL 4.0)."""
        return self.ctx.version_code >= DISPLACE_GL

    @property
    def last_deform_ms(self) -> float:
        """CPU time of the last normals + tangents update."""
        return self.deform.last_ms if self.deform is not None else 0.0

    # --- scene data ---------------------------------------------------------------------------
    def set_mesh(self, mesh: FaceMesh, poses: Sequence[KeyPose] = ()) -> None:
        """New topology (or key poses): rebuild every vertex buffer (positions start at the
        neutral pose). Deforming on the GPU, the poses' offsets are uploaded here, once."""
        self._release_geometry()
        self.mesh = mesh
        self.deform = (GpuDeformPass(self.ctx, self.programs, mesh, poses)
                       if self.deforms_on_gpu else DeformPass(self.ctx, mesh))
        self.face = FacePass(self.ctx, self.programs, mesh, self.deform, self.maps, self.t1,
                             self.relief)
        self.face.split.set_area_boxes(self.t1.area_boxes, *self.t1.masks.size[:2])

    def set_positions(self, welded_positions: np.ndarray) -> None:
        """The pose of this frame (welded positions), deforming on the CPU; normals and
        tangents follow at draw."""
        self.deform.set_positions(welded_positions)

    def set_pose_weights(self, weights: np.ndarray) -> None:
        """The pose of this frame as a weight per key pose (in ``set_mesh``'s order),
        deforming on the GPU: the blend, normals and tangents follow at draw."""
        self.deform.set_weights(weights)

    def set_wrinkle_drive(self, positions: np.ndarray | None, drive: np.ndarray | None) -> None:
        """With poses' onsets: this frame's welded positions and the welded positions the
        wrinkles of technique 2 and the automatic mode measure (None, None: the face's own)."""
        self.face.set_wrinkle_drive(positions, drive)

    def set_skin(self, skin: np.ndarray) -> None:
        """(W,) per welded vertex: 1 where wrinkles may show, 0 on not-face vertices."""
        self.face.set_skin(skin)

    def set_textures(self, textures: FaceTextures) -> None:
        """The diffuse and normal maps; the relief heights follow them when a relief draws."""
        self.maps.set_textures(textures)
        self.relief.set_maps(textures.normal_neutral, list(textures.wrinkle_maps.values()))

    def set_masks(self, masks: np.ndarray) -> None:
        """Technique 1 masks, (N, H, W) in [0, 1]; any N (an empty stack becomes one zero layer)."""
        self.t1.set_masks(masks)
        if self.face is not None:
            self.face.split.set_area_boxes(self.t1.area_boxes, *self.t1.masks.size[:2])

    def update_mask_region(self, layer: int, x: int, y: int, patch: np.ndarray) -> None:
        """Upload only a painted rectangle of one mask (image coordinates, top row first)."""
        box = self.t1.update_region(layer, x, y, patch)
        if self.face is not None:
            self.face.split.set_area_box(layer, box)

    def set_activations(self, activations: np.ndarray) -> None:
        """Technique 1's activation vector; nothing is uploaded or recomposed if unchanged."""
        self.t1.set_activations(activations)

    def read_t1_weights(self) -> np.ndarray:
        """Technique 1's composed weight texture as the face shader reads it (see
        ``T1ComposePass.read_weights``): what tests compare with the numpy reference."""
        return self.t1.read_weights()

    def set_area_maps(self, maps: np.ndarray) -> None:
        """Which wrinkled map (index) each technique-1 area reveals, in area order."""
        self.t1.set_area_maps(maps)

    def set_wdv(self, slots: WdvSlots, expression_factor: float = 1.0,
                scale_free: bool = True) -> None:
        """Technique 2 slots per welded vertex (see ``WdvSetup.pack_slots``)."""
        self.face.set_wdv(slots)
        self.expression_factor = float(expression_factor)
        self.scale_free = bool(scale_free)

    # --- drawing ------------------------------------------------------------------------------
    def render(self, fbo: moderngl.Framebuffer, camera: OrbitCamera, settings: RenderSettings,
               viewport: tuple[int, int, int, int] | None = None) -> None:
        """Draw the face into ``fbo`` (within ``viewport``, x y w h in device pixels)."""
        if self.mesh is None:
            raise RuntimeError("FaceRenderer.render called before set_mesh")
        relief = settings.active_relief
        if relief == "displace" and not self.can_displace:
            raise RenderError(f"relief 'displace' needs OpenGL 4.0 (tessellation shaders); "
                              f"this driver offers {gl_version(self.ctx)}; use relief "
                              "'parallax' instead")
        # the passes before the draw, each doing nothing unless its inputs changed
        if relief != "off":
            self.relief.prepare()
        self.deform.upload(settings.tangent_frame)
        ctx = self.ctx
        # set every piece of state the passes rely on: the viewport's overlays may leave any on
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.wireframe = False
        composed = settings.t1_mode == "composed" or relief == "displace"  # tessellation reads it
        if settings.technique == "t1" and composed:
            self.t1.compose()
        if settings.technique == "strain":
            self.face.update_strain(settings.strain_full_at)
        viewport = viewport or (0, 0, *fbo.size)
        fbo.use()
        ctx.viewport = viewport
        ctx.scissor = viewport
        fbo.clear(*settings.background, 1.0, depth=1.0)
        ctx.scissor = None
        ctx.enable(moderngl.DEPTH_TEST)
        view = camera.view_matrix()
        proj = camera.projection_matrix(viewport[2] / max(viewport[3], 1))
        self.maps.bind()
        self.t1.bind()
        self.relief.bind()
        self.face.draw(settings, view, proj, viewport, self.split_draws,
                       {"u_expression": self.expression_factor, "u_scale_free": self.scale_free},
                       self.nearest_first)

    def _release_geometry(self) -> None:
        for part in (self.face, self.deform):
            if part is not None:
                part.release()
        self.face = self.deform = None

    def release(self) -> None:
        self._release_geometry()
        for part in (self.programs, self.maps, self.relief, self.t1):
            part.release()
