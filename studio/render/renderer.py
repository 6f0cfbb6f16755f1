"""The face renderer: any moderngl context, any framebuffer, no Qt.

It keeps GPU copies of the mesh, textures, masks and wrinkle direction vectors and re-uploads only
what a ``set_*`` call marked dirty; the per-frame work is the pose's positions, normals and
tangents (one interleaved buffer write) and the draw.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from studio.core.camera import OrbitCamera
from studio.core.draw_split import moved
from studio.core.geometry import DeformCache
from studio.core.mask_sparse import quantise, sparse_masks
from studio.core.mesh import FaceMesh
from studio.core.relief import DEFAULT_RELIEF_DEPTH, maps_digest, relief_image
from studio.core.strain import DEFAULT_FULL_AT, StrainField
from studio.core.tangent_frames import DEFAULT_TANGENT_FRAME, TANGENT_FRAMES
from studio.core.techniques import TECHNIQUES, WRINKLE_TECHNIQUES, shader_define
from studio.core.textures import FaceTextures, pack_more_maps, pack_normal_maps
from studio.core.view_settings import BLENDS, DEBUG_VIEWS, RELIEFS
from studio.core.wdv import SLOTS, WdvSlots
from studio.render.shaders import build_program
from studio.render.triangle_split import TriangleSplit

VIEW_MODES = {name: i for i, name in enumerate(DEBUG_VIEWS)}  # u_view_mode in face.frag

_UNIT = {"diffuse": 0, "normals": 1, "masks": 2, "activations": 3, "t1_weight": 4,
         "t1_index": 5, "t1_slot_weight": 6, "more_maps": 7, "relief": 8}
T1_MODES = ("composed", "direct")
DISPLACE_GL = 400  # tessellation shaders: OpenGL 4.0
TESS_PIXELS = 3.0  # displace: wanted screen length of one segment of a wrinkled edge
TESS_MAX = 32.0  # displace: most segments per edge


@dataclass
class RenderSettings:
    technique: str = "t2"  # flat | none | t1 | t2 | strain (automatic, from skin compression)
    view: str = "shaded"  # shaded | heat | normals | uv
    wireframe: bool = False
    light_dir: tuple[float, float, float] = (0.45, 0.5, 0.75)  # view space, toward the light
    ambient: float = 0.1
    specular: float = 0.12
    shininess: float = 20.0
    background: tuple[float, float, float] = (0.16, 0.17, 0.19)
    blend: str = "colour"  # colour: the thesis's mix of two shadings; normal: light once
    t1_mode: str = "composed"  # composed: one weight texture a frame; direct: every mask a pixel
    strain_full_at: float = DEFAULT_FULL_AT  # compression at which strain wrinkles fully show
    relief: str = "off"  # off | displace (tessellation, GL 4.0) | parallax: wrinkles in depth
    relief_depth: float = DEFAULT_RELIEF_DEPTH  # model units of the deepest wrinkle
    tangent_frame: str = DEFAULT_TANGENT_FRAME  # mikktspace | thesis: how the maps are read

    def __post_init__(self) -> None:
        for value, allowed, what in ((self.technique, tuple(TECHNIQUES), "technique"),
                                     (self.view, tuple(VIEW_MODES), "view"),
                                     (self.blend, BLENDS, "blend"),
                                     (self.t1_mode, T1_MODES, "technique-1 mode"),
                                     (self.relief, RELIEFS, "relief"),
                                     (self.tangent_frame, TANGENT_FRAMES, "tangent frame")):
            if value not in allowed:
                raise ValueError(f"unknown {what} '{value}' (choose from {allowed})")
        if not 0.0 <= self.relief_depth < float("inf"):
            raise ValueError(f"the relief depth must be 0 or more, got {self.relief_depth}")

    @property
    def active_relief(self) -> str:
        """The relief actually drawn: only the wrinkle techniques have wrinkles to raise."""
        return self.relief if self.technique in WRINKLE_TECHNIQUES else "off"

    def program_key(self) -> tuple[str, ...]:
        """What selects a compiled program: only options that change the shader's code."""
        defines = [shader_define(self.technique)]
        if self.blend == "normal":
            defines.append("BLEND_NORMALS")
        if self.technique == "t1" and self.t1_mode == "direct":
            defines.append("T1_DIRECT")
        if self.active_relief != "off":
            defines.append(f"RELIEF_{self.active_relief.upper()}")
        return tuple(defines)


def mask_boxes(masks: np.ndarray) -> np.ndarray:
    """(N, 4) int64 bounding box x0, y0, x1, y1 (end exclusive) of each mask's non-zero
    texels; (0, 0, 0, 0) for an empty mask."""
    _, h, w = masks.shape
    rows, cols = masks.any(axis=2), masks.any(axis=1)
    boxes = np.stack([cols.argmax(axis=1), rows.argmax(axis=1),
                      w - cols[:, ::-1].argmax(axis=1), h - rows[:, ::-1].argmax(axis=1)], axis=1)
    boxes[~rows.any(axis=1)] = 0
    return boxes.astype(np.int64)


def _texture_dtype(image: np.ndarray) -> str:
    return "nu2" if image.dtype == np.uint16 else "f1"


def _uv_per_unit(mesh: FaceMesh) -> float:
    """Texcoord units per model unit over the neutral surface (the root of the UV area over the
    surface area): how far a parallax offset of one model unit moves in the maps."""
    corners = mesh.rest[mesh.weld][mesh.triangles]
    uv = mesh.uvs[mesh.triangles]
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                          axis=1).sum()
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()
    return float(np.sqrt(uv_area / area)) if area > 0 and uv_area > 0 else 1.0


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
        self._activation_values = np.zeros(1, np.float32)
        self._area_maps = np.zeros(0, np.float32)  # wrinkled-map index of each technique-1 area
        self._map_count = 1  # wrinkled maps of the current textures
        self._t1_index: moderngl.Texture | None = None
        self._t1_slot_weight: moderngl.Texture | None = None
        self._t1_weight: moderngl.Texture | None = None
        self._t1_fbo: moderngl.Framebuffer | None = None
        self._t1_dirty = True
        self._t1_dirty_rect: tuple[int, int, int, int] | None = None  # None: the whole texture
        self._buffers: list[moderngl.Buffer] = []
        self._positions: np.ndarray | None = None
        self._geometry_dirty = False
        self.last_deform_ms = 0.0  # CPU time of the last normals + tangents update
        self.expression_factor = 1.0
        self.split_draws = True  # plain shading for triangles that cannot wrinkle (same picture)
        self.scale_free = True
        self._relief: moderngl.Texture | None = None  # wrinkle heights, made on first use
        self._relief_maps: tuple[np.ndarray, list[np.ndarray]] | None = None  # due from these
        self._relief_digest = b""  # of the maps the relief texture was made from
        self._uv_per_unit = 1.0
        self.set_masks(np.zeros((0, 1, 1), np.float32))

    @property
    def can_displace(self) -> bool:
        """Whether relief "displace" can draw here (tessellation shaders, OpenGL 4.0)."""
        return self.ctx.version_code >= DISPLACE_GL

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
        self._wdv = self.ctx.buffer(np.zeros((v, 4 * SLOTS + 2 * SLOTS), "f4").tobytes())
        self._skin = self.ctx.buffer(np.ones(v, "f4").tobytes())
        self._strain_field = StrainField(mesh)
        self._strain = self.ctx.buffer(reserve=v * 4, dynamic=True)
        self._strain_key: tuple[int, float] | None = None  # (positions version, full_at)
        self._render_strain = np.zeros(len(mesh.weld), np.float32)
        self._split = TriangleSplit(self._ibo, mesh.triangles, mesh.uvs, mesh.rest[mesh.weld])
        if self._masks is not None:
            self._split.set_area_boxes(self._area_boxes, *self._masks.size[:2])
        self._buffers = [self._ibo, self._dynamic, self._static, self._wdv, self._strain,
                         self._skin]
        self._positions = mesh.rest.copy()
        self._positions_version = 0
        self._geometry_dirty = True
        self._uv_per_unit = _uv_per_unit(mesh)

    def set_positions(self, welded_positions: np.ndarray) -> None:
        """The pose of this frame (welded positions); normals and tangents follow at draw."""
        np.copyto(self._positions, welded_positions)
        self._geometry_dirty = True
        self._positions_version += 1

    def set_skin(self, skin: np.ndarray) -> None:
        """(W,) per welded vertex: 1 where wrinkles may show, 0 on not-face vertices."""
        render_skin = np.asarray(skin, "f4")[self.mesh.weld]
        self._skin.write(render_skin.tobytes())
        self._split.set_skin(render_skin)

    def set_textures(self, textures: FaceTextures) -> None:
        """Diffuse map; the neutral and first wrinkled normal maps packed into one texture (one
        fetch blends them); further wrinkled maps in an array read only where they show."""
        from studio.core.errors import RenderError

        max_size = int(self.ctx.info.get("GL_MAX_TEXTURE_SIZE") or 0)
        named = {"diffuse": textures.diffuse, "neutral normal": textures.normal_neutral,
                 **{f"wrinkled normal ('{k}')": v for k, v in textures.wrinkle_maps.items()}}
        for name, image in named.items():
            h, w = image.shape[:2]
            if max_size and max(w, h) > max_size:
                raise RenderError(f"the {name} map is {w}×{h} pixels, but this "
                                  f"GPU's largest texture is {max_size}×{max_size}; use a "
                                  "smaller map")
        created: dict[str, moderngl.Texture | moderngl.TextureArray] = {}
        try:  # all new textures first: on failure the old ones still draw
            normals = pack_normal_maps(textures.normal_neutral, textures.normal_wrinkled)
            images = {"diffuse": textures.diffuse, "normals": normals,
                      "more_maps": pack_more_maps(textures, normals)}
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            for name, image in images.items():
                if image.ndim == 4:  # layers of a texture array
                    n, h, w, components = image.shape
                    tex = self.ctx.texture_array((w, h, n), components, image.tobytes(),
                                                 dtype=_texture_dtype(image))
                else:
                    h, w, components = image.shape
                    tex = self.ctx.texture((w, h), components, image.tobytes(),
                                           dtype=_texture_dtype(image))
                created[name] = tex
                tex.build_mipmaps()
                tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
                # further wrinkled maps: trilinear only. A software renderer fetches them on
                # every pixel (it runs both sides of a branch), and 8x anisotropic fetches of
                # them doubled the cost of a frame; the first map keeps full filtering
                tex.anisotropy = 1.0 if name == "more_maps" else 8.0
                tex.repeat_x = tex.repeat_y = False
                if self.ctx.error == "GL_OUT_OF_MEMORY":
                    raise MemoryError("GL_OUT_OF_MEMORY")
        except (moderngl.Error, MemoryError) as exc:
            for tex in created.values():
                tex.release()
            size = "×".join(str(v) for v in textures.diffuse.shape[1::-1])
            raise RenderError(f"the GPU cannot hold the texture maps ({size} pixels; "
                              f"{exc or type(exc).__name__}); use smaller maps") from None
        for name, tex in created.items():
            old = self._textures.pop(name, None)
            if old is not None:
                old.release()
            self._textures[name] = tex
        self._map_count = len(textures.wrinkle_maps)  # compiled into the face programs
        # the wrinkle heights follow these maps; integrated once, when a relief first draws
        # (a fraction of a second at 1024², never per frame)
        self._relief_maps = (textures.normal_neutral, list(textures.wrinkle_maps.values()))

    def _ensure_relief(self) -> None:
        """The wrinkle-height texture (studio/core/relief.py) for the current maps."""
        if self._relief_maps is None:
            return
        from studio.core.errors import RenderError

        digest = maps_digest(*self._relief_maps)
        if self._relief is not None and digest == self._relief_digest:
            self._relief_maps = None  # the same maps again (a project reloaded, say)
            return
        image = relief_image(*self._relief_maps)
        h, w = image.shape[:2]
        try:
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            tex = self.ctx.texture((w, h), 4, image.tobytes(), dtype="f2")
            if self.ctx.error == "GL_OUT_OF_MEMORY":
                tex.release()
                raise MemoryError("GL_OUT_OF_MEMORY")
        except (moderngl.Error, MemoryError) as exc:
            raise RenderError(f"the GPU cannot hold the wrinkle heights ({w}×{h} pixels; "
                              f"{exc or type(exc).__name__}); use smaller maps") from None
        tex.build_mipmaps()
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        if self._relief is not None:
            self._relief.release()
        self._relief = tex
        self._relief_maps = None
        self._relief_digest = digest

    def set_masks(self, masks: np.ndarray) -> None:
        """Technique 1 masks, (N, H, W) in [0, 1]; any N (an empty stack becomes one zero layer)."""
        masks = np.asarray(masks, np.float32)
        if len(masks) == 0:
            masks = np.zeros((1, 1, 1), np.float32)
        n, h, w = masks.shape
        # GPU limits: refuse with a clear message what the driver would fail on or crash with
        from studio.core.errors import RenderError

        info = self.ctx.info
        max_layers = int(info.get("GL_MAX_ARRAY_TEXTURE_LAYERS") or 0)
        max_size = int(info.get("GL_MAX_TEXTURE_SIZE") or 0)
        if max_layers and n > max_layers:
            raise RenderError(f"this project has {n} influence areas, but this GPU can hold at "
                              f"most {max_layers} masks; merge or delete some areas")
        if max_size and max(w, h) > max_size:
            raise RenderError(f"the influence masks are {w}×{h} pixels, but this GPU's largest "
                              f"texture is {max_size}×{max_size}; use smaller masks")
        try:
            data = quantise(masks)
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            if self._masks is not None and self._masks.size == (w, h, n):
                self._masks.write(data.tobytes())
            else:  # the new texture first: on failure the old one still draws
                new = self.ctx.texture_array((w, h, n), 1, data.tobytes(), dtype="f1")
                if self.ctx.error == "GL_OUT_OF_MEMORY":
                    new.release()
                    raise MemoryError("GL_OUT_OF_MEMORY")
                if self._masks is not None:
                    self._masks.release()
                self._masks = new
                self._masks.repeat_x = self._masks.repeat_y = False
                self._masks.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._mask_bytes = data  # kept to rebuild the sparse form of a painted rectangle
            self._area_boxes = mask_boxes(data)
            self._area_count = n
            if self.mesh is not None:
                self._split.set_area_boxes(self._area_boxes, w, h)
            self._set_sparse_masks(data)
        except (moderngl.Error, MemoryError) as exc:
            raise RenderError(f"the GPU cannot hold {n} influence masks of {w}×{h} pixels "
                              f"({exc or type(exc).__name__}); use fewer areas or smaller "
                              "masks") from None
        self._activation_values = np.zeros(0, np.float32)
        self.set_activations(np.zeros(n, np.float32))

    def _set_sparse_masks(self, data: np.ndarray) -> None:
        """The composed path's per-texel strongest areas, and its weight texture."""
        _, h, w = data.shape
        sparse = sparse_masks(data)
        for tex in (self._t1_index, self._t1_slot_weight, self._t1_weight):
            if tex is not None:
                tex.release()
        if self._t1_fbo is not None:
            self._t1_fbo.release()
        self._t1_index = self.ctx.texture((w, h), 4, sparse.indices.tobytes(), dtype="u2")
        self._t1_slot_weight = self.ctx.texture((w, h), 4, sparse.weights.tobytes(), dtype="f1")
        for tex in (self._t1_index, self._t1_slot_weight):
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._t1_weight = self.ctx.texture((w, h), 4, dtype="f2")  # one weight per wrinkled map
        self._t1_weight.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._t1_weight.repeat_x = self._t1_weight.repeat_y = False
        self._t1_fbo = self.ctx.framebuffer(color_attachments=[self._t1_weight])
        self._t1_dirty = True
        self._t1_dirty_rect = None

    def update_mask_region(self, layer: int, x: int, y: int, patch: np.ndarray) -> None:
        """Upload only a painted rectangle of one mask (image coordinates, top row first)."""
        data = quantise(patch)
        h, w = data.shape
        self._masks.write(data.tobytes(), viewport=(x, y, layer, w, h, 1))
        self._mask_bytes[layer, y:y + h, x:x + w] = data
        box = self._area_boxes[layer]
        if box[2] > box[0]:  # grow the layer's box to the painted rectangle
            box[:] = min(box[0], x), min(box[1], y), max(box[2], x + w), max(box[3], y + h)
        else:
            box[:] = x, y, x + w, y + h
        self._split.set_area_box(layer, box)
        sparse = sparse_masks(self._mask_bytes[:, y:y + h, x:x + w])
        self._t1_index.write(sparse.indices.tobytes(), viewport=(x, y, w, h))
        self._t1_slot_weight.write(sparse.weights.tobytes(), viewport=(x, y, w, h))
        self._mark_t1_region(x, y, w, h)

    def _mark_t1_region(self, x: int, y: int, w: int, h: int) -> None:
        """A dab changed only this rectangle: the next compose redoes just that (a 4096² mask
        would otherwise be recomposed whole after every dab)."""
        if self._t1_dirty and self._t1_dirty_rect is None:
            return  # the whole texture is due anyway
        if self._t1_dirty:
            x0, y0, w0, h0 = self._t1_dirty_rect
            x1, y1 = min(x, x0), min(y, y0)
            w, h = max(x + w, x0 + w0) - x1, max(y + h, y0 + h0) - y1
            x, y = x1, y1
        self._t1_dirty_rect = (x, y, w, h)
        self._t1_dirty = True

    def set_activations(self, activations: np.ndarray) -> None:
        """Technique 1's activation vector; nothing is uploaded or recomposed if unchanged."""
        values = np.zeros(max(self._area_count, 1), np.float32)
        values[: len(activations)] = activations
        old = self._activation_values
        if np.array_equal(values, old):
            return
        self._activation_values = values
        if len(old) != len(values):
            self._upload_activations()
            return
        # recompose only where the areas whose activation changed have any mask (an animation
        # moves a few areas a frame; the whole weight texture would cost the same every time)
        boxes = self._area_boxes[np.flatnonzero(values != old)]
        boxes = boxes[boxes[:, 2] > boxes[:, 0]]
        self._upload_activations(recompose=False)
        if len(boxes):
            x0, y0 = boxes[:, :2].min(axis=0)
            x1, y1 = boxes[:, 2:].max(axis=0)
            self._mark_t1_region(int(x0), int(y0), int(x1 - x0), int(y1 - y0))

    def read_t1_weights(self) -> np.ndarray:
        """Technique 1's composed weight texture as the face shader reads it, (H, W, 4) float32,
        one weight per wrinkled map, row 0 at the top like the masks (composed first if an
        activation or a mask changed): what tests compare with the numpy reference."""
        if self._t1_dirty:
            self._compose_t1()
        w, h = self._t1_weight.size
        data = np.frombuffer(self._t1_weight.read(), np.float16).reshape(h, w, 4)
        return data.astype(np.float32)

    def set_area_maps(self, maps: np.ndarray) -> None:
        """Which wrinkled map (index) each technique-1 area reveals, in area order."""
        self._area_maps = np.asarray(maps, np.float32)
        self._upload_activations()

    def _upload_activations(self, recompose: bool = True) -> None:
        values = self._activation_values
        texels = np.zeros((len(values), 2), np.float32)
        texels[:, 0] = values
        n = min(len(values), len(self._area_maps))
        texels[:n, 1] = self._area_maps[:n]
        if self._activations is None or self._activations.width != len(values):
            if self._activations is not None:
                self._activations.release()
            self._activations = self.ctx.texture((len(values), 1), 2, dtype="f4")
            self._activations.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._activations.write(texels.tobytes())
        if recompose:
            self._t1_dirty = True
            self._t1_dirty_rect = None

    def set_wdv(self, slots: WdvSlots, expression_factor: float = 1.0,
                scale_free: bool = True) -> None:
        """Technique 2 slots per welded vertex (see ``WdvSetup.pack_slots``)."""
        weld = self.mesh.weld
        packed = np.hstack([slots.dirs.reshape(len(slots.dirs), -1)[weld],
                            slots.cones[weld], slots.maps[weld]]).astype("f4")
        self._wdv.write(packed.tobytes())
        in_use = (slots.dirs[..., 3] > 0) & (slots.cones > 0)
        self._split.set_slots(in_use.any(axis=1)[weld])
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
            from studio.core.errors import RenderError

            v = self.ctx.version_code
            raise RenderError(f"relief 'displace' needs OpenGL 4.0 (tessellation shaders); "
                              f"this driver offers {v // 100}.{v % 100 // 10}; use relief "
                              "'parallax' instead")
        if relief != "off":
            self._ensure_relief()
        if settings.tangent_frame != self._deform.frame:  # the vertex buffer's tangents follow
            self._deform.set_frame(settings.tangent_frame)
            self._geometry_dirty = True
        if self._geometry_dirty:
            start = time.perf_counter()
            attributes = self._deform.update(self._positions)
            self.last_deform_ms = (time.perf_counter() - start) * 1000.0
            lo, hi = self._deform.last_span  # only the render vertices this pose moved
            if hi > lo:
                self._dynamic.write(attributes[lo:hi], offset=lo * attributes.strides[0])
            self._geometry_dirty = False
        ctx = self.ctx
        # set every piece of state the passes rely on: the viewport's overlays may leave any on
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.wireframe = False
        composed = settings.t1_mode == "composed" or relief == "displace"  # tessellation reads it
        if settings.technique == "t1" and composed and self._t1_dirty:
            self._compose_t1()
        if settings.technique == "strain":
            self._update_strain(settings.strain_full_at)
        viewport = viewport or (0, 0, *fbo.size)
        fbo.use()
        ctx.viewport = viewport
        ctx.scissor = viewport
        fbo.clear(*settings.background, 1.0, depth=1.0)
        ctx.scissor = None
        ctx.enable(moderngl.DEPTH_TEST)
        view = camera.view_matrix()
        proj = camera.projection_matrix(viewport[2] / max(viewport[3], 1))
        self._bind_textures()
        self._split.set_view(view)
        if relief == "displace":  # one program: the tessellated and flat edges would not meet
            self._split.order(None)
            ctx.patch_vertices = 3
            self._vao(self._face_program(settings, view, proj, viewport)).render(moderngl.PATCHES)
        else:
            self._draw_split(settings, view, proj, viewport)
        if settings.wireframe:
            self._draw_wireframe(view, proj)

    def _face_program(self, settings: RenderSettings, view: np.ndarray, proj: np.ndarray,
                      viewport: tuple[int, int, int, int]) -> tuple[str, ...]:
        """The face program for ``settings``, its uniforms set; returns its key."""
        key = (*settings.program_key(), f"WRINKLE_MAPS {self._map_count}")
        self._set_uniforms(self._program(key), view, proj, settings, viewport)
        return key

    def _draw_split(self, settings: RenderSettings, view: np.ndarray, proj: np.ndarray,
                    viewport: tuple[int, int, int, int]) -> None:
        """The triangles that can show wrinkles with the technique's program, the rest with
        the technique-off program (the same picture there, without the wrinkle shading)."""
        count = self._split.order(self._wrinkled_triangles(settings) if self.split_draws
                                  else None)
        total = len(self.mesh.triangles)
        if count:
            key = self._face_program(settings, view, proj, viewport)
            self._vao(key).render(moderngl.TRIANGLES, vertices=3 * count)
        if count < total:
            key = self._face_program(replace(settings, technique="none"), view, proj, viewport)
            self._vao(key).render(moderngl.TRIANGLES, vertices=3 * (total - count),
                                  first=3 * count)

    def _wrinkled_triangles(self, settings: RenderSettings) -> np.ndarray | None:
        """(T,) the triangles whose wrinkle weight can be above 0 this frame (None: all)."""
        technique = settings.technique
        if technique == "t1":
            return self._split.for_areas(self._activation_values)
        if technique == "t2":
            return self._split.for_slots(self._positions_version, lambda: moved(
                self._positions, self.mesh.rest)[self.mesh.weld])
        if technique == "strain":
            return self._split.for_weights(self._strain_key, lambda: self._render_strain)
        return None

    def _update_strain(self, full_at: float) -> None:
        """Compression weights for this frame's pose (only when the pose or gain changed)."""
        key = (self._positions_version, full_at)
        if key != self._strain_key:
            weights = self._strain_field.weights(self._positions, full_at)
            self._render_strain = weights[self.mesh.weld].astype("f4")
            self._strain.write(self._render_strain.tobytes())
            self._strain_key = key

    def _compose_t1(self) -> None:
        """Σ mask·activation into the weight texture, from each texel's strongest areas."""
        prog = self._program(("compose",))
        self._bind_textures()
        for name in ("t1_index", "t1_slot_weight", "activations"):
            prog[f"u_{name}"].value = _UNIT[name]
        # the weights are written, not blended: an overlay drawn before may have left blending on
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        self._t1_fbo.use()
        self.ctx.viewport = (0, 0, *self._t1_weight.size)
        self.ctx.scissor = self._t1_dirty_rect
        self._vao(("compose",)).render(moderngl.TRIANGLES, vertices=3)
        self.ctx.scissor = None
        self._t1_dirty = False
        self._t1_dirty_rect = None

    def _draw_wireframe(self, view: np.ndarray, proj: np.ndarray) -> None:
        prog = self._program(("wire",))
        self._write_matrix(prog, "u_view", view)
        self._write_matrix(prog, "u_proj", proj)
        prog["u_colour"].value = (0.05, 0.05, 0.05, 0.55)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.wireframe = True
        self.ctx.polygon_offset = (-1.0, -1.0)
        self._vao(("wire",)).render(moderngl.TRIANGLES)
        self.ctx.polygon_offset = (0.0, 0.0)
        self.ctx.wireframe = False
        self.ctx.disable(moderngl.BLEND)

    def _program(self, key: tuple[str, ...]) -> moderngl.Program:
        """Programs by their defines; ("wire",) and ("compose",) are the helper passes."""
        if key not in self._programs:
            files = {("wire",): ("wire.vert", "wire.frag"),
                     ("compose",): ("t1_compose.vert", "t1_compose.frag")}
            vert, frag = files.get(key, ("face.vert", "face.frag"))
            defines = () if key in files else key
            tess = ("face.tesc", "face.tese") if "RELIEF_DISPLACE" in key else (None, None)
            self._programs[key] = build_program(self.ctx, vert, frag, defines, *tess)
        return self._programs[key]

    def _vao(self, key: tuple[str, ...]) -> moderngl.VertexArray:
        if key not in self._vaos:
            if key == ("compose",):
                self._vaos[key] = self.ctx.vertex_array(self._program(key), [])
                return self._vaos[key]
            content = [
                (self._dynamic, "3f 3f 4f", "in_position", "in_normal", "in_tangent"),
                (self._static, "2f 3f", "in_uv", "in_rest"),
                (self._skin, "1f", "in_skin"),
                (self._wdv, "16f 4f 4f", "in_wdv", "in_cone", "in_slot_map"),
                (self._strain, "1f", "in_strain"),
            ]
            self._vaos[key] = self.ctx.vertex_array(
                self._program(key), content, self._ibo, index_element_size=4, skip_errors=True)
        return self._vaos[key]

    @staticmethod
    def _write_matrix(prog: moderngl.Program, name: str, matrix: np.ndarray) -> None:
        prog[name].write(matrix.T.astype("f4").tobytes())

    def _set_uniforms(self, prog: moderngl.Program, view: np.ndarray, proj: np.ndarray,
                      settings: RenderSettings, viewport: tuple[int, int, int, int]) -> None:
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
            "u_relief_depth": settings.relief_depth,
            "u_uv_per_unit": self._uv_per_unit,
            "u_viewport_size": (float(viewport[2]), float(viewport[3])),
            "u_tess_pixels": TESS_PIXELS,
            "u_tess_max": TESS_MAX,
            "u_relief_texels_per_unit": self._uv_per_unit * max(
                self._relief.size if self._relief is not None else (1, 1)),
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
        self._t1_weight.use(_UNIT["t1_weight"])
        self._t1_index.use(_UNIT["t1_index"])
        self._t1_slot_weight.use(_UNIT["t1_slot_weight"])
        if self._relief is not None:
            self._relief.use(_UNIT["relief"])

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
        for tex in [*self._textures.values(), self._masks, self._activations, self._t1_index,
                    self._t1_slot_weight, self._t1_weight, self._t1_fbo, self._relief]:
            if tex is not None:
                tex.release()
