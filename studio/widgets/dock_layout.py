"""The studio window's docks: how they are made, the default layout (every panel a tab in one
narrow right-hand column, the timeline a short strip under the viewport, as Blender and
Substance Painter lay out theirs) and the paint layout (Substance Painter's 2D/3D split).

Why its own module: where panels sit is one concern, apart from the window's menus and files;
``MainWindow`` keeps one-line methods of the same names, which the feature modules call.
"""

from __future__ import annotations

from PySide6.QtCore import QSize, Qt
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QTabWidget, QWidget

# The default layout: these panels as tabs in one right-hand column, in this order.
RIGHT_TABS = ("Poses", "Shading", "Areas", "Wrinkle vectors", "Furrows", "UV Paint")
SIDE_WIDTH = 360  # pixels: the right-hand column (a pose slider gets 100 of them)
TIMELINE_HEIGHT = 200  # pixels: the timeline strip under the viewport


class ColumnPanel(QScrollArea):
    """A panel of the right-hand column: asks for the column's width (so the window lays out
    that way from its first frame) and scrolls what does not fit."""

    def sizeHint(self) -> QSize:
        return QSize(SIDE_WIDTH, super().sizeHint().height())


def add_dock(window: QMainWindow, docks: dict[str, QDockWidget], title: str, widget: QWidget,
             area: Qt.DockWidgetArea) -> None:
    """A dock for ``widget``; a right-hand column panel narrower than it asks scrolls, so the
    column stays put (not the UV canvas, which pans and zooms itself)."""
    dock = QDockWidget(title, window)
    dock.setObjectName(f"dock:{title}")
    if title in RIGHT_TABS and title != "UV Paint":
        scroll = ColumnPanel()
        scroll.setWidget(widget)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        dock.setWidget(scroll)
    else:
        dock.setWidget(widget)
    window.addDockWidget(area, dock)
    docks[title] = dock


def arrange_docks(window: QMainWindow, docks: dict[str, QDockWidget]) -> None:
    """The default layout: every panel a tab in one narrow column on the right and the timeline
    a short strip below the viewport, so the face gets most of the window (History stays hidden
    on the left)."""
    right = [docks[t] for t in RIGHT_TABS if t in docks]
    # the tabs down the column's edge, as Blender's sidebar: every title reads in full
    window.setTabPosition(Qt.DockWidgetArea.RightDockWidgetArea, QTabWidget.TabPosition.East)
    for dock in right:
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
        dock.setMinimumWidth(0)  # a panel may ask for room; the column's width is ours
    for dock in right[1:]:
        window.tabifyDockWidget(right[0], dock)
    for dock in right:
        raise_on_toggle(dock)
    if right:
        right[0].raise_()
    window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, docks["History"])
    if "Timeline" in docks:
        window.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, docks["Timeline"])


def raise_on_toggle(dock: QDockWidget) -> None:
    """A panel's toggle (View menu, toolbar) brings a panel that sits behind another tab to the
    front instead of closing it, and raises a panel it opens."""
    on_screen = {"now": False}  # in front of its tab group (a closed one keeps its last)
    dock.visibilityChanged.connect(
        lambda visible: None if dock.isHidden() else on_screen.update(now=visible))

    def toggled(checked: bool) -> None:
        if not checked and not on_screen["now"] and not dock.isFloating():
            dock.show()  # it was open, behind another tab: the user asked to see it
        if dock.isVisible():
            dock.raise_()

    dock.toggleViewAction().triggered.connect(toggled)


def default_dock_sizes(window: QMainWindow, docks: dict[str, QDockWidget]) -> None:
    """The side column narrow and the timeline short (sizes apply only to a shown window)."""
    shown = [d for t, d in docks.items() if t in RIGHT_TABS and not d.isHidden()]
    if shown:
        window.resizeDocks(shown[:1], [SIDE_WIDTH], Qt.Orientation.Horizontal)
    if "Timeline" in docks:
        window.resizeDocks([docks["Timeline"]], [TIMELINE_HEIGHT], Qt.Orientation.Vertical)


def arrange_for_painting(window: QMainWindow, docks: dict[str, QDockWidget]) -> None:
    """Substance Painter's 2D/3D split, from the default layout: the UV canvas on the left and
    the face beside it, sharing the room left of the panels equally (the face shows the painted
    area live while a stroke lasts), and the Areas panel, with the brush and the area's links,
    in front on the right."""
    canvas = docks["UV Paint"]
    window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, canvas)  # out of the tabs
    canvas.show()
    docks["Areas"].show()
    docks["Areas"].raise_()
    window.layout().activate()
    side = docks["Areas"].width()
    window.resizeDocks([canvas], [(window.width() - side) // 2], Qt.Orientation.Horizontal)
