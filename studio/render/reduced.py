"""Drawing at reduced resolution while the user moves (orbits, scrubs, drags a pose slider, plays),
as Blender's viewport does on a slow machine: a software renderer (Mesa's llvmpipe in a virtual
machine or a remote desktop) pays for every pixel on a few CPU cores, and a 1728 × 972 frame of
the ICT head takes it several hundred milliseconds; a third of the size takes a ninth of that.

``MotionScale`` picks the size from the frames it has timed, so as to hold a frame rate;
``ReducedTarget`` is the small framebuffer the face is drawn into and its bilinear stretch over
the viewport. The viewport (widgets) decides when the user is moving and draws full size again
once they stop.
"""

from __future__ import annotations

from fractions import Fraction

import moderngl

from studio.render.shaders import build_program

#: The sizes a moving frame may be drawn at, as a share of the viewport's width and height.
SCALES = (Fraction(1), Fraction(1, 2), Fraction(1, 3), Fraction(1, 4), Fraction(1, 5),
          Fraction(1, 6))
TARGET_FPS = 20.0
#: The smallest share a played frame is drawn at: furrows a few pixels wide stay furrows at a
#: half, and turn to blur at a sixth.
PLAYING_FLOOR = Fraction(1, 2)
#: The least time left for drawing whatever the rest of a frame takes (Qt composing the
#: window, the events): below it the smallest scale is drawn anyway.
MIN_BUDGET_MS = 10.0
#: A larger size is taken only when its predicted time is this far under the budget, so that
#: the size does not flicker between two neighbours.
GROW_MARGIN = 0.8


def scaled_size(size: tuple[int, int], scale: Fraction) -> tuple[int, int]:
    """The reduced frame's size in pixels (at least 1 × 1)."""
    return max(1, round(size[0] * scale)), max(1, round(size[1] * scale))


class MotionScale:
    """The size to draw the next moving frame at: the largest of ``SCALES`` whose predicted time
    fits the budget, predicted from the last timed frame with the time proportional to the
    pixels drawn (a software renderer's frame is mostly its pixels; the fixed part makes the
    prediction for a larger size pessimistic, for a smaller one optimistic, and the next
    frame's time corrects it)."""

    def __init__(self, frame_ms: float = 1000.0 / TARGET_FPS) -> None:
        """``frame_ms``: the time one frame may take, drawing and the rest."""
        self.frame_ms = frame_ms
        # the smallest share drawn: 1/6 while orbiting (the shape is what is looked at), kept
        # at PLAYING_FLOOR while the timeline plays (the wrinkles are what is looked at, and a
        # played frame may be late: the player skips frames to keep time)
        self.floor = SCALES[-1]
        self.budget_ms = frame_ms  # of it, the drawing's share (see ``record``)
        self.scale = SCALES[0]
        self._known = False  # no moving frame timed yet

    def record(self, scale: Fraction, ms: float, rest_ms: float = 0.0) -> None:
        """A moving frame drawn at ``scale`` took ``ms``, and a frame's work besides the
        drawing (Qt composing the window: a software renderer pays for it by the window's
        pixels) takes ``rest_ms``: choose the next one's scale."""
        self.budget_ms = max(self.frame_ms - rest_ms, MIN_BUDGET_MS)
        allowed = [c for c in SCALES if c >= self.floor]
        chosen = allowed[-1]
        for candidate in allowed:
            predicted = ms * float(candidate / scale) ** 2
            limit = self.budget_ms * (GROW_MARGIN if candidate > scale else 1.0)
            if predicted <= limit:
                chosen = candidate
                break
        self.scale = chosen
        self._known = True

    def start(self, full_ms: float) -> None:
        """A movement starts after a still frame of ``full_ms`` (drawn full size, perhaps
        multisampled): without a moving frame timed yet, guess from it."""
        if not self._known:
            self.record(SCALES[0], full_ms)

    def label(self) -> str:
        """``"1/2"``: the scale as the status bar says it."""
        return str(self.scale)


class ReducedTarget:
    """A single-sampled colour + depth framebuffer of a reduced size (made again when the size
    changes) and the pass that stretches it over a larger framebuffer: the colour filtered
    bilinearly, the depth too (nearest), so overlays (points, lines) can be drawn on top at
    full size, their width in pixels as in a still frame, hidden where the face is nearer."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.fbo: moderngl.Framebuffer | None = None
        self._program = build_program(ctx, "upscale.vert", "upscale.frag")
        self._program["u_frame"].value = 0
        self._program["u_depth"].value = 1
        self._vao = ctx.vertex_array(self._program, [])  # corners from gl_VertexID

    def framebuffer(self, size: tuple[int, int]) -> moderngl.Framebuffer:
        """The reduced framebuffer of ``size`` pixels, to draw the frame into."""
        if self.fbo is None or self.fbo.size != size:
            self._release_fbo()
            colour = self.ctx.texture(size, 4)
            colour.filter = (moderngl.LINEAR, moderngl.LINEAR)
            colour.repeat_x = colour.repeat_y = False
            depth = self.ctx.depth_texture(size)
            depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
            depth.compare_func = ""  # read as values, not compared (moderngl's default)
            depth.repeat_x = depth.repeat_y = False
            self.fbo = self.ctx.framebuffer([colour], depth)
        return self.fbo

    def upscale(self, target: moderngl.Framebuffer, size: tuple[int, int]) -> None:
        """Stretch the reduced frame, colour and depth, over ``target``'s (0, 0, *size)."""
        ctx = self.ctx
        target.use()
        ctx.viewport = (0, 0, *size)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)  # depth is written only with the test on: always pass
        ctx.depth_func = "1"
        self.fbo.color_attachments[0].use(0)
        self.fbo.depth_attachment.use(1)
        self._vao.render(moderngl.TRIANGLES, vertices=3)
        ctx.depth_func = "<"  # the default the passes draw with

    def _release_fbo(self) -> None:
        if self.fbo is not None:
            for attachment in (*self.fbo.color_attachments, self.fbo.depth_attachment):
                attachment.release()
            self.fbo.release()
        self.fbo = None

    def release(self) -> None:
        self._release_fbo()
        self._vao.release()
        self._program.release()
