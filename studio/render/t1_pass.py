"""Technique 1 on the GPU: the influence masks, the activation vector, and the compose pass that
sums mask × activation into one weight texture (one weight per wrinkled map) for the face draw.

Why a composed texture: the face shader then reads one texel instead of every mask. Only what
changed is redone: a painted rectangle, or the bounding boxes of the areas whose activation
changed (an animation moves a few areas a frame).
"""

from __future__ import annotations

import moderngl
import numpy as np

from studio.core.files.errors import RenderError
from studio.core.wrinkles.mask_sparse import quantise, sparse_masks
from studio.render.face_maps import check_gl_size, raise_if_out_of_memory
from studio.render.programs import UNITS, Programs

Rect = tuple[int, int, int, int]  # x, y, width, height in mask pixels


def mask_boxes(masks: np.ndarray) -> np.ndarray:
    """(N, 4) int64 bounding box x0, y0, x1, y1 (end exclusive) of each mask's non-zero
    texels; (0, 0, 0, 0) for an empty mask."""
    _, h, w = masks.shape
    rows, cols = masks.any(axis=2), masks.any(axis=1)
    boxes = np.stack([cols.argmax(axis=1), rows.argmax(axis=1),
                      w - cols[:, ::-1].argmax(axis=1), h - rows[:, ::-1].argmax(axis=1)], axis=1)
    boxes[~rows.any(axis=1)] = 0
    return boxes.astype(np.int64)


class T1ComposePass:
    def __init__(self, ctx: moderngl.Context, programs: Programs) -> None:
        self.ctx = ctx
        self.programs = programs
        self.masks: moderngl.TextureArray | None = None
        self.activation_values = np.zeros(1, np.float32)
        self.area_maps = np.zeros(0, np.float32)  # wrinkled-map index of each area
        self.area_boxes = np.zeros((0, 4), np.int64)
        self.area_count = 0
        self._activations: moderngl.Texture | None = None
        self._mask_bytes = np.zeros((0, 1, 1), np.uint8)  # to rebuild a painted rectangle
        self._index: moderngl.Texture | None = None
        self._slot_weight: moderngl.Texture | None = None
        self.weight: moderngl.Texture | None = None
        self._fbo: moderngl.Framebuffer | None = None
        self._compose_vao: moderngl.VertexArray | None = None
        self.dirty = True
        self.dirty_rect: Rect | None = None  # None: the whole texture

    # --- masks ----------------------------------------------------------------------------
    def set_masks(self, masks: np.ndarray) -> None:
        """(N, H, W) in [0, 1]; any N (an empty stack becomes one zero layer). Refuses with a
        clear message what the GPU cannot hold; the old masks then still draw."""
        masks = np.asarray(masks, np.float32)
        if len(masks) == 0:
            masks = np.zeros((1, 1, 1), np.float32)
        n, h, w = masks.shape
        max_layers = int(self.ctx.info.get("GL_MAX_ARRAY_TEXTURE_LAYERS") or 0)
        if max_layers and n > max_layers:
            raise RenderError(f"this project has {n} influence areas, but this GPU can hold at "
                              f"most {max_layers} masks; merge or delete some areas")
        check_gl_size(self.ctx, "the influence masks are", w, h, "use smaller masks")
        try:
            data = quantise(masks)
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            if self.masks is not None and self.masks.size == (w, h, n):
                self.masks.write(data.tobytes())
            else:  # the new texture first: on failure the old one still draws
                new = self.ctx.texture_array((w, h, n), 1, data.tobytes(), dtype="f1")
                try:
                    raise_if_out_of_memory(self.ctx)
                except MemoryError:
                    new.release()
                    raise
                if self.masks is not None:
                    self.masks.release()
                self.masks = new
                self.masks.repeat_x = self.masks.repeat_y = False
                self.masks.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._mask_bytes = data
            self.area_boxes = mask_boxes(data)
            self.area_count = n
            self._set_sparse(data)
        except (moderngl.Error, MemoryError) as exc:
            raise RenderError(f"the GPU cannot hold {n} influence masks of {w}×{h} pixels "
                              f"({exc or type(exc).__name__}); use fewer areas or smaller "
                              "masks") from None
        self.activation_values = np.zeros(0, np.float32)
        self.set_activations(np.zeros(n, np.float32))

    def _set_sparse(self, data: np.ndarray) -> None:
        """Each texel's strongest areas (what the compose pass reads), and the weight texture."""
        _, h, w = data.shape
        sparse = sparse_masks(data)
        for gl_object in (self._index, self._slot_weight, self.weight, self._fbo):
            if gl_object is not None:
                gl_object.release()
        self._index = self.ctx.texture((w, h), 4, sparse.indices.tobytes(), dtype="u2")
        self._slot_weight = self.ctx.texture((w, h), 4, sparse.weights.tobytes(), dtype="f1")
        for tex in (self._index, self._slot_weight):
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.weight = self.ctx.texture((w, h), 4, dtype="f2")  # one weight per wrinkled map
        self.weight.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.weight.repeat_x = self.weight.repeat_y = False
        self._fbo = self.ctx.framebuffer(color_attachments=[self.weight])
        self.dirty = True
        self.dirty_rect = None

    def update_region(self, layer: int, x: int, y: int, patch: np.ndarray) -> np.ndarray:
        """Upload only a painted rectangle of one mask (image coordinates, top row first);
        returns the layer's grown bounding box."""
        data = quantise(patch)
        h, w = data.shape
        self.masks.write(data.tobytes(), viewport=(x, y, layer, w, h, 1))
        self._mask_bytes[layer, y:y + h, x:x + w] = data
        box = self.area_boxes[layer]
        if box[2] > box[0]:
            box[:] = min(box[0], x), min(box[1], y), max(box[2], x + w), max(box[3], y + h)
        else:
            box[:] = x, y, x + w, y + h
        sparse = sparse_masks(self._mask_bytes[:, y:y + h, x:x + w])
        self._index.write(sparse.indices.tobytes(), viewport=(x, y, w, h))
        self._slot_weight.write(sparse.weights.tobytes(), viewport=(x, y, w, h))
        self._mark_region(x, y, w, h)
        return box

    def _mark_region(self, x: int, y: int, w: int, h: int) -> None:
        """Only this rectangle changed: the next compose redoes just that (a 4096² mask would
        otherwise be recomposed whole after every dab)."""
        if self.dirty and self.dirty_rect is None:
            return  # the whole texture is due anyway
        if self.dirty:
            x0, y0, w0, h0 = self.dirty_rect
            x1, y1 = min(x, x0), min(y, y0)
            w, h = max(x + w, x0 + w0) - x1, max(y + h, y0 + h0) - y1
            x, y = x1, y1
        self.dirty_rect = (x, y, w, h)
        self.dirty = True

    # --- activations ----------------------------------------------------------------------
    def set_activations(self, activations: np.ndarray) -> None:
        """The activation vector; nothing is uploaded or recomposed if unchanged."""
        values = np.zeros(max(self.area_count, 1), np.float32)
        values[: len(activations)] = activations
        old = self.activation_values
        if np.array_equal(values, old):
            return
        self.activation_values = values
        if len(old) != len(values):
            self._upload_activations()
            return
        boxes = self.area_boxes[np.flatnonzero(values != old)]
        boxes = boxes[boxes[:, 2] > boxes[:, 0]]
        self._upload_activations(recompose=False)
        if len(boxes):
            x0, y0 = boxes[:, :2].min(axis=0)
            x1, y1 = boxes[:, 2:].max(axis=0)
            self._mark_region(int(x0), int(y0), int(x1 - x0), int(y1 - y0))

    def set_area_maps(self, maps: np.ndarray) -> None:
        """Which wrinkled map (index) each area reveals, in area order."""
        self.area_maps = np.asarray(maps, np.float32)
        self._upload_activations()

    def _upload_activations(self, recompose: bool = True) -> None:
        values = self.activation_values
        texels = np.zeros((len(values), 2), np.float32)
        texels[:, 0] = values
        n = min(len(values), len(self.area_maps))
        texels[:n, 1] = self.area_maps[:n]
        if self._activations is None or self._activations.width != len(values):
            if self._activations is not None:
                self._activations.release()
            self._activations = self.ctx.texture((len(values), 1), 2, dtype="f4")
            self._activations.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._activations.write(texels.tobytes())
        if recompose:
            self.dirty = True
            self.dirty_rect = None

    # --- the pass -------------------------------------------------------------------------
    def compose(self) -> None:
        """Σ mask·activation into the weight texture, from each texel's strongest areas, over
        the dirty rectangle only."""
        if not self.dirty:
            return
        prog = self.programs.get(("compose",))
        self.bind()
        for name in ("t1_index", "t1_slot_weight", "activations"):
            prog[f"u_{name}"].value = UNITS[name]
        # the weights are written, not blended: an overlay drawn before may have left blending on
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        self._fbo.use()
        self.ctx.viewport = (0, 0, *self.weight.size)
        self.ctx.scissor = self.dirty_rect
        self._vao().render(moderngl.TRIANGLES, vertices=3)
        self.ctx.scissor = None
        self.dirty = False
        self.dirty_rect = None

    def _vao(self) -> moderngl.VertexArray:
        if self._compose_vao is None:
            self._compose_vao = self.ctx.vertex_array(self.programs.get(("compose",)), [])
        return self._compose_vao

    def read_weights(self) -> np.ndarray:
        """The composed weight texture as the face shader reads it, (H, W, 4) float32, one
        weight per wrinkled map, row 0 at the top like the masks (composed first if due)."""
        self.compose()
        w, h = self.weight.size
        return np.frombuffer(self.weight.read(), np.float16).reshape(h, w, 4).astype(np.float32)

    def bind(self) -> None:
        self.masks.use(UNITS["masks"])
        self._activations.use(UNITS["activations"])
        self.weight.use(UNITS["t1_weight"])
        self._index.use(UNITS["t1_index"])
        self._slot_weight.use(UNITS["t1_slot_weight"])

    def release(self) -> None:
        for gl_object in (self.masks, self._activations, self._index, self._slot_weight,
                          self.weight, self._fbo, self._compose_vao):
            if gl_object is not None:
                gl_object.release()
