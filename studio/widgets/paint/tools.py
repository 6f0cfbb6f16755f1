"""Technique-1 authoring in the studio window: the Areas dock, the UV Paint dock and the
face-paint tool (B) in the Tools toolbar. One call from the main window installs it all."""

from __future__ import annotations

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QAction, QKeySequence

from studio.widgets.app_settings import settings
from studio.widgets.paint.areas_panel import AreasPanel, PaintState
from studio.widgets.paint.paint_tool import FacePaintTool
from studio.widgets.paint.uv_canvas import UvCanvas
from studio.widgets.viewport.techniques import show_technique_1

SAY_MS = 8000  # a status line a person has time to read


class MaskTools:
    """What install_mask_tools made, kept on the window as ``window.mask_tools``."""

    def __init__(self, window) -> None:
        self.window = window
        doc = window.doc
        self.state = PaintState(window)
        self.state.mirror_plane = window.doc.mirror_plane  # the face's own symmetry plane
        self.state.skin_triangles = lambda: doc.project.skin_triangles()
        self._remember_brush()
        self.panel = AreasPanel(doc, self.state)
        self.canvas = UvCanvas(doc, self.state)
        self.canvas.previewing.connect(
            lambda area: window.viewport.set_mask_preview(None if area < 0 else area))
        self.canvas.previewing.connect(self._painted)
        self.panel.said.connect(self.say)
        self.tool = FacePaintTool(doc, self.state,
                                  lambda text: window.statusBar().showMessage(text, 4000))
        # a painting workspace on the left: the canvas above, its layers and brush below
        window._add_dock("UV Paint", self.canvas, Qt.DockWidgetArea.LeftDockWidgetArea)
        window._add_dock("Areas", self.panel, Qt.DockWidgetArea.LeftDockWidgetArea)
        window.splitDockWidget(window.docks["UV Paint"], window.docks["Areas"],
                               Qt.Orientation.Vertical)
        window.resizeDocks([window.docks["UV Paint"], window.docks["Areas"]], [560, 420],
                           Qt.Orientation.Vertical)
        window.docks["UV Paint"].setMinimumWidth(380)
        self.action = QAction("Paint Areas", window)
        self.action.setCheckable(True)
        self.action.setShortcut(QKeySequence("B"))
        self.action.setToolTip("Paint the selected influence area on the face (B); "
                               "the brush is set in the Areas panel")
        self.action.toggled.connect(self.set_painting)
        self.tool.on_deactivate = self._dropped
        window.tools.addAction(self.action)
        for title in ("Areas", "UV Paint"):
            menu_action = window.docks[title].toggleViewAction()
            window.panels_bar.addAction(menu_action)

    def _remember_brush(self) -> None:
        """The brush (size, softness, flow, mirror mode) as the user last left it, and kept so."""

        self.state.restore(settings())
        self.state.changed.connect(lambda: self.state.save(settings()))

    def _dropped(self) -> None:
        """The viewport switched to another tool: show the paint action unchecked."""
        blocker = QSignalBlocker(self.action)
        self.action.setChecked(False)
        del blocker

    def say(self, text: str) -> None:
        self.window.statusBar().showMessage(text, SAY_MS)

    def _painted(self, area: int) -> None:
        """A stroke on the UV canvas began: the face goes on showing technique 1 after it (the
        stroke's own preview shows it only while the pen is down)."""
        if area >= 0:
            switched = show_technique_1(self.window.doc)
            if switched:
                self.say(switched)

    def set_painting(self, on: bool) -> None:
        """The face-paint tool in the viewport; painting shows technique 1, whose masks these
        are (a view setting, not an edit)."""
        viewport = self.window.viewport
        if on:
            viewport.set_tool(self.tool)
            switched = show_technique_1(self.window.doc)
            self.window.docks["Areas"].show()
            self.window.docks["Areas"].raise_()
            self.say(" ".join(filter(None, (
                "Paint: left-drag on the face paints the selected area; B leaves the tool.",
                switched))))
        elif viewport.tool is self.tool:
            viewport.set_tool(None)


def install_mask_tools(window) -> MaskTools:
    tools = MaskTools(window)
    window.mask_tools = tools
    return tools
