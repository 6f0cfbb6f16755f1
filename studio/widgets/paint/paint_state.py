"""The brush and the area being painted: tool options shared by the Areas panel, the UV canvas
and the viewport's paint tool (an image editor's tool options bar), not project data.

Why its own module: three views read it, and none of them should have to import the others.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QObject, QSettings, Signal

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.brush import Brush, Mirror, UvMirror
from studio.core.wrinkles.surface_mirror import SurfaceMirror
from studio.widgets.paint.areas_model import brush_setting, scaled_radius

MIRROR_MODES = {
    "off": ("Off", "Dabs land only under the brush"),
    "uv": ("In UV (u → 1 − u)", "Every dab also lands mirrored across the UV square's middle: "
           "right when the UV layout is itself symmetric"),
    "mesh": ("Through the mesh (x → −x)", "Every dab also lands at the mirrored point of the "
             "face's surface (across x = 0), whatever the UV layout"),
}
BRUSH_SETTINGS = ("radius", "hardness", "opacity", "flow")  # remembered between sessions


class PaintState(QObject):
    """The brush and the area being painted: tool options, not project data."""

    changed = Signal()
    activeChanged = Signal(int)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.brush = Brush()
        self.active = -1
        self.mirror = "off"  # a key of MIRROR_MODES
        self.overlap = False
        self._surface: SurfaceMirror | None = None
        # (model axis, position) of the face's left–right symmetry plane, and the skin's
        # triangles (the mirror's only targets); the mask tools point these at the document
        self.mirror_plane: Callable[[], tuple[int, float]] = lambda: (0, 0.0)
        self.skin_triangles: Callable[[], np.ndarray | None] = lambda: None

    def set_brush(self, **values) -> None:
        for key, value in values.items():
            setattr(self.brush, key, value)
        self.changed.emit()

    def set_erase(self, erase: bool) -> None:
        self.set_brush(erase=bool(erase))

    def scale_radius(self, factor: float) -> None:
        self.set_brush(radius=scaled_radius(self.brush.radius, factor))

    def set_active(self, index: int) -> None:
        if index != self.active:
            self.active = index
            self.activeChanged.emit(index)

    def set_option(self, **values) -> None:
        for key, value in values.items():
            setattr(self, key, value)
        self.changed.emit()

    def set_mirror(self, mode: str) -> None:
        if mode not in MIRROR_MODES:
            raise ValueError(f"unknown mirror mode {mode!r}")
        self.set_option(mirror=mode)

    # --- mirrors -------------------------------------------------------------------------------
    def surface_mirror(self, mesh: FaceMesh) -> SurfaceMirror:
        """The mirror through this mesh, built once per mesh (its lookups are precomputed)."""
        axis, plane = self.mirror_plane()
        skin = self.skin_triangles()
        if self._surface is None or self._surface.mesh is not mesh or \
                (self._surface.axis, self._surface.plane) != (axis, plane) or \
                self._surface.skin is not skin:
            self._surface = SurfaceMirror(mesh, axis, plane, skin)
        return self._surface

    def stroke_mirror(self, mesh: FaceMesh) -> Mirror | None:
        """What a new stroke mirrors its dabs with, in the current mode."""
        if self.mirror == "uv":
            return UvMirror()
        if self.mirror == "mesh":
            return self.surface_mirror(mesh)
        return None

    # --- remembered between sessions -----------------------------------------------------------
    def restore(self, settings: QSettings) -> None:
        """The brush as the user last left it; unreadable values keep the defaults."""
        for key in BRUSH_SETTINGS:
            default = getattr(self.brush, key)
            setattr(self.brush, key,
                    brush_setting(key, settings.value(f"brush/{key}", default), default))
        mode = str(settings.value("brush/mirror", self.mirror))
        self.mirror = mode if mode in MIRROR_MODES else self.mirror
        self.changed.emit()

    def save(self, settings: QSettings) -> None:
        for key in BRUSH_SETTINGS:
            settings.setValue(f"brush/{key}", float(getattr(self.brush, key)))
        settings.setValue("brush/mirror", self.mirror)
