"""From the view model to one draw's settings: the single place where a ``ViewSettings`` field
reaches the renderer, for the viewport, the animation export, the command line and the bench."""

from __future__ import annotations

from studio.core.project.view_settings import ViewSettings
from studio.render.renderer import RenderSettings


def render_settings(view: ViewSettings, *, technique: str | None = None,
                    relief: str | None = None) -> RenderSettings:
    """The renderer's settings for a view; ``technique`` draws another technique with the same
    view (a column of the split view), ``relief`` replaces the relief with what the context can
    draw (displacement needs OpenGL 4.0)."""
    return RenderSettings(technique=technique or view.technique, view=view.debug_view,
                          wireframe=view.wireframe, light_dir=view.light_dir(),
                          blend=view.blend, relief=relief or view.relief,
                          relief_depth=view.relief_depth, tangent_frame=view.tangent_frame)
