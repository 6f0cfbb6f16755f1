"""The relief pass's input: a wrinkle-height texture integrated from the normal maps
(studio/core/wrinkles/relief.py), made when a relief first draws — a fraction of a second at
1024², never per frame — and again only when the maps change."""

from __future__ import annotations

import moderngl
import numpy as np

from studio.core.files.errors import RenderError
from studio.core.wrinkles.relief import maps_digest, relief_image
from studio.render.face_maps import raise_if_out_of_memory
from studio.render.programs import UNITS


class ReliefPass:
    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.texture: moderngl.Texture | None = None
        self._due: tuple[np.ndarray, list[np.ndarray]] | None = None  # maps to make it from
        self._digest = b""  # of the maps the texture was made from

    def set_maps(self, neutral: np.ndarray, wrinkled: list[np.ndarray]) -> None:
        """The heights follow these maps; nothing is computed until a relief draws."""
        self._due = (neutral, wrinkled)

    def prepare(self) -> None:
        if self._due is None:
            return
        digest = maps_digest(*self._due)
        if self.texture is not None and digest == self._digest:
            self._due = None  # the same maps again (a project reloaded, say)
            return
        image = relief_image(*self._due)
        h, w = image.shape[:2]
        try:
            self.ctx.error  # noqa: B018 - reading it clears an earlier, unrelated error flag
            tex = self.ctx.texture((w, h), 4, image.tobytes(), dtype="f2")
            try:
                raise_if_out_of_memory(self.ctx)
            except MemoryError:
                tex.release()
                raise
        except (moderngl.Error, MemoryError) as exc:
            raise RenderError(f"the GPU cannot hold the wrinkle heights ({w}×{h} pixels; "
                              f"{exc or type(exc).__name__}); use smaller maps") from None
        tex.build_mipmaps()
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        if self.texture is not None:
            self.texture.release()
        self.texture = tex
        self._due = None
        self._digest = digest

    @property
    def texels(self) -> int:
        """The height texture's larger side (1 before it exists)."""
        return max(self.texture.size) if self.texture is not None else 1

    def bind(self) -> None:
        if self.texture is not None:
            self.texture.use(UNITS["relief"])

    def release(self) -> None:
        if self.texture is not None:
            self.texture.release()
            self.texture = None
