"""Getting started: what to do first, for each technique, in a panel beside the viewport.

Why: a person opening the studio sees a face, five panels and a timeline, and nothing says
where to begin. Shown at the first start (then remembered as seen), reopened from Help ▸
Getting Started, closed like any panel. Each step names the control it uses, in the words the
panels use, so it can be followed without this text on screen.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QDockWidget, QTextBrowser

from studio.widgets.app_settings import settings

SEEN_KEY = "getting_started/seen"
TEXT = """
<h3>Getting started</h3>
<p>The face wrinkles where its skin compresses. Press <b>Space</b> over the timeline to play
the sample's expressions; drag a slider in <b>Poses</b> to pose it yourself.</p>
<h4>Technique 1 — paint where wrinkles appear</h4>
<ol>
<li><b>Areas</b> panel: <b>Add</b> an area (or pick one).</li>
<li>Paint its mask on the <b>UV Paint</b> canvas, or on the face with <b>B</b>.</li>
<li>Under the list, <b>Add pose…</b>: type part of a pose's name (<i>browDown</i>),
Return. The area now reveals that pose's own wrinkled map, and the face shows technique 1
(the label at the viewport's top left says which technique shows; click it to switch).
Set the gain.</li>
<li>Move that pose's slider in <b>Poses</b>: the wrinkles appear inside the mask.</li>
</ol>
<p>Faster: pick a pose under <i>From pose</i> and press <b>Auto mask</b>.</p>
<h4>Technique 2 — wrinkle direction vectors</h4>
<ol>
<li><b>Wrinkle vectors</b> panel: pick or <b>Add</b> a vector area, choose its <b>Pose</b>.</li>
<li>Press <b>S</b> and drag over the face to select vertices (<b>Suggest</b> selects what the
pose moves).</li>
<li><b>Create</b>; comb directions by hand with <b>C</b>.</li>
<li>Move the pose's slider: wrinkles show where the skin moves along the vectors.</li>
</ol>
<h4>Automatic</h4>
<p><b>Shading</b> ▸ Technique ▸ automatic: wrinkles from the compression alone, no
authoring. <b>Tools ▸ Auto Setup from Poses</b> sets both techniques up for a new face.</p>
<h4>Keep it</h4>
<p><b>Ctrl+S</b> saves one project file; every change is undoable (<b>Ctrl+Z</b>) and
autosaved within seconds.</p>
"""


def install_getting_started(window) -> QDockWidget:
    """The panel (a tab of the right-hand column, so the viewport keeps its size), its Help
    entry, and the first-start showing (in front of the other tabs)."""
    browser = QTextBrowser()
    browser.setHtml(TEXT)
    browser.setOpenExternalLinks(False)
    dock = QDockWidget("Getting started", window)
    dock.setObjectName("dock:Getting started")
    dock.setWidget(browser)
    window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
    if "Poses" in window.docks:
        window.tabifyDockWidget(window.docks["Poses"], dock)
    window.docks["Getting started"] = dock
    window._raise_on_toggle(dock)  # Help brings it in front of the tab it shares
    action = dock.toggleViewAction()
    action.setText("&Getting Started")
    help_menu = window.menus["Help"]
    help_menu.insertAction(help_menu.actions()[0] if help_menu.actions() else None, action)
    store = settings()
    if store.value(SEEN_KEY, False, type=bool):
        dock.hide()
        if "Poses" in window.docks:  # (tabifying made this tab current; hidden, Poses is)
            window.docks["Poses"].raise_()
    else:
        store.setValue(SEEN_KEY, True)
        # once the window is up (and has restored its last layout, which may have closed it)
        QTimer.singleShot(0, lambda: (dock.show(), dock.raise_()))
    return dock
