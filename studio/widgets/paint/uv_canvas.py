"""The UV paint canvas: the UV layout over a map, the masks on top, painted like in an image editor.

Scene units are mask pixels (x right, y down), so a brush radius in the panel is a radius here.
The mask overlay is an RGBA buffer updated only where ``maskRegionChanged`` says; the item repaints
that rectangle alone, so strokes stay smooth at 4096². Zoom: wheel (around the cursor); pan:
middle-drag or Space+left-drag; F fits the layout. Left-drag paints, X toggles the eraser,
[ and ] change the brush size. A tablet's pressure scales each dab.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, QTimer, Signal
from PySide6.QtGui import (
    QBrush,
    QColor,
    QPen,
    QPixmap,
    QTransform,
)
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QGraphicsEllipseItem,
    QGraphicsItem,
    QGraphicsPixmapItem,
    QGraphicsScene,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.mask_ops import mesh_edges
from studio.widgets.document import Document
from studio.widgets.paint.canvas_items import BufferItem, LinesItem, to_qimage
from studio.widgets.paint.paint_state import MIRROR_MODES, PaintState
from studio.widgets.paint.paint_view import PaintView
from studio.widgets.paint.uv_canvas_model import (
    brush_hint,
    mask_size,
    masks_rgba,
    outline_edges,
    overlap_activations,
    overlap_rgba,
    uv_points,
)


class UvCanvas(QWidget):
    """The 2-D paint surface (a dock): header with view options, then the view."""

    previewing = Signal(int)  # the area a stroke paints now, -1 once it ends

    def __init__(self, document: Document, state: PaintState, parent: QWidget | None = None
                 ) -> None:
        super().__init__(parent)
        self.doc = document
        self.state = state
        self.scene = QGraphicsScene(self)
        self.background = QGraphicsPixmapItem()
        self.background.setTransformationMode(Qt.TransformationMode.SmoothTransformation)
        self.scene.addItem(self.background)
        self.masks = BufferItem(1, 1)
        self.scene.addItem(self.masks)
        self.overlap_item = BufferItem(1, 1)
        self.scene.addItem(self.overlap_item)
        self.wire = LinesItem()  # the skin's edges: what the masks are painted over
        self.scene.addItem(self.wire)
        self.outline = LinesItem(QColor(150, 170, 200, 120))  # the rest (eyes, teeth…): outlined
        self.scene.addItem(self.outline)
        self.cursor_item = QGraphicsEllipseItem()
        cursor_pen = QPen(QColor(255, 255, 255, 230))
        cursor_pen.setCosmetic(True)
        cursor_pen.setWidthF(1.5)
        self.cursor_item.setPen(cursor_pen)
        self.inner_cursor = QGraphicsEllipseItem()
        inner_pen = QPen(QColor(255, 255, 255, 120), 1.0, Qt.PenStyle.DashLine)
        inner_pen.setCosmetic(True)
        self.inner_cursor.setPen(inner_pen)
        self.mirror_cursor = QGraphicsEllipseItem()  # where the mirror paints, when it is on
        mirror_pen = QPen(QColor(255, 255, 255, 170), 1.2, Qt.PenStyle.DashLine)
        mirror_pen.setCosmetic(True)
        self.mirror_cursor.setPen(mirror_pen)
        for item in (self.cursor_item, self.inner_cursor, self.mirror_cursor):
            item.setBrush(QBrush(Qt.BrushStyle.NoBrush))
            item.setZValue(10)
            self.scene.addItem(item)
            item.hide()

        self.view = PaintView(self)
        self.backdrop = QComboBox()
        for label, key in (("Diffuse", "diffuse"), ("Wrinkled normal map", "normal_wrinkled"),
                           ("Neutral normal map", "normal_neutral"), ("No map", "none")):
            self.backdrop.addItem(label, key)
        self.backdrop.setToolTip("What the UV layout is drawn over")
        self.show_all = QCheckBox("All areas")
        self.show_all.setToolTip("Show every visible area in its colour, not only the active one")
        self.tile = QComboBox()
        self.tile.setToolTip("Which UDIM tile to show (the face's tiles share one atlas)")
        self.tile_items: list = []  # cell borders and tile numbers, drawn over the layout
        self.show_wire = QCheckBox("UV wireframe")
        self.show_wire.setChecked(True)
        fit = QPushButton("Fit")
        fit.setToolTip("Fit the UV square in the view (F)")
        self.hint = QLabel("")
        self.hint.setStyleSheet("color: #9a9a9a;")
        self.hint.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.hint.setWordWrap(True)  # a narrow canvas wraps its hint, never cuts it
        for combo in (self.backdrop, self.tile):  # the canvas lives in a narrow column
            combo.setSizeAdjustPolicy(
                QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
            combo.setMinimumContentsLength(8)
        self.show_wire.setText("Wireframe")
        self.show_wire.setToolTip("The skin's UV edges, and the outline of the rest (eyes, "
                                  "lashes, teeth)")
        head = QHBoxLayout()  # two short rows: the canvas lives in a narrow column
        head.setContentsMargins(4, 2, 4, 0)
        head.addWidget(self.backdrop, 1)
        head.addWidget(self.tile, 1)
        head.addWidget(fit)
        shows = QHBoxLayout()
        shows.setContentsMargins(4, 0, 4, 2)
        shows.addWidget(self.show_all)
        shows.addWidget(self.show_wire)
        shows.addStretch(1)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addLayout(head)
        layout.addLayout(shows)
        layout.addWidget(self.view, 1)
        layout.addWidget(self.hint)

        self.backdrop.currentIndexChanged.connect(lambda _: self._load_background())
        self.tile.currentIndexChanged.connect(lambda _: self.view.fit())
        self.show_all.toggled.connect(self._toggle_all)
        self.show_wire.toggled.connect(self.wire.setVisible)
        self.show_wire.toggled.connect(self.outline.setVisible)
        fit.clicked.connect(self.view.fit)
        d = document
        d.projectReplaced.connect(self.rebuild)
        d.posesChanged.connect(self._load_wire)
        d.texturesChanged.connect(self._load_background)
        d.masksChanged.connect(self.refresh_masks)
        d.areasChanged.connect(self.refresh_masks)
        d.maskRegionChanged.connect(self._region_changed)
        d.activationsChanged.connect(self._activations_changed)
        d.poseWeightsChanged.connect(self._activations_changed)
        state.changed.connect(self._state_changed)
        state.activeChanged.connect(lambda _: self.refresh_masks())
        self._coverage: np.ndarray | None = None
        self._stale = False
        self.rebuild()

    # --- building ------------------------------------------------------------------------------
    def mask_size(self) -> tuple[int, int]:
        return mask_size(self.doc.project.influence.resolution)

    def layout_rect(self) -> QRectF:
        w, h = self.mask_size()
        return QRectF(0, 0, w, h)

    def tile_rect(self) -> QRectF:
        """The chosen tile's cell in scene pixels (the whole layout for "All tiles")."""
        tiles = self.doc.project.uv_tiles
        tile = self.tile.currentData()
        if tiles is None or tile is None:
            return self.layout_rect()
        x, y, side = tiles.layout.cells[tiles.layout.index(tile)]
        w, h = self.mask_size()
        return QRectF(x * w, y * h, side * w, side * h)

    def _load_tiles(self) -> None:
        """The tile chooser and each tile's border and UDIM number, for a tiled face."""
        for item in self.tile_items:
            self.scene.removeItem(item)
        self.tile_items = []
        tiles = self.doc.project.uv_tiles
        self.tile.blockSignals(True)
        self.tile.clear()
        self.tile.addItem("All tiles", None)
        if tiles is not None:
            skin = set(self.doc.project.skin_tiles())
            for tile in tiles.layout.tiles:
                self.tile.addItem(f"{tile}{' (skin)' if tile in skin else ''}", tile)
            first_skin = next((t for t in tiles.layout.tiles if t in skin), None)
            self.tile.setCurrentIndex(self.tile.findData(first_skin) if first_skin else 0)
            w, h = self.mask_size()
            pen = QPen(QColor(255, 210, 90, 200), 1.5)
            pen.setCosmetic(True)
            for tile, (x, y, side) in zip(tiles.layout.tiles, tiles.layout.cells, strict=True):
                box = self.scene.addRect(QRectF(x * w, y * h, side * w, side * h), pen)
                label = self.scene.addSimpleText(str(tile))
                label.setBrush(QColor(255, 210, 90))
                label.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations)
                label.setPos(x * w + 4, y * h + 4)
                for item in (box, label):
                    item.setZValue(5)
                    self.tile_items.append(item)
        self.tile.setVisible(tiles is not None)
        self.tile.blockSignals(False)

    def _defer(self) -> bool:
        """Whether to leave the canvas to be built when it is next shown: hidden behind another
        tab (as at start, where building its wireframe and overlay took a second of the first
        frame's time) it draws nothing, so a change only marks it stale."""
        if self.isVisible():
            return False
        self._stale = True
        return True

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self._stale:  # after the event: a tab behind another is shown, then hidden, at start
            QTimer.singleShot(0, self._build_if_shown)

    def _build_if_shown(self) -> None:
        if self._stale and self.isVisible():
            self.rebuild()

    def rebuild(self) -> None:
        self._coverage = None
        if self._defer():
            return
        self._stale = False
        self._load_tiles()
        self._load_background()
        self._load_wire()
        self.refresh_masks()
        self.view.fit()

    def _load_background(self) -> None:
        if self._defer():
            return
        key = self.backdrop.currentData()
        w, h = self.mask_size()
        if key == "none":
            self.background.setPixmap(QPixmap())
            return
        image = to_qimage(getattr(self.doc.project.textures, key))
        pix = QPixmap.fromImage(image)
        self.background.setPixmap(pix)
        self.background.setTransform(QTransform.fromScale(w / max(pix.width(), 1),
                                                          h / max(pix.height(), 1)))

    def _load_wire(self) -> None:
        """The UV layout's edges (render vertices, so seams show as chart borders): every edge
        of the skin, only the outline of what is not face (eyes, lashes, teeth), which often
        lies over the skin's tile and would bury its wireframe."""
        if self._defer():
            return
        project = self.doc.project
        mesh = project.mesh
        w, h = self.mask_size()
        pts = uv_points(mesh.uvs, w, h)
        skin = project.skin_triangles()
        rect = QRectF(0, 0, w, h)
        self.wire.set_lines(pts[mesh_edges(mesh.triangles[skin])], rect)
        self.outline.set_lines(pts[outline_edges(mesh.triangles[~skin])], rect)

    # --- the mask overlay ----------------------------------------------------------------------
    def _rgba(self, x: int, y: int, w: int, h: int) -> np.ndarray:
        """Premultiplied RGBA of the masks in one rectangle."""
        areas = self.doc.project.influence.areas
        if self.show_all.isChecked():
            shown = [a for a in areas if a.visible]
        else:
            a = self.state.active
            shown = [areas[a]] if 0 <= a < len(areas) else []
        masks = np.zeros((0, h, w), np.float32) if not shown else np.stack(
            [a.mask[y:y + h, x:x + w] for a in shown])
        return masks_rgba(masks, np.array([a.colour for a in shown], np.float32).reshape(-1, 3))

    def _overlap_rgba(self, x: int, y: int, w: int, h: int) -> np.ndarray:
        areas = self.doc.project.influence.areas
        if not self.state.overlap or not areas:
            return np.zeros((h, w, 4), np.uint8)
        masks = np.stack([a.mask[y:y + h, x:x + w] for a in areas])
        return overlap_rgba(*mask_ops.overlap(masks, self.overlap_activations(),
                                              self.coverage()[y:y + h, x:x + w]))

    def overlap_activations(self) -> np.ndarray:
        """The current activations, or every area at 1 while the face is neutral (so a conflict
        shows before any pose is set)."""
        return overlap_activations(self.doc.activations(),
                                   [a.visible for a in self.doc.project.influence.areas])

    def coverage(self) -> np.ndarray:
        """Where the UV layout has faces, at mask size (computed once, at ≤ 1024², enlarged)."""
        w, h = self.mask_size()
        if self._coverage is None or self._coverage.shape != (h, w):
            size = min(w, 1024)
            cov = mask_ops.uv_coverage(self.doc.project.mesh, size)
            if size != w:
                cov = mask_ops.resample(cov.astype(np.float32), (w, h)) > 0.5
            self._coverage = cov
        return self._coverage

    def refresh_masks(self) -> None:
        if self._defer():
            return
        w, h = self.mask_size()
        if self.masks.buffer.shape[:2] != (h, w):
            self.masks.resize(w, h)
            self.overlap_item.resize(w, h)
            self._load_background()
            self._load_wire()
        self.masks.write(0, 0, self._rgba(0, 0, w, h))
        self.overlap_item.write(0, 0, self._overlap_rgba(0, 0, w, h))
        self.overlap_item.setVisible(self.state.overlap)
        self._update_hint()

    def _region_changed(self, layer: int, x: int, y: int, w: int, h: int) -> None:
        """A dab: redraw just that rectangle."""
        if self._defer():
            return
        if self.masks.buffer.shape[:2] != self.mask_size()[::-1]:
            self.refresh_masks()
            return
        self.masks.write(x, y, self._rgba(x, y, w, h))
        if self.state.overlap:
            self.overlap_item.write(x, y, self._overlap_rgba(x, y, w, h))

    def _activations_changed(self) -> None:
        if self.state.overlap and not self._defer():
            w, h = self.mask_size()
            self.overlap_item.write(0, 0, self._overlap_rgba(0, 0, w, h))

    def _toggle_all(self, _checked: bool) -> None:
        self.refresh_masks()

    def _state_changed(self) -> None:
        if self.overlap_item.isVisible() != self.state.overlap:
            self.refresh_masks()
        self._resize_cursor()
        self._update_hint()

    def _update_hint(self) -> None:
        areas = self.doc.project.influence.areas
        a, state = self.state.active, self.state
        mirror = MIRROR_MODES[state.mirror][0] if state.mirror in MIRROR_MODES \
            and state.mirror != "off" else None
        self.hint.setText(brush_hint(areas[a].name if 0 <= a < len(areas) else None,
                                     state.brush.erase, state.brush.radius, mirror,
                                     state.overlap))

    # --- brush cursor --------------------------------------------------------------------------
    def update_cursor(self, p: QPointF) -> None:
        self._cursor_pos = p
        self.cursor_item.show()
        self.inner_cursor.show()
        self._resize_cursor()

    def _resize_cursor(self) -> None:
        p = getattr(self, "_cursor_pos", None)
        if p is None:
            return
        r = self.state.brush.radius
        self.cursor_item.setRect(QRectF(p.x() - r, p.y() - r, 2 * r, 2 * r))
        ri = r * min(max(self.state.brush.hardness, 0.0), 1.0)
        self.inner_cursor.setRect(QRectF(p.x() - ri, p.y() - ri, 2 * ri, 2 * ri))
        self._place_mirror_cursor(p, r)

    def _place_mirror_cursor(self, p: QPointF, r: float) -> None:
        """The mirror image of the brush (its main one), dashed; hidden with the mirror off or
        when the brush is off every UV chart."""
        mirror = self.state.stroke_mirror(self.doc.project.mesh)
        owner, points, scale = (mirror(np.array([[p.x(), p.y()]]), self.mask_size()[::-1], r)
                                if mirror is not None and self.cursor_item.isVisible()
                                else ((), None, None))
        if not len(owner):
            self.mirror_cursor.hide()
            return
        (x, y), rm = points[0], r * float(scale[0])
        self.mirror_cursor.setRect(QRectF(x - rm, y - rm, 2 * rm, 2 * rm))
        self.mirror_cursor.show()
