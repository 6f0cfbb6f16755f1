"""Technique-2 authoring in the window: the dock, the select and comb tools and the overlay,
wired to the document. ``studio.widgets.wdv.panel.install_wdv_tools(window)`` is the one call
the main window makes.

``WdvTools`` holds only view state (the current area, tool options) and caches derived from the
document (posed positions, normals, edges, the mirror map), refreshed when its signals say so.
"""

from __future__ import annotations

import time

import numpy as np
from PySide6.QtCore import QObject, Signal

from studio.core.mesh import selection as sel
from studio.core.mesh.geometry import vertex_normals
from studio.core.wrinkles.colours import SELECTION
from studio.core.wrinkles.wdv import WdvArea, WdvSetup
from studio.render.wdv_overlay import WdvOverlay, vector_lines
from studio.widgets.document import Document
from studio.widgets.wdv.comb_tool import CombTool
from studio.widgets.wdv.select_tool import CLICK_RADIUS, SelectTool, pick_vertex

GLYPH_FRACTION = 0.02  # vector glyph length, as a fraction of the face's size
OTHERS_OPACITY = 0.25  # the other areas' vectors, when all are asked for


class WdvTools(QObject):
    currentAreaChanged = Signal()
    timing = Signal(str, float)  # what, milliseconds: for measurements
    said = Signal(str)  # what a gesture did, in words (the status bar and the viewport say it)

    def __init__(self, doc: Document, viewport) -> None:
        super().__init__(viewport)
        self.doc = doc
        self.viewport = viewport
        self.overlay = WdvOverlay()
        self.tool = SelectTool(self)
        self.comb = CombTool(self)  # drawing directions (C): the panel's Comb controls set it
        self.select_through = False
        self.cone_paint_value = 8.0  # degrees the cone brush paints (Ctrl paints "area's angle")
        # vectors follow the task: the current area's while its panel is open, the others
        # (faint) only when asked; a face with a dozen areas is otherwise all needles
        self.panel_open = False
        self.all_areas = False
        # the selected vertices are drawn only while selecting (Blender shows them in edit mode
        # only): afterwards the dots would cover the wrinkles the selection was made for
        self.selecting = False
        self._posed: np.ndarray | None = None
        self._normals: np.ndarray | None = None
        self._edges: np.ndarray | None = None
        self._mirror: np.ndarray | None = None
        doc.projectReplaced.connect(self._project_changed)
        doc.posesChanged.connect(self._project_changed)
        doc.poseWeightsChanged.connect(self._pose_changed)
        doc.wdvChanged.connect(self._wdv_changed)
        doc.selectionChanged.connect(self._selection_changed)
        doc.viewChanged.connect(self._view_changed)
        doc.currentWdvAreaChanged.connect(self._current_changed)
        self._project_changed()

    # --- the current area (view state) ---------------------------------------------------------
    @property
    def current_area(self) -> WdvArea | None:
        """The document's current area (it belongs there: undo and redo restore it)."""
        return self.doc.current_wdv_area

    def set_current_area(self, area: WdvArea | None) -> None:
        self.doc.set_current_wdv_area(area)

    def _current_changed(self) -> None:
        self._selection_changed()
        self._update_vectors()
        self.currentAreaChanged.emit()

    def set_panel_open(self, on: bool) -> None:
        """The wrinkle vectors panel shown (or hidden behind another tab)."""
        self.panel_open = on
        self._update_vectors()

    def set_all_areas(self, on: bool) -> None:
        """Every area's vectors, the current one's bright and the others faint."""
        self.all_areas = on
        self._update_vectors()

    # --- caches from the document --------------------------------------------------------------
    def _project_changed(self) -> None:
        mesh = self.doc.project.mesh
        self._edges, self._mirror = None, None
        self.overlay.set_mesh(mesh.welded_triangles)
        self._pose_changed()
        self._wdv_changed()
        self._selection_changed()

    def _view_changed(self) -> None:
        """The split view draws each half with its own aspect: the overlay (drawn over the
        whole viewport) would not line up, so it waits for the single view."""
        self.overlay.visible = not self.doc.view.split

    def _pose_changed(self) -> None:
        self._posed, self._normals = None, None
        self.overlay.set_positions(self.posed())
        self._update_vectors()

    def _wdv_changed(self) -> None:
        self._update_vectors()
        self._selection_changed()  # the current area's colour may have changed
        self.currentAreaChanged.emit()

    def say(self, text: str) -> None:
        self.said.emit(text)

    def set_selecting(self, on: bool) -> None:
        """The select tool took (or left) the viewport: show (or hide) the selection's dots."""
        self.selecting = on
        self._selection_changed()

    def _selection_changed(self) -> None:
        # selected vertices in the selection's own colour (Blender's orange), never an area's:
        # the vectors are drawn in the area's, and the two must be told apart
        shown = np.flatnonzero(self.doc.selection) if self.selecting else np.zeros(0, np.int64)
        self.overlay.set_selection(shown, SELECTION)
        self.viewport.update()

    def _update_vectors(self) -> None:
        """The vectors the overlay draws: none while the panel is closed, else the current
        area's, and the others faint when all are asked for."""
        lo, hi = self.doc.project.mesh.bounds()
        length = GLYPH_FRACTION * float(np.linalg.norm(hi - lo))
        wdv = self.doc.project.wdv
        if not self.panel_open:
            wdv = WdvSetup([])
        current = self.current_area
        self.overlay.set_vectors(*vector_lines(
            self.posed(), wdv, length, only=current.name if current is not None else "",
            others=OTHERS_OPACITY if self.all_areas else None))
        self.viewport.update()

    def posed(self) -> np.ndarray:
        """Welded positions at the current pose weights (what the viewport shows)."""
        if self._posed is None:
            self._posed = self.doc.posed_positions()
        return self._posed

    def normals(self) -> np.ndarray:
        if self._normals is None:
            self._normals = vertex_normals(self.posed(), self.doc.project.mesh.welded_triangles)
        return self._normals

    def edges(self) -> np.ndarray:
        if self._edges is None:
            self._edges = sel.edges(self.doc.project.mesh.welded_triangles)
        return self._edges

    def mirror_index(self) -> np.ndarray:
        if self._mirror is None:
            self._mirror = sel.mirror_map(self.doc.project.mesh.rest, *self.doc.mirror_plane())
        return self._mirror

    # --- what the select tool asks ---------------------------------------------------------------
    def screen_view(self) -> sel.ScreenView:
        """Every vertex projected, with its visibility: once per gesture."""
        start = time.perf_counter()
        vp = self.viewport
        w, h = vp.pixel_size()
        cam = self.doc.camera
        posed = self.posed()
        pixels, depth = cam.project(posed, w, h)
        depth_buffer = None
        if vp.ctx is not None:
            vp.makeCurrent()
            try:
                depth_buffer = self.overlay.read_depth(vp.ctx, cam, w, h)
            finally:
                vp.doneCurrent()
        near, far = cam.clip_planes()
        view = sel.screen_view(pixels, depth, posed, self.normals(), cam.eye(), depth_buffer,
                               near, far, tolerance=0.01 * cam.radius)
        self.timing.emit("screen view", (time.perf_counter() - start) * 1000.0)
        return view

    def pick(self, x: float, y: float) -> int | None:
        """The vertex under a pixel: exact ray cast, or with "select through" the nearest
        projected vertex (so hidden ones can be clicked)."""
        vp = self.viewport
        w, h = vp.pixel_size()
        cam = self.doc.camera
        if self.select_through:
            pixels, depth = cam.project(self.posed(), w, h)
            facing = np.ones(len(pixels), bool)
            view = sel.ScreenView(pixels, depth, facing, facing)
            return sel.nearest_in_radius(view, x, y, CLICK_RADIUS, through=True)
        origin, direction = cam.ray(x, y, w, h)
        return pick_vertex(self.posed(), self.doc.project.mesh.welded_triangles, origin,
                           direction)
