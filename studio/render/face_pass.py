"""The face draw: the per-vertex inputs of the face program (UVs, rest positions, skin, wrinkle
direction vectors, strain) and the draw itself, split into the triangles that can show wrinkles
this frame (the technique's program) and the rest (the technique-off program, the same picture
there at a fraction of the cost), plus the wireframe overlay.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.skin_light import light_rig
from studio.core.wrinkles.wdv import SLOTS, WdvSlots
from studio.render import deform_pass
from studio.render.programs import UNITS, Programs, set_uniforms, write_matrix
from studio.render.settings import VIEW_MODES
from studio.render.triangle_split import TriangleSplit
from studio.render.wrinkle_drive import WrinkleDrive

if TYPE_CHECKING:
    from studio.render.deform_pass import DeformPass
    from studio.render.face_maps import FaceMaps
    from studio.render.gpu_deform import GpuDeformPass
    from studio.render.relief_pass import ReliefPass
    from studio.render.settings import RenderSettings
    from studio.render.t1_pass import T1ComposePass

TESS_PIXELS = 3.0  # displace: wanted screen length of one segment of a wrinkled edge
TESS_MAX = 32.0  # displace: most segments per edge
Viewport = tuple[int, int, int, int]


def uv_per_unit(mesh: FaceMesh) -> float:
    """Texcoord units per model unit over the neutral surface (the root of the UV area over the
    surface area): how far a parallax offset of one model unit moves in the maps."""
    corners = mesh.rest[mesh.weld][mesh.triangles]
    uv = mesh.uvs[mesh.triangles]
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                          axis=1).sum()
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()
    return float(np.sqrt(uv_area / area)) if area > 0 and uv_area > 0 else 1.0


class FacePass:
    """Buffers of one mesh; reads the deform pass's vertices, the maps, technique 1's weights
    and the relief heights that the renderer prepared before it draws."""

    def __init__(self, ctx: moderngl.Context, programs: Programs, mesh: FaceMesh,
                 deform: DeformPass | GpuDeformPass, maps: FaceMaps, t1: T1ComposePass,
                 relief: ReliefPass) -> None:
        self.ctx, self.programs, self.mesh = ctx, programs, mesh
        self.deform, self.maps, self.t1, self.relief = deform, maps, t1, relief
        v = mesh.n_vertices
        self.ibo = ctx.buffer(mesh.triangles.astype("i4").tobytes())
        self._static = ctx.buffer(np.hstack([mesh.uvs, mesh.rest[mesh.weld]]).astype("f4")
                                  .tobytes())
        self._wdv = ctx.buffer(np.zeros((v, 4 * SLOTS + 2 * SLOTS), "f4").tobytes())
        self._skin = ctx.buffer(np.ones(v, "f4").tobytes())
        self._strain = ctx.buffer(reserve=v * 4, dynamic=True)
        self.drive = WrinkleDrive(mesh)  # what t2 and strain measure when poses have onsets
        self._strain_key: tuple[int, float, int] | None = None  # (pose, full_at, drive)
        self._strain_split: tuple[object, np.ndarray] = (None, np.zeros(v, np.float32))
        self.split = TriangleSplit(self.ibo, mesh.triangles, mesh.uvs, mesh.rest[mesh.weld])
        self._vaos: dict[tuple[str, ...], moderngl.VertexArray] = {}
        self._uniforms: dict[str, object] = {}
        self._nearest_first = True
        self.uv_per_unit = uv_per_unit(mesh)

    # --- inputs ---------------------------------------------------------------------------
    def set_skin(self, skin: np.ndarray) -> None:
        """(W,) per welded vertex: 1 where wrinkles may show, 0 on not-face vertices."""
        render_skin = np.asarray(skin, "f4")[self.mesh.weld]
        self._skin.write(render_skin.tobytes())
        self.split.set_skin(render_skin)

    def set_wdv(self, slots: WdvSlots) -> None:
        """Technique 2 slots per welded vertex (see ``WdvSetup.pack_slots``)."""
        weld = self.mesh.weld
        packed = np.hstack([slots.dirs.reshape(len(slots.dirs), -1)[weld],
                            slots.cones[weld], slots.maps[weld]]).astype("f4")
        self._wdv.write(packed.tobytes())
        in_use = (slots.dirs[..., 3] > 0) & (slots.cones > 0)
        self.split.set_slots(in_use.any(axis=1)[weld])

    def set_wrinkle_drive(self, positions: np.ndarray | None, drive: np.ndarray | None) -> None:
        """What technique 2 and the automatic mode measure (see ``WrinkleDrive``): this
        frame's welded positions and the drive, or None for both to measure the face."""
        if drive is None and not self.drive.active:
            return
        rest = self.drive.set(positions, drive)
        self._static.write(np.hstack([self.mesh.uvs.astype("f4"), rest]).tobytes())

    def update_strain(self, full_at: float) -> None:
        """Compression weights for this frame's pose (only when the pose, gain or drive
        changed)."""
        key = (self.deform.version, full_at, self.drive.version)
        if key != self._strain_key:
            if self.drive.active:
                weights = self.drive.strain(full_at)
                self._strain.write(weights.tobytes())
                self._strain_split = (key, weights)
            else:
                self._strain_split = self.deform.write_strain(self._strain, full_at)
            self._strain_key = key

    # --- drawing --------------------------------------------------------------------------
    def draw(self, settings: RenderSettings, view: np.ndarray, proj: np.ndarray,
             viewport: Viewport, split_draws: bool, uniforms: dict[str, object],
             nearest_first: bool = True) -> None:
        """Draw into the bound framebuffer; ``uniforms`` are the renderer's own (technique 2's
        expression factor, say), set on every face program with the settings'.
        ``nearest_first``: triangles in depth order (see ``TriangleSplit.order``)."""
        self._uniforms = uniforms
        self._nearest_first = nearest_first
        self.split.set_view(view, nearest_first)
        if settings.active_relief == "displace":  # one program: tessellated and flat edges
            self.split.order(None, nearest_first)  # would not meet
            self.ctx.patch_vertices = 3
            self._vao(self._program(settings, view, proj, viewport)).render(moderngl.PATCHES)
        else:
            self._draw_split(settings, view, proj, viewport, split_draws)
        if settings.wireframe:
            self._draw_wireframe(view, proj)

    def _draw_split(self, settings: RenderSettings, view: np.ndarray, proj: np.ndarray,
                    viewport: Viewport, split_draws: bool) -> None:
        count = self.split.order(self.wrinkled_triangles(settings) if split_draws else None,
                                 self._nearest_first)
        total = len(self.mesh.triangles)
        if count:
            key = self._program(settings, view, proj, viewport)
            self._vao(key).render(moderngl.TRIANGLES, vertices=3 * count)
        if count < total:
            key = self._program(replace(settings, technique="none"), view, proj, viewport)
            self._vao(key).render(moderngl.TRIANGLES, vertices=3 * (total - count),
                                  first=3 * count)

    def wrinkled_triangles(self, settings: RenderSettings) -> np.ndarray | None:
        """(T,) the triangles whose wrinkle weight can be above 0 this frame (None: all)."""
        technique = settings.technique
        if technique == "t1":
            return self.split.for_areas(self.t1.activation_values)
        if technique == "t2":
            return self.split.for_slots(self.deform.motion_key,
                                        lambda: self.deform.moved_welded()[self.mesh.weld])
        if technique == "strain":
            key, weights = self._strain_split
            return self.split.for_weights(key, lambda: weights)
        return None

    def _program(self, settings: RenderSettings, view: np.ndarray, proj: np.ndarray,
                 viewport: Viewport) -> tuple[str, ...]:
        """The face program for ``settings``, its uniforms set; returns its key."""
        key = (*settings.program_key(), f"WRINKLE_MAPS {self.maps.map_count}")
        if self.maps.has_tone and settings.look == "skin":  # clay shows the normals alone
            key = (*key, "SKIN_TONE")
        prog = self.programs.get(key)
        write_matrix(prog, "u_view", view)
        write_matrix(prog, "u_proj", proj)
        light = np.asarray(settings.light_dir, float)
        rig = light_rig(settings.light_rig, settings.light_dir)
        set_uniforms(prog, {
            "u_light_dir": tuple(light / np.linalg.norm(light)),
            "u_ambient": settings.ambient,
            "u_specular": settings.specular,
            "u_shininess": settings.shininess,
            "u_rig_dir": rig.directions,
            "u_rig_colour": rig.colours,
            "u_rig_ambient": rig.ambient,
            "u_view_mode": VIEW_MODES[settings.view],
            "u_relief_depth": settings.relief_depth,
            "u_uv_per_unit": self.uv_per_unit,
            "u_viewport_size": (float(viewport[2]), float(viewport[3])),
            "u_tess_pixels": TESS_PIXELS,
            "u_tess_max": TESS_MAX,
            "u_relief_texels_per_unit": self.uv_per_unit * self.relief.texels,
            **{f"u_{name}": unit for name, unit in UNITS.items()},
            **self._uniforms,
        })
        return key

    def _vao(self, key: tuple[str, ...]) -> moderngl.VertexArray:
        if key not in self._vaos:
            content = [
                (self.deform.buffer, deform_pass.ATTRIBUTES, *deform_pass.NAMES),
                (self._static, "2f 3f", "in_uv", "in_rest"),
                (self._skin, "1f", "in_skin"),
                (self._wdv, "16f 4f 4f", "in_wdv", "in_cone", "in_slot_map"),
                (self._strain, "1f", "in_strain"),
            ]
            self._vaos[key] = self.ctx.vertex_array(
                self.programs.get(key), content, self.ibo, index_element_size=4,
                skip_errors=True)
        return self._vaos[key]

    def _draw_wireframe(self, view: np.ndarray, proj: np.ndarray) -> None:
        prog = self.programs.get(("wire",))
        write_matrix(prog, "u_view", view)
        write_matrix(prog, "u_proj", proj)
        prog["u_colour"].value = (0.05, 0.05, 0.05, 0.55)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.wireframe = True
        self.ctx.polygon_offset = (-1.0, -1.0)
        self._vao(("wire",)).render(moderngl.TRIANGLES)
        self.ctx.polygon_offset = (0.0, 0.0)
        self.ctx.wireframe = False
        self.ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        for buf in (self.ibo, self._static, self._wdv, self._skin, self._strain):
            buf.release()
