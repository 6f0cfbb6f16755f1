"""Deformation on the GPU: the key-pose blend, normals, tangents and the strain mode's weights
computed from the blended positions by transform feedback (OpenGL 3.3), so that nothing of the
mesh's size crosses the bus in a frame — only the pose weights (one float a pose).

What is uploaded once per mesh and set of poses: each pose's offsets where it moves a vertex
(sparse, grouped by vertex), the welded corners and UV terms of every triangle, and the corner
lists that each vertex's sums gather over (CSR: first and count per vertex into one list).
Then a frame is three passes over points, no rasterisation:

1. ``deform_blend.vert`` per welded vertex: ``rest + Σ w_k offset_k`` → a positions texture;
2. ``deform_frame.vert`` per render vertex: position, normal and tangent (the thesis's or the
   MikkTSpace-style frame) → the face's vertex buffer, which the face draw reads as it is;
3. ``deform_strain.vert`` per render vertex, in the strain mode only → its weight attribute.

The numpy code (core/animation/poses.py, core/mesh/geometry.py, core/mesh/tangent_frames.py,
core/wrinkles/strain.py) stays the reference and the fallback (``DeformPass``); the tests
compare the two. What the CPU still needs per frame is which vertices may have moved (the split
draw's choice of triangles), found from the poses of non-zero weight alone.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import moderngl
import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import _uv_coefficients
from studio.core.mesh.tangent_frames import MikkTSpaceFrame, uv_directions
from studio.core.wrinkles.strain import StrainField
from studio.render.programs import UNITS, Programs

Array = np.ndarray
DATA_WIDTH = 2048  # texels per row of a data texture (any size fits: rows are added)
FRAMES = {"thesis": (), "mikktspace": ("FRAME_MIKKTSPACE",)}
FRAME_VARYINGS = ("out_position", "out_normal", "out_tangent")  # = deform_pass.ATTRIBUTES
# each data texture's unit, past the face draw's own (programs.UNITS)
DATA_UNITS = {name: UNITS["deform"] + k for k, name in enumerate(
    ("offsets", "weights", "positions", "triangles", "corners", "uv_terms", "neighbours",
     "rest_lengths"))}


def data_texture(ctx: moderngl.Context, values: Array) -> moderngl.Texture:
    """An ``(n, c)`` float32 or int32 array as a texture the shaders read item by item with
    ``fetch`` (shaders/deform_data.glsl): row after row of ``DATA_WIDTH`` texels."""
    values = np.asarray(values)
    n, components = values.shape
    width = min(DATA_WIDTH, max(n, 1))
    rows = max(1, -(-n // width))
    padded = np.zeros((width * rows, components), values.dtype)
    padded[:n] = values
    texture = ctx.texture((width, rows), components, padded.tobytes(), dtype=values.dtype.str[1:])
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)  # integer textures need it
    return texture


def spans(owner: Array, n: int) -> tuple[Array, Array]:
    """The items grouped by ``owner`` (a stable order) and each owner's ``(first, count)``
    in that order, ``(n, 2)`` int32: a CSR list a shader loops over."""
    owner = np.asarray(owner, np.intp)
    order = np.argsort(owner, kind="stable")
    count = np.bincount(owner, minlength=n)
    first = np.cumsum(count) - count
    return order, np.column_stack([first, count]).astype(np.int32)


class GpuDeformPass:
    """The deform pass of ``DeformPass``'s interface, done on the GPU: ``set_weights`` each
    frame (the blender's weight vector), ``upload`` before the draw, ``buffer`` drawn from."""

    def __init__(self, ctx: moderngl.Context, programs: Programs, mesh: FaceMesh,
                 poses: Sequence[KeyPose]) -> None:
        self.ctx, self.programs, self.mesh = ctx, programs, mesh
        n_v, n_w = mesh.n_vertices, mesh.n_welded
        self.buffer = ctx.buffer(reserve=n_v * 10 * 4)  # written by transform feedback
        self.version = 0  # counts pose changes, as DeformPass's
        self.dirty = True
        self.frame = ""  # the tangent frame the buffer holds ("" before the first upload)
        self.last_ms = 0.0  # CPU time of the last upload (submitting the passes)
        self._gpu: list = []  # everything to release
        # transform feedback captures nothing on a surfaceless EGL context without a
        # framebuffer bound; the face draw binds its own afterwards
        self._bound = self._keep(ctx.simple_framebuffer((1, 1)))

        # the blend: each pose's non-zero offsets, grouped by vertex
        rest = np.ascontiguousarray(mesh.rest, np.float32)
        deltas = np.stack([p.positions - rest for p in poses]) if poses else \
            np.zeros((0, n_w, 3), np.float32)
        self._supports = (deltas != 0).any(axis=2)  # (P, W): which vertices each pose moves
        vertex, pose = np.nonzero(self._supports.T)  # ordered by vertex, then pose
        _, offset_spans = spans(vertex, n_w)
        offsets = np.column_stack([deltas[pose, vertex], pose.astype(np.float32)])
        self._weights = np.zeros(max(len(poses), 1), np.float32)
        self._active: tuple[int, ...] = ()  # poses of non-zero weight
        self._offsets = self._keep(data_texture(ctx, offsets.astype(np.float32)))
        self._weights_texture = self._keep(data_texture(ctx, self._weights[:, None]))
        width = min(DATA_WIDTH, n_w)
        rows = -(-n_w // width)
        self._positions = self._keep(ctx.texture((width, rows), 4, dtype="f4"))
        self._positions.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._blended = self._keep(ctx.buffer(reserve=width * rows * 16))
        blend = self._program("deform_blend.vert", ("out_position",))
        self._blend_vao = self._keep(ctx.vertex_array(blend, [
            (self._keep(ctx.buffer(rest.tobytes())), "3f", "in_rest"),
            (self._keep(ctx.buffer(offset_spans.tobytes())), "2i", "in_offsets")]))

        # normals and tangents: the corners each vertex gathers over
        triangles = mesh.triangles.astype(np.intp)
        weld = mesh.weld.astype(np.intp)
        corner_weld = weld[triangles].ravel()
        normal_order, normal_spans = spans(corner_weld, n_w)
        tangent_order, tangent_spans = spans(triangles.ravel(), n_v)
        tangent_spans[:, 0] += len(normal_order)
        corners = np.concatenate([normal_order, tangent_order]).astype(np.int32)[:, None]
        per_vertex = np.column_stack([weld, normal_spans[weld], tangent_spans]).astype(np.int32)
        self._corners = self._keep(data_texture(ctx, corners))
        welded_triangles = np.zeros((len(triangles), 4), np.int32)
        welded_triangles[:, :3] = weld[triangles]
        self._triangles = self._keep(data_texture(ctx, welded_triangles))
        self._thesis_terms = np.stack(_uv_coefficients(mesh.uvs, triangles), axis=1)
        self._uv_terms: dict[str, moderngl.Texture] = {}
        self._side = np.ones(n_v, np.float32)  # MikkTSpace's per vertex (on first use)
        self._frame_input = self._keep(ctx.buffer(per_vertex.tobytes()))
        self._side_buffer = self._keep(ctx.buffer(reserve=n_v * 4))
        self._frame_vaos: dict[str, moderngl.VertexArray] = {}

        self._strain: StrainField | None = None  # the strain mode's edges (on first use)
        self._strain_vao: moderngl.VertexArray | None = None
        self._strain_mask: tuple[object, Array] | None = None

    def _keep(self, thing):
        self._gpu.append(thing)
        return thing

    # --- a frame --------------------------------------------------------------------------
    def set_weights(self, weights: Array) -> None:
        """This frame's weight per pose (``PoseBlender.weights_vector``): a few bytes."""
        np.copyto(self._weights[:len(weights)], weights)
        self._active = tuple(np.flatnonzero(weights).tolist())
        self.dirty = True
        self.version += 1

    @property
    def motion_key(self) -> object:
        """Changes when the set of vertices that may have moved does: the poses in use."""
        return self._active

    def moved_welded(self) -> Array:
        """(W,) bool: the vertices some pose of non-zero weight moves (a superset of those
        away from the neutral pose: offsets may cancel)."""
        return self._supports[list(self._active)].any(axis=0)

    def upload(self, tangent_frame: str) -> None:
        """Blend, then normals and tangents in ``tangent_frame`` into ``buffer``, on the GPU."""
        if tangent_frame != self.frame:
            self.frame, self.dirty = tangent_frame, True
        if not self.dirty:
            return
        start = time.thread_time()
        self._bound.use()
        self._weights_texture.write(self._weights.tobytes())
        self._bind(("offsets", self._offsets), ("weights", self._weights_texture))
        self._blend_vao.transform(self._blended, moderngl.POINTS, self.mesh.n_welded)
        self._positions.write(self._blended)  # GPU to GPU
        program = self._frame_vao(tangent_frame)
        self._bind(("positions", self._positions), ("triangles", self._triangles),
                   ("corners", self._corners), ("uv_terms", self._uv_terms[tangent_frame]))
        program.transform(self.buffer, moderngl.POINTS, self.mesh.n_vertices)
        self.last_ms = (time.thread_time() - start) * 1000.0
        self.dirty = False

    def _frame_vao(self, tangent_frame: str) -> moderngl.VertexArray:
        if tangent_frame not in self._frame_vaos:
            mesh = self.mesh
            if tangent_frame == "mikktspace":
                a, b, side = uv_directions(mesh.uvs, mesh.triangles)
                terms = np.column_stack([a, b, side, np.zeros_like(a)])
                self._side = MikkTSpaceFrame(mesh.triangles, mesh.uvs, mesh.weld,
                                             mesh.rest).side.astype(np.float32)
                self._side_buffer.write(self._side.tobytes())
            else:
                terms = self._thesis_terms
            self._uv_terms[tangent_frame] = self._keep(
                data_texture(self.ctx, terms.astype(np.float32)))
            program = self._program("deform_frame.vert", FRAME_VARYINGS, FRAMES[tangent_frame])
            self._frame_vaos[tangent_frame] = self._keep(self.ctx.vertex_array(program, [
                (self._frame_input, "1i 2i 2i", "in_weld", "in_normal_corners",
                 "in_tangent_corners"),
                (self._side_buffer, "1f", "in_side")], skip_errors=True))
        return self._frame_vaos[tangent_frame]

    def _program(self, vertex: str, varyings: tuple[str, ...],
                 defines: tuple[str, ...] = ()) -> moderngl.Program:
        """A transform-feedback program, its data textures' units set."""
        program = self.programs.feedback(vertex, varyings, defines)
        for name, unit in DATA_UNITS.items():
            if f"u_{name}" in program:
                program[f"u_{name}"].value = unit
        return program

    @staticmethod
    def _bind(*textures: tuple[str, moderngl.Texture]) -> None:
        for name, texture in textures:
            texture.use(DATA_UNITS[name])

    # --- the strain mode --------------------------------------------------------------------
    def write_strain(self, target: moderngl.Buffer, full_at: float) -> tuple[object, Array]:
        """The strain weights of this frame's positions into ``target`` (per render vertex),
        on the GPU; returns the key and the per-render-vertex values above 0 where the weight
        can be (the vertices at an edge with a moved end), for the split draw."""
        if self._strain_vao is None:
            self._build_strain()
        program = self._program("deform_strain.vert", ("out_strain",))
        program["u_full_at"].value = float(full_at)
        self._bind(("positions", self._positions), ("neighbours", self._neighbours),
                   ("rest_lengths", self._rest_lengths))
        self._bound.use()
        self._strain_vao.transform(target, moderngl.POINTS, self.mesh.n_vertices)
        key = self.motion_key
        if self._strain_mask is None or self._strain_mask[0] != key:
            moved = self.moved_welded()
            a, b = self._strain.edges[:, 0], self._strain.edges[:, 1]
            near = moved.copy()
            near[a[moved[b]]] = True
            near[b[moved[a]]] = True
            self._strain_mask = (key, near[self.mesh.weld].astype(np.float32))
        return self._strain_mask

    def _build_strain(self) -> None:
        field = self._strain = StrainField(self.mesh)
        a, b = field.edges[:, 0], field.edges[:, 1]
        order, edge_spans = spans(np.concatenate([a, b]), self.mesh.n_welded)
        other = np.concatenate([b, a])[order]
        lengths = np.concatenate([field.rest_lengths, field.rest_lengths])[order]
        self._neighbours = self._keep(data_texture(self.ctx, other.astype(np.int32)[:, None]))
        self._rest_lengths = self._keep(data_texture(self.ctx,
                                                     lengths.astype(np.float32)[:, None]))
        weld = self.mesh.weld.astype(np.intp)
        per_vertex = np.column_stack([weld, edge_spans[weld]]).astype(np.int32)
        program = self._program("deform_strain.vert", ("out_strain",))
        self._strain_vao = self._keep(self.ctx.vertex_array(program, [
            (self._keep(self.ctx.buffer(per_vertex.tobytes())), "1i 2i", "in_weld",
             "in_edges")]))

    def release(self) -> None:
        self.buffer.release()
        for thing in reversed(self._gpu):
            thing.release()
        self._gpu.clear()
