"""Painting on the face in the 3D viewport: left-drag lays brush dabs into the active area's mask
at the UV of the surface under the cursor, on the posed face as it is drawn.

Each cursor position is a ray against the posed triangles (studio.core.picking); the hit's
barycentric coordinates give its UV, and the dab lands there with the panel's brush (radius in
mask pixels). Between two hits in the same UV chart the stroke is continuous (dabs spaced along
the UV path). Across a UV seam: when the hit triangle touches a seam vertex, the same 3D point is
also expressed in the neighbouring chart (barycentric coordinates extrapolated on a triangle of
that chart at the shared vertex) and a dab lands there too, so a stroke over the seam paints
both sides; a jump between charts restarts the stroke's spacing instead of drawing a line
across the UV layout.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QMouseEvent

from studio.core.brush import Stroke, union
from studio.core.mesh import FaceMesh
from studio.core.picking import ray_triangles
from studio.core.poses import PoseBlender
from studio.widgets.areas_panel import PaintState
from studio.widgets.document import Document
from studio.widgets.mask_edits import PaintSession, _announce_region


class SeamMap:
    """For each welded vertex on a UV seam, one triangle per other chart that uses it."""

    def __init__(self, mesh: FaceMesh) -> None:
        self.mesh = mesh
        weld = mesh.weld
        counts = np.bincount(weld, minlength=mesh.n_welded)
        self.seam_welded = counts > 1
        # welded vertex -> list of (render vertex, a triangle using it)
        self.corners: dict[int, list[tuple[int, int]]] = {}
        tri = mesh.triangles
        on_seam = self.seam_welded[weld[tri]]
        for f, k in zip(*np.nonzero(on_seam), strict=True):
            r = int(tri[f, k])
            entries = self.corners.setdefault(int(weld[r]), [])
            if all(r != e[0] for e in entries):
                entries.append((r, int(f)))

    def other_charts(self, triangle: int) -> list[int]:
        """Triangles in other charts that share a seam vertex with ``triangle``."""
        tri = self.mesh.triangles[triangle]
        own = set(int(r) for r in tri)
        found = []
        for r in tri:
            w = int(self.mesh.weld[r])
            if self.seam_welded[w]:
                found += [f for rr, f in self.corners.get(w, []) if rr not in own]
        return found


def barycentric_on(point: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of a point projected on a triangle's plane (may be negative)."""
    a, b, c = corners
    e1, e2, d = b - a, c - a, point - a
    m = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    rhs = np.array([d @ e1, d @ e2])
    try:
        u, v = np.linalg.solve(m, rhs)
    except np.linalg.LinAlgError:
        return np.array([1.0, 0.0, 0.0])
    return np.array([1.0 - u - v, u, v])


class FacePaintTool:
    """The viewport tool (see Viewport.set_tool): press/move/release paint on the surface."""

    def __init__(self, document: Document, state: PaintState, status=None) -> None:
        self.doc = document
        self.state = state
        self.status = status  # a callable(str) for hints (the status bar)
        self.on_deactivate = None  # called when the viewport drops this tool
        self.session: PaintSession | None = None
        self._last_chart_uv: np.ndarray | None = None
        self._seams: tuple[FaceMesh, SeamMap] | None = None
        self._extra: dict[int, Stroke] = {}  # other-chart strokes of this drag, by triangle

    # --- picking -------------------------------------------------------------------------------
    def _positions(self, viewport) -> np.ndarray:
        """Render-vertex positions of the face as drawn (posed)."""
        mesh = self.doc.project.mesh
        scene = getattr(viewport, "scene", None)
        if scene is not None and scene.project is self.doc.project:
            welded = scene.blender.blend(scene.weights)
        else:
            blender = PoseBlender(mesh.rest, self.doc.project.poses)
            names = set(blender.names)
            welded = blender.blend({k: v for k, v in self.doc.pose_weights.items()
                                    if k in names})
        return welded[mesh.weld]

    def pick(self, viewport, x: float, y: float):
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
        hit, _ = picked
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
                                    self.state.mirror)
        self._last_chart_uv = None
        self._extra = {}
        self._paint(viewport, event)
        event.accept()

    def move(self, viewport, event: QMouseEvent) -> None:
        if self.session is None or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        self._paint(viewport, event)

    def release(self, viewport, event: QMouseEvent) -> None:
        if self.session is None:
            return
        self._paint(viewport, event)
        self.session.end()
        self.session = None
        self._extra = {}

    def deactivate(self, viewport) -> None:
        """Another tool took the viewport: finish any stroke, tell the owner (the action)."""
        if self.session is not None:
            self.session.end()
            self.session = None
        if self.on_deactivate is not None:
            self.on_deactivate()

    def _say(self, text: str) -> None:
        if self.status is not None:
            self.status(text)

    def _paint(self, viewport, event: QMouseEvent) -> None:
        pos = event.position()
        picked = self.pick(viewport, pos.x(), pos.y())
        if picked is None:
            self._last_chart_uv = None  # off the face: the next hit starts afresh
            return
        hit, positions = picked
        mesh = self.doc.project.mesh
        uv = hit.interpolate(mesh.uvs[mesh.triangles[hit.triangle]].astype(np.float64))
        x, y = self._to_pixels(uv)
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

    def _seam_dabs(self, hit, positions: np.ndarray) -> None:
        """The same surface point in the other charts at a seam: a dab there too."""
        seams = self._seam_map()
        mesh = self.doc.project.mesh
        touched = None
        placed: list[tuple[float, float]] = []
        for f in seams.other_charts(hit.triangle):
            tri = mesh.triangles[f]
            bary = barycentric_on(hit.point, positions[tri].astype(np.float64))
            if bary.min() < -1.5:  # too far from that triangle to extrapolate its UVs
                continue
            uv = bary @ mesh.uvs[tri].astype(np.float64)
            x, y = self._to_pixels(uv)
            if any(np.hypot(x - px, y - py) < 0.5 * self.state.brush.radius
                   for px, py in placed):
                continue  # two triangles of one chart: one dab is enough
            placed.append((x, y))
            stroke = self._extra.get(f)
            if stroke is None:
                stroke = self._extra[f] = Stroke(self.session.area.mask, self.session.brush,
                                                 self.session.stroke.mirror)
                # share the main stroke's backup so the undo step holds every tile once
                stroke.backup = self.session.stroke.backup
                touched = union(touched, stroke.jump(x, y))
            else:
                touched = union(touched, stroke.to(x, y))
        if touched is not None:
            _announce_region(self.doc, self.session.area, touched)
