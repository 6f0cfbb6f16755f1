"""Painting on the face in the 3D viewport: left-drag lays brush dabs into the active area's mask
at the UV of the surface under the cursor, on the posed face as it is drawn.

Each cursor position is a ray against the posed triangles (studio.core.mesh.picking); the hit's
barycentric coordinates give its UV, and the dab lands there with the panel's brush (radius in
mask pixels). Between two hits in the same UV chart the stroke is continuous (dabs spaced along
the UV path). Across a UV seam: when the hit triangle touches a seam vertex, the same 3D point is
also expressed in the neighbouring chart (barycentric coordinates extrapolated on a triangle of
that chart at the shared vertex) and a dab lands there too, so a stroke over the seam paints
both sides; a jump between charts restarts the stroke's spacing instead of drawing a line
across the UV layout.

While the tool is on, the brush's footprint follows the mouse over the face (BrushCursor, a
QPainter layer over the viewport: moving it never re-renders the face), with a dashed ring where
the mirror will paint when a mirror mode is on.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QMouseEvent

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.picking import Hit, ray_triangles
from studio.core.wrinkles.brush import Stroke, union
from studio.core.wrinkles.surface_mirror import SeamMap, SurfaceMirror, footprint_ring
from studio.widgets.document import Document
from studio.widgets.paint.brush_cursor import BrushCursor, Ring
from studio.widgets.paint.edits import PaintSession, _announce_region
from studio.widgets.paint.paint_state import PaintState

__all__ = ["FacePaintTool", "SeamMap"]


class FacePaintTool:
    """The viewport tool (see Viewport.set_tool): press/move/release paint on the surface."""

    def __init__(self, document: Document, state: PaintState, status=None) -> None:
        self.doc = document
        self.state = state
        self.status = status  # a callable(str) for hints (the status bar)
        self.on_deactivate = None  # called when the viewport drops this tool
        self.session: PaintSession | None = None
        self.cursor: BrushCursor | None = None
        self._viewport = None
        self._mouse: QPointF | None = None  # where the cursor was last seen over the viewport
        self._last_chart_uv: np.ndarray | None = None
        self._seams: tuple[FaceMesh, SeamMap] | None = None
        self._posed: tuple | None = None  # (blender, mesh, weights, positions)
        self._extra: dict[int, Stroke] = {}  # other-chart strokes of this drag, by triangle
        # the footprint follows the camera, the pose and the brush, not only the mouse
        for signal in (document.cameraChanged, document.poseWeightsChanged,
                       document.projectReplaced, document.posesChanged, state.changed):
            signal.connect(self._refresh_cursor)

    # --- picking -------------------------------------------------------------------------------
    def _positions(self, viewport) -> np.ndarray:
        """Render-vertex positions of the face as drawn (posed); blended once per pose."""
        # the document's weights, which the next frame draws (the scene takes them then)
        posed = self.doc.posed_positions()
        if self._posed is None or self._posed[0] is not posed:
            self._posed = (posed, posed[self.doc.project.mesh.weld])
        return self._posed[1]

    def pick(self, viewport, x: float, y: float) -> tuple[Hit, np.ndarray] | None:
        """(hit, positions) for a widget position, or None off the face."""
        ratio = viewport.devicePixelRatioF()
        w, h = viewport.pixel_size()
        origin, direction = self.doc.camera.ray(x * ratio, y * ratio, w, h)
        positions = self._positions(viewport)
        hit = ray_triangles(origin, direction, positions, self.doc.project.mesh.triangles)
        return None if hit is None else (hit, positions)

    def uv_at(self, viewport, x: float, y: float) -> np.ndarray | None:
        picked = self.pick(viewport, x, y)
        if picked is None:
            return None
        return self._hit_uv(picked[0])

    def _hit_uv(self, hit: Hit) -> np.ndarray:
        mesh = self.doc.project.mesh
        return hit.interpolate(mesh.uvs[mesh.triangles[hit.triangle]].astype(np.float64))

    def _to_pixels(self, uv: np.ndarray) -> tuple[float, float]:
        h, w = self.doc.project.influence.resolution
        return float(uv[0] * w), float((1.0 - uv[1]) * h)

    def _seam_map(self) -> SeamMap:
        mesh = self.doc.project.mesh
        if self._seams is None or self._seams[0] is not mesh:
            self._seams = (mesh, SeamMap(mesh))
        return self._seams[1]

    # --- gestures ------------------------------------------------------------------------------
    def press(self, viewport, event: QMouseEvent) -> None:
        areas = self.doc.project.influence.areas
        if not (0 <= self.state.active < len(areas)):
            self._say("Select or add an area in the Areas panel to paint on the face.")
            return
        self.session = PaintSession(self.doc, self.state.active, self.state.brush,
                                    self.state.stroke_mirror(self.doc.project.mesh))
        self._last_chart_uv = None
        self._extra = {}
        self._paint(self._hover(viewport, event.position()))
        event.accept()

    def move(self, viewport, event: QMouseEvent) -> None:
        picked = self._hover(viewport, event.position())
        if self.session is None or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        self._paint(picked)

    def release(self, viewport, event: QMouseEvent) -> None:
        if self.session is None:
            return
        self._paint(self._hover(viewport, event.position()))
        self.session.end()
        self.session = None
        self._extra = {}

    def deactivate(self, viewport) -> None:
        """Another tool took the viewport: finish any stroke, hide the cursor, tell the owner."""
        if self.session is not None:
            self.session.end()
            self.session = None
        self._mouse = None
        if self.cursor is not None:
            self.cursor.set_rings([])
        if self.on_deactivate is not None:
            self.on_deactivate()

    def _say(self, text: str) -> None:
        if self.status is not None:
            self.status(text)

    def _paint(self, picked: tuple[Hit, np.ndarray] | None) -> None:
        if picked is None:
            self._last_chart_uv = None  # off the face: the next hit starts afresh
            return
        hit, positions = picked
        x, y = self._to_pixels(self._hit_uv(hit))
        session = self.session
        w = self.doc.project.influence.resolution[1]
        jump = (self._last_chart_uv is None
                or np.hypot(*(np.array([x, y]) - self._last_chart_uv)) > max(
                    8 * self.state.brush.radius, 0.1 * w))
        if jump:
            session.jump(x, y)
        else:
            session.to(x, y)
        self._last_chart_uv = np.array([x, y])
        self._seam_dabs(hit, positions)

    def _seam_dabs(self, hit: Hit, positions: np.ndarray) -> None:
        """The same surface point in the other charts at a seam: a dab there too."""
        w = self.doc.project.influence.resolution[1]
        mirror = self.session.stroke.mirror
        # the surface mirror finds the other charts on its own side itself
        seam_mirror = None if isinstance(mirror, SurfaceMirror) else mirror
        touched = None
        for f, uv in self._seam_map().locations(hit.triangle, hit.point, positions,
                                                self.state.brush.radius / w):
            x, y = self._to_pixels(uv)
            stroke = self._extra.get(f)
            if stroke is None:
                stroke = self._extra[f] = Stroke(self.session.area.mask, self.session.brush,
                                                 seam_mirror)
                # share the main stroke's backup so the undo step holds every tile once
                stroke.backup = self.session.stroke.backup
                touched = union(touched, stroke.jump(x, y))
            else:
                touched = union(touched, stroke.to(x, y))
        if touched is not None:
            _announce_region(self.doc, self.session.area, touched)

    # --- the brush cursor ----------------------------------------------------------------------
    def _hover(self, viewport, pos: QPointF) -> tuple[Hit, np.ndarray] | None:
        """Pick under the mouse and show the brush's footprint there (hidden off the face)."""
        self._mouse = QPointF(pos)
        if self.cursor is None or self._viewport is not viewport:
            self._attach(viewport)
        picked = self.pick(viewport, pos.x(), pos.y())
        self.cursor.set_rings([] if picked is None else self._rings(viewport, *picked))
        return picked

    def _attach(self, viewport) -> None:
        """Make the cursor layer on this viewport."""
        if self.cursor is not None:
            self.cursor.deleteLater()
        self._viewport = viewport
        self.cursor = BrushCursor(viewport)
        self.cursor.left.connect(lambda: setattr(self, "_mouse", None))

    def _refresh_cursor(self) -> None:
        viewport = self._viewport
        if viewport is None or viewport.tool is not self or self._mouse is None:
            return
        self._hover(viewport, self._mouse)

    def _rings(self, viewport, hit: Hit, positions: np.ndarray) -> list[Ring]:
        """The footprint under the mouse, and where the mirror paints when it is on."""
        mesh = self.doc.project.mesh
        h, w = self.doc.project.influence.resolution
        radius = self.state.brush.radius
        uv = self._hit_uv(hit)
        rings = [self._ring(viewport, hit.triangle, uv, radius, positions, False)]
        mirror = self.state.stroke_mirror(mesh)
        if mirror is not None:
            owner, mirrored, scale = mirror(np.array([self._to_pixels(uv)]), (h, w), radius)
            if len(owner):  # the main image (not its copies in other charts at a seam)
                uv2 = np.array([mirrored[0, 0] / w, 1.0 - mirrored[0, 1] / h])
                tri, bary = self.state.surface_mirror(mesh).locate_uv(uv2[None],
                                                                     radius / max(w, h))
                if tri[0] >= 0 and self._visible(bary[0] @ positions[mesh.triangles[tri[0]]],
                                                 positions):
                    rings.append(self._ring(viewport, int(tri[0]), uv2, radius * scale[0],
                                            positions, True))
        return [r for r in rings if r is not None]

    def _ring(self, viewport, triangle: int, uv: np.ndarray, radius: float,
              positions: np.ndarray, mirrored: bool) -> Ring | None:
        """One footprint (outer edge and the hardness ring) in widget pixels."""
        mesh = self.doc.project.mesh
        h, w = self.doc.project.influence.resolution
        tri = mesh.triangles[triangle]
        uv_corners, corners = mesh.uvs[tri], positions[tri]
        outer = footprint_ring(uv, (radius / w, radius / h), uv_corners, corners)
        if outer is None:
            return None
        hard = min(max(self.state.brush.hardness, 0.0), 1.0) * radius
        inner = footprint_ring(uv, (hard / w, hard / h), uv_corners, corners) if hard else None
        points = outer if inner is None else np.concatenate([outer, inner])
        px, depth = self.doc.camera.project(points, *viewport.pixel_size())
        if (depth <= 0.0).any():  # (partly) behind the camera
            return None
        px = px / viewport.devicePixelRatioF()
        n = len(outer)
        return Ring(px[:n], None if inner is None else px[n:], mirrored)

    def _visible(self, point: np.ndarray, positions: np.ndarray) -> bool:
        """Whether a surface point is in sight: the ray from the eye meets no surface first."""
        camera = self.doc.camera
        eye = np.asarray(camera.eye(), np.float64)
        ray = point - eye
        distance = float(np.linalg.norm(ray))
        if distance == 0.0:
            return False
        hit = ray_triangles(eye, ray / distance, positions, self.doc.project.mesh.triangles)
        return hit is not None and hit.distance >= distance - 0.01 * camera.radius
