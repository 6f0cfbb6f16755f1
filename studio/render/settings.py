"""One draw's settings (``RenderSettings``), and the view model turned into them: the single
place where a ``ViewSettings`` field reaches the renderer, for the viewport, the animation
export, the command line and the bench."""

from __future__ import annotations

from dataclasses import dataclass

from studio.core.formats.web_export import WebLook
from studio.core.mesh.tangent_frames import DEFAULT_TANGENT_FRAME, TANGENT_FRAMES
from studio.core.project.view_settings import BLENDS, DEBUG_VIEWS, RELIEFS, ViewSettings
from studio.core.wrinkles.relief import DEFAULT_RELIEF_DEPTH
from studio.core.wrinkles.skin_light import LOOKS, RIG_NAMES, light_rig
from studio.core.wrinkles.strain import DEFAULT_FULL_AT
from studio.core.wrinkles.techniques import TECHNIQUES, WRINKLE_TECHNIQUES, shader_define

VIEW_MODES = {name: i for i, name in enumerate(DEBUG_VIEWS)}  # u_view_mode in face.frag
T1_MODES = ("composed", "direct")


@dataclass
class RenderSettings:
    technique: str = "t2"  # flat | none | t1 | t2 | strain (automatic, from skin compression)
    view: str = "shaded"  # shaded | heat | normals | uv | heat-shows (DEBUG_VIEWS)
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
    look: str = "clay"  # clay (common.glsl's light) | skin (skin.glsl under ``light_rig``)
    light_rig: str = "studio"  # studio | overcast | raking (core/wrinkles/skin_light.py)

    def __post_init__(self) -> None:
        for value, allowed, what in ((self.technique, tuple(TECHNIQUES), "technique"),
                                     (self.view, tuple(VIEW_MODES), "view"),
                                     (self.blend, BLENDS, "blend"),
                                     (self.t1_mode, T1_MODES, "technique-1 mode"),
                                     (self.relief, RELIEFS, "relief"),
                                     (self.tangent_frame, TANGENT_FRAMES, "tangent frame"),
                                     (self.look, LOOKS, "look"),
                                     (self.light_rig, RIG_NAMES, "light rig")):
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
        if self.look == "skin":
            defines.append("SKIN")
        if self.blend == "normal":
            defines.append("BLEND_NORMALS")
        if self.technique == "t1" and self.t1_mode == "direct":
            defines.append("T1_DIRECT")
        if self.active_relief != "off":
            defines.append(f"RELIEF_{self.active_relief.upper()}")
        return tuple(defines)


def render_settings(view: ViewSettings, *, technique: str | None = None,
                    relief: str | None = None) -> RenderSettings:
    """The renderer's settings for a view; ``technique`` draws another technique with the same
    view (a column of the split view), ``relief`` replaces the relief with what the context can
    draw (displacement needs OpenGL 4.0)."""
    return RenderSettings(technique=technique or view.technique, view=view.debug_view,
                          wireframe=view.wireframe, light_dir=view.light_dir(),
                          blend=view.blend, relief=relief or view.relief,
                          relief_depth=view.relief_depth, tangent_frame=view.tangent_frame,
                          look=view.look, light_rig=view.light_rig)


def web_look(view: ViewSettings) -> WebLook:
    """The light, blend and tangent frame a view draws with, for the web page (core's page
    writer cannot read the renderer's settings): the command line's default view, or the
    studio's own when the page is exported from its window, so the page shows what was seen."""
    settings = render_settings(view)
    rig = light_rig(settings.light_rig, settings.light_dir) if settings.look == "skin" else None
    return WebLook(light_dir=settings.light_dir, ambient=settings.ambient,
                   specular=settings.specular, shininess=settings.shininess,
                   background=settings.background, blend=settings.blend,
                   tangent_frame=settings.tangent_frame, rig=rig)
