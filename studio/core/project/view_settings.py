"""How a face is looked at — the one view model every renderer client shares.

The viewport, the animation export, ``wrinkle-studio render`` and the benchmark all draw from a
``ViewSettings``; the renderer's per-draw ``RenderSettings`` is made from it in one place
(``studio.render.settings.render_settings``), so no client can forget a field (an exported
animation once ignored the blend mode and the relief because its dialog copied fields by hand).
It is saved with the project (``project.view["view"]``) but is not an edit: changing it is not
undoable, like turning the camera.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from studio.core.mesh.tangent_frames import DEFAULT_TANGENT_FRAME, TANGENT_FRAMES
from studio.core.wrinkles.relief import DEFAULT_RELIEF_DEPTH
from studio.core.wrinkles.skin_light import LOOKS, RIG_NAMES
from studio.core.wrinkles.techniques import TECHNIQUES

# heat: the wrinkle weight; heat-shows: the weight times how much the revealed wrinkled map
# differs from the neutral one there (an area on a flat part of its map is hot in one, cold in
# the other). The order is face.frag's u_view_mode.
DEBUG_VIEWS = ("shaded", "heat", "normals", "uv", "heat-shows")
BLENDS = ("colour", "normal")  # colour: the thesis's mix of two shadings; normal: light once
RELIEFS = ("off", "displace", "parallax")  # displace: tessellation (OpenGL 4.0); parallax: 3.3

CHOICES: dict[str, tuple[str, ...]] = {"technique": tuple(TECHNIQUES), "debug_view": DEBUG_VIEWS,
                                       "blend": BLENDS, "relief": RELIEFS,
                                       "tangent_frame": TANGENT_FRAMES, "look": LOOKS,
                                       "light_rig": RIG_NAMES}


@dataclass(frozen=True)
class ViewSettings:
    technique: str = "t2"  # a key of studio.core.wrinkles.techniques.TECHNIQUES
    split: bool = False  # t1 | t2 | automatic side by side (the viewport only)
    debug_view: str = "shaded"  # shaded | heat | normals | uv | heat-shows
    wireframe: bool = False
    blend: str = "colour"
    relief: str = "off"
    relief_depth: float = DEFAULT_RELIEF_DEPTH  # model units of the deepest wrinkle
    light_azimuth: float = 30.0  # degrees, camera-relative: 0 = from the viewer, + = from the right
    light_elevation: float = 35.0  # degrees above the view direction
    # the frame the normal maps are read in (core/tangent_frames.py): it is the project's, as
    # the baker bakes and the glTF export writes TANGENT in it too
    tangent_frame: str = DEFAULT_TANGENT_FRAME
    # clay: the first shading (common.glsl); skin: skin.glsl under the rig (core/skin_light.py)
    look: str = "clay"
    light_rig: str = "studio"  # studio | overcast | raking: the skin look's lights

    def __post_init__(self) -> None:
        for name, allowed in CHOICES.items():
            if getattr(self, name) not in allowed:
                raise ValueError(f"unknown {name.replace('_', ' ')} '{getattr(self, name)}' "
                                 f"(choose from {', '.join(allowed)})")
        if not 0.0 <= self.relief_depth < math.inf:
            raise ValueError(f"the relief depth must be 0 or more, got {self.relief_depth}")
        for name in ("light_azimuth", "light_elevation"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"the {name.replace('_', ' ')} must be a finite number")

    def light_dir(self) -> tuple[float, float, float]:
        """Unit vector toward the light, in view space."""
        az, el = math.radians(self.light_azimuth), math.radians(self.light_elevation)
        return (math.sin(az) * math.cos(el), math.sin(el), math.cos(az) * math.cos(el))

    def with_changes(self, **changes: Any) -> ViewSettings:
        """A copy with some fields changed (unknown names raise AttributeError)."""
        for key in changes:
            if key not in self.field_names():
                raise AttributeError(key)
        return replace(self, **changes)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> ViewSettings:
        """Settings from a project file; a value of the wrong type or an unknown choice (a
        damaged or newer file) falls back to the default instead of breaking the viewport."""
        defaults = cls()
        values = {}
        for f in fields(cls):
            if f.name not in data:
                continue
            value, default = data[f.name], getattr(defaults, f.name)
            if isinstance(default, float) and isinstance(value, int | float) \
                    and not isinstance(value, bool):
                value = float(value)
            if type(value) is not type(default) or (
                    f.name in CHOICES and value not in CHOICES[f.name]):
                continue
            if isinstance(value, float) and not (math.isfinite(value) and (
                    f.name != "relief_depth" or value >= 0.0)):
                continue
            values[f.name] = value
        return cls(**values)


def saved_view(project_view: dict) -> ViewSettings:
    """The view settings a project saved (``project.view``), defaults where it saved none."""
    saved = project_view.get("view", {})
    return ViewSettings.from_dict(saved if isinstance(saved, dict) else {})
