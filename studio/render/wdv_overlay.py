"""What technique-2 authoring draws over the face: selected vertices, wrinkle direction vectors
and the selection tool's outline; and a depth pass of the posed face for occlusion-aware picking.

The widget layer hands it plain arrays (posed positions, selected indices, line segments);
uploads happen lazily in ``draw``, inside the viewport's GL context. Points and lines are drawn
with the depth test against the face's depth, nudged slightly toward the camera, so what lies
behind the face stays hidden.
"""

from __future__ import annotations

import moderngl
import numpy as np

from studio.core.mesh.camera import OrbitCamera
from studio.core.wrinkles.wdv import WdvSetup
from studio.render.shaders import build_program

Array = np.ndarray
DEPTH_BIAS = 2e-4  # in clip-space z per w: enough to win over the surface a vertex lies on


def vector_lines(positions: Array, wdv: WdvSetup, glyph_length: float,
                 only: str | None = None, others: float | None = None) -> tuple[Array, Array]:
    """Line segments (2 per authored vertex of every enabled area) and their RGBA colours: tail
    at the vertex in a dim tone, head along the direction in the area's full colour.

    With ``only`` (an area's name) that area is drawn as above and the others, so that a face
    with a dozen areas is not buried in needles, not at all or (``others``, an opacity) faint.
    """
    starts, ends, colours = [], [], []
    for area in wdv.areas:  # loops over areas, each vectorised over its vertices
        if not area.enabled:
            continue
        opacity = 1.0 if only is None or area.name == only else others
        if opacity is None:
            continue
        idx = np.flatnonzero(area.authored)
        if len(idx) == 0:
            continue
        p = positions[idx]
        starts.append(p)
        ends.append(p + area.directions[idx] * glyph_length)
        c = np.asarray(area.colour, np.float32) / 255.0
        colours.append(np.broadcast_to(np.r_[c * 0.45, 0.9 * opacity], (len(idx), 4)))
        colours.append(np.broadcast_to(np.r_[c, opacity], (len(idx), 4)))
    if not starts:
        return np.zeros((0, 3), np.float32), np.zeros((0, 4), np.float32)
    s, e = np.concatenate(starts), np.concatenate(ends)
    n_each = [len(x) for x in starts]
    pos = np.empty((2 * len(s), 3), np.float32)
    pos[0::2], pos[1::2] = s, e
    cols = np.empty((2 * len(s), 4), np.float32)
    offset = 0
    for k, n in enumerate(n_each):
        cols[2 * offset:2 * (offset + n):2] = colours[2 * k]
        cols[2 * offset + 1:2 * (offset + n):2] = colours[2 * k + 1]
        offset += n
    return pos, cols


class WdvOverlay:
    """Viewport overlay: ``draw(ctx, fbo, camera, rect)`` after the face each frame."""

    def __init__(self) -> None:
        self.visible = True
        self.show_vectors = True
        self._positions: Array | None = None
        self._triangles: Array | None = None
        self._selected: Array = np.zeros(0, np.int32)
        self.point_colour = (1.0, 0.6, 0.15, 1.0)
        self.point_size = 7.0
        self._lines = (np.zeros((0, 3), np.float32), np.zeros((0, 4), np.float32))
        self._outline: Array | None = None  # (N, 2) pixels of the tool's shape, closed or not
        self._outline_closed = False
        self._dirty = {"positions", "triangles", "selected", "lines", "outline"}
        self._gl: dict = {}
        self._ctx: moderngl.Context | None = None
        self._depth_fbo: moderngl.Framebuffer | None = None

    # --- data from the widget layer -------------------------------------------------------------
    def set_mesh(self, welded_triangles: Array) -> None:
        self._triangles = np.ascontiguousarray(welded_triangles, np.int32)
        self._dirty.add("triangles")

    def set_positions(self, positions: Array) -> None:
        self._positions = np.ascontiguousarray(positions, np.float32)
        self._dirty.add("positions")

    def set_selection(self, indices: Array, colour: tuple[int, int, int]) -> None:
        self._selected = np.ascontiguousarray(indices, np.int32)
        self.point_colour = (*(c / 255.0 for c in colour), 1.0)
        self._dirty.add("selected")

    def set_vectors(self, positions: Array, colours: Array) -> None:
        self._lines = (np.ascontiguousarray(positions, np.float32),
                       np.ascontiguousarray(colours, np.float32))
        self._dirty.add("lines")

    def set_outline(self, pixels: Array | None, closed: bool = False) -> None:
        self._outline = None if pixels is None else np.asarray(pixels, np.float32)
        self._outline_closed = closed
        self._dirty.add("outline")

    # --- GL -------------------------------------------------------------------------------------
    def _buffer(self, name: str, data: Array) -> moderngl.Buffer:
        """A buffer holding ``data``, grown only when it no longer fits."""
        raw = data.tobytes()
        buf = self._gl.get(name)
        if buf is None or buf.size < max(len(raw), 4):
            if buf is not None:
                buf.release()
            buf = self._ctx.buffer(reserve=max(len(raw), 4) * 2)
            self._gl[name] = buf
            for key in [k for k in self._gl if k.startswith("vao:")]:
                self._gl.pop(key).release()  # vertex arrays refer to the old buffer
        if raw:
            buf.write(raw)
        return buf

    def _prepare(self, ctx: moderngl.Context) -> None:
        if self._ctx is not ctx:
            self._ctx = ctx
            self._gl = {}
            self._depth_fbo = None
            self._dirty = {"positions", "triangles", "selected", "lines", "outline"}
            self._points = build_program(ctx, "wdv_points.vert", "wdv_points.frag")
            self._arrows = build_program(ctx, "wdv_arrows.vert", "wdv_arrows.frag")
        dirty = self._dirty
        if "positions" in dirty and self._positions is not None:
            self._buffer("positions", self._positions)
        if "triangles" in dirty and self._triangles is not None:
            self._buffer("triangles", self._triangles)
        if "selected" in dirty:
            self._buffer("selected", self._selected)
        if "lines" in dirty:
            pos, col = self._lines
            self._buffer("lines", np.hstack([pos, col]).astype(np.float32))
        self._dirty = set()

    def _vao(self, name: str, program: moderngl.Program, content, index: str | None = None
             ) -> moderngl.VertexArray:
        key = f"vao:{name}"
        if key not in self._gl:
            ibo = self._gl[index] if index else None
            self._gl[key] = self._ctx.vertex_array(program, content, ibo,
                                                   index_element_size=4, skip_errors=True)
        return self._gl[key]

    @staticmethod
    def _matrices(program: moderngl.Program, view: Array, proj: Array) -> None:
        program["u_view"].write(view.T.astype("f4").tobytes())
        program["u_proj"].write(proj.T.astype("f4").tobytes())

    def draw(self, ctx: moderngl.Context, fbo: moderngl.Framebuffer, camera: OrbitCamera,
             rect: tuple[int, int, int, int]) -> None:
        if not self.visible or self._positions is None:
            return
        self._prepare(ctx)
        _, _, w, h = rect
        fbo.use()
        ctx.viewport = rect
        view = camera.view_matrix()
        proj = camera.projection_matrix(w / max(h, 1))
        ctx.enable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.PROGRAM_POINT_SIZE)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        n_lines = len(self._lines[0])
        if self.show_vectors and n_lines:
            prog = self._arrows
            self._matrices(prog, view, proj)
            prog["u_depth_bias"].value = DEPTH_BIAS
            vao = self._vao("lines", prog, [(self._gl["lines"], "3f 4f", "in_position",
                                             "in_colour")])
            vao.render(moderngl.LINES, vertices=n_lines)
        n_sel = len(self._selected)
        if n_sel:
            prog = self._points
            self._matrices(prog, view, proj)
            prog["u_depth_bias"].value = DEPTH_BIAS
            prog["u_point_size"].value = self.point_size
            prog["u_colour"].value = self.point_colour
            prog["u_round"].value = True
            vao = self._vao("selected", prog, [(self._gl["positions"], "3f", "in_position")],
                            index="selected")
            vao.render(moderngl.POINTS, vertices=n_sel)
        if self._outline is not None and len(self._outline) >= 2:
            self._draw_outline(ctx, w, h)
        ctx.disable(moderngl.BLEND | moderngl.PROGRAM_POINT_SIZE)

    def _draw_outline(self, ctx: moderngl.Context, w: int, h: int) -> None:
        """The box, lasso or brush circle in pixel coordinates, on top of everything."""
        n = len(self._outline)
        parts = []
        # a dark copy one pixel down-right under a white one: readable on skin and background;
        # +0.5 puts the line on pixel centres so it stays crisp
        for shift, colour in ((1.5, (0.0, 0.0, 0.0, 0.6)), (0.5, (1.0, 1.0, 1.0, 1.0))):
            pts = self._outline + shift
            ndc = np.c_[pts[:, 0] / w * 2.0 - 1.0, 1.0 - pts[:, 1] / h * 2.0, np.zeros(n)]
            parts.append(np.hstack([ndc, np.tile(colour, (n, 1))]))
        buf = self._buffer("outline", np.concatenate(parts).astype(np.float32))
        prog = self._arrows
        eye = np.eye(4)
        self._matrices(prog, eye, eye)
        prog["u_depth_bias"].value = 0.0
        vao = self._vao("outline", prog, [(buf, "3f 4f", "in_position", "in_colour")])
        ctx.disable(moderngl.DEPTH_TEST)
        mode = moderngl.LINE_LOOP if self._outline_closed else moderngl.LINE_STRIP
        vao.render(mode, vertices=n, first=0)
        vao.render(mode, vertices=n, first=n)
        ctx.enable(moderngl.DEPTH_TEST)

    def read_depth(self, ctx: moderngl.Context, camera: OrbitCamera, width: int,
                   height: int) -> Array | None:
        """Depth buffer (H, W; first row at the bottom) of the posed face as ``camera`` sees it,
        drawn into a private single-sample target (the window's own is multisampled)."""
        if self._positions is None or self._triangles is None:
            return None
        self._prepare(ctx)
        fbo = self._depth_fbo
        if fbo is None or fbo.size != (width, height):
            if fbo is not None:
                fbo.release()
            depth = ctx.depth_renderbuffer((width, height))
            fbo = self._depth_fbo = ctx.framebuffer(depth_attachment=depth)
        fbo.use()
        ctx.viewport = (0, 0, width, height)
        fbo.clear(depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        prog = self._points
        self._matrices(prog, camera.view_matrix(), camera.projection_matrix(width / max(height, 1)))
        prog["u_depth_bias"].value = 0.0
        prog["u_point_size"].value = 1.0
        prog["u_round"].value = False
        vao = self._vao("faces", prog, [(self._gl["positions"], "3f", "in_position")],
                        index="triangles")
        vao.render(moderngl.TRIANGLES, vertices=len(self._triangles) * 3)
        data = fbo.read(components=1, attachment=-1, dtype="f4")
        return np.frombuffer(data, np.float32).reshape(height, width)

    def release(self) -> None:
        for obj in self._gl.values():
            obj.release()
        self._gl = {}
