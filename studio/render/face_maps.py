"""The face's texture maps on the GPU: diffuse, the neutral and first wrinkled normal maps packed
into one texture (one fetch blends them), any further wrinkled maps in an array read only
where they show, and, for a face that has them, each wrinkled map's colour and cavity
(skin_tone.py) in one more array, a layer per map."""

from __future__ import annotations

import moderngl
import numpy as np

from studio.core.files.errors import RenderError
from studio.core.wrinkles.skin_tone import pack_tone
from studio.core.wrinkles.textures import FaceTextures, pack_more_maps, pack_normal_maps
from studio.render.gl_info import ANISOTROPY
from studio.render.programs import UNITS


def texture_dtype(image: np.ndarray) -> str:
    return "nu2" if image.dtype == np.uint16 else "f1"


def check_gl_size(ctx: moderngl.Context, what: str, width: int, height: int,
                  advice: str) -> None:
    """Refuse, with a message naming the map, a texture larger than this GPU can hold (the
    driver would fail on it, or crash)."""
    max_size = int(ctx.info.get("GL_MAX_TEXTURE_SIZE") or 0)
    if max_size and max(width, height) > max_size:
        raise RenderError(f"{what} {width}×{height} pixels, but this GPU's largest texture is "
                          f"{max_size}×{max_size}; {advice}")


def raise_if_out_of_memory(ctx: moderngl.Context) -> None:
    if ctx.error == "GL_OUT_OF_MEMORY":
        raise MemoryError("GL_OUT_OF_MEMORY")


class FaceMaps:
    """Uploads a project's maps; a failed upload keeps the previous maps drawing."""

    def __init__(self, ctx: moderngl.Context, anisotropy: float = ANISOTROPY) -> None:
        """``anisotropy``: the diffuse and first normal maps' (see ``gl_info.map_anisotropy``)."""
        self.ctx = ctx
        self.anisotropy = anisotropy
        self.textures: dict[str, moderngl.Texture | moderngl.TextureArray] = {}
        self.map_count = 1  # wrinkled maps of the current textures (compiled into the program)
        self.has_tone = False  # whether any has a colour or cavity map (the "tone" array)

    def set_textures(self, textures: FaceTextures) -> None:
        named = {"diffuse": textures.diffuse, "neutral normal": textures.normal_neutral,
                 **{f"wrinkled normal ('{k}')": v for k, v in textures.wrinkle_maps.items()}}
        for name, image in named.items():
            h, w = image.shape[:2]
            check_gl_size(self.ctx, f"the {name} map is", w, h, "use a smaller map")
        created: dict[str, moderngl.Texture | moderngl.TextureArray] = {}
        try:  # all new textures first: on failure the old ones still draw
            normals = pack_normal_maps(textures.normal_neutral, textures.normal_wrinkled)
            images = {"diffuse": textures.diffuse, "normals": normals,
                      "more_maps": pack_more_maps(textures, normals)}
            if textures.has_tone:
                images["tone"] = pack_tone(textures)
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            for name, image in images.items():
                created[name] = tex = self._texture(image)
                tex.build_mipmaps()
                tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
                # further wrinkled maps: trilinear only. A software renderer fetches them on
                # every pixel (it runs both sides of a branch), and 8x anisotropic fetches of
                # them doubled the cost of a frame; the first map keeps full filtering
                tex.anisotropy = 1.0 if name == "more_maps" else self.anisotropy
                tex.repeat_x = tex.repeat_y = False
                raise_if_out_of_memory(self.ctx)
        except (moderngl.Error, MemoryError) as exc:
            for tex in created.values():
                tex.release()
            size = "×".join(str(v) for v in textures.diffuse.shape[1::-1])
            raise RenderError(f"the GPU cannot hold the texture maps ({size} pixels; "
                              f"{exc or type(exc).__name__}); use smaller maps") from None
        for name in {*created, "tone"}:
            old = self.textures.pop(name, None)
            if old is not None:
                old.release()
            if name in created:
                self.textures[name] = created[name]
        self.map_count = len(textures.wrinkle_maps)
        self.has_tone = "tone" in created

    def _texture(self, image: np.ndarray) -> moderngl.Texture | moderngl.TextureArray:
        if image.ndim == 4:  # layers of a texture array
            n, h, w, components = image.shape
            return self.ctx.texture_array((w, h, n), components, image.tobytes(),
                                          dtype=texture_dtype(image))
        h, w, components = image.shape
        return self.ctx.texture((w, h), components, image.tobytes(), dtype=texture_dtype(image))

    def bind(self) -> None:
        for name, tex in self.textures.items():
            tex.use(UNITS[name])

    def release(self) -> None:
        for tex in self.textures.values():
            tex.release()
        self.textures.clear()
