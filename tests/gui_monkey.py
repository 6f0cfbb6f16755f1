"""A monkey that drives every editable widget of every panel with real Qt events.

Run as a script (``python -m tests.gui_monkey [--test-face] [--phases ...]``) in a child
process, so a crash is a dead child, not a dead test run: before each gesture it prints one
``ACT phase | widget | gesture`` line (flushed), so the last such line of a crashed run names
the widget and the gesture that killed it. It ends with ``DONE <gestures>`` on success.

What a person does with a field: click it, type a value and press Return, type and Tab away,
press the arrow keys and Page Up, press Escape, turn the wheel over it (focused, and after the
focus moved elsewhere); a check box is clicked and toggled with Space; a combo box is opened,
moved with Down and chosen with Return; a slider is clicked and moved with the keys; a list is
walked with the arrows and its rows renamed with F2. Every gesture is a real event delivered to
the widget under the pointer or with the focus, never a setter. Dialogs a gesture opens are
answered with their default (message boxes) or cancelled (file, colour and text dialogs).

Phases repeat the walk after the selection moved: another influence area, another vector area,
another pose in the timeline, another wrinkled map; and after a new area is added and linked
to a pose by typing its name (``link``), the fields that gesture made.
"""

from __future__ import annotations

import argparse
import faulthandler
import sys
from collections.abc import Callable, Iterator

from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import (
    QAbstractButton,
    QAbstractItemView,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QCheckBox,
    QColorDialog,
    QComboBox,
    QDockWidget,
    QFileDialog,
    QGroupBox,
    QInputDialog,
    QLabel,
    QLineEdit,
    QMessageBox,
    QScrollArea,
    QScrollBar,
    QWidget,
)
from shiboken6 import isValid

Gesture = Callable[[QWidget], None]
ALIKE_IN_FULL = 4  # fields of one kind in one group that get every gesture (walk)
K = Qt.Key


def _say(*parts: object) -> None:
    print(*parts, flush=True)


def _settle(ms: int = 5) -> None:
    QTest.qWait(ms)


# --- dialogs a gesture may open: answered at once, as a person dismisses them -----------------
def _quiet_dialogs() -> None:
    def answer(default):
        return staticmethod(lambda *a, **k: default)

    for kind in ("critical", "information"):
        setattr(QMessageBox, kind, answer(QMessageBox.StandardButton.Ok))
    QMessageBox.warning = answer(QMessageBox.StandardButton.Discard)  # "save changes?": no
    QMessageBox.question = answer(QMessageBox.StandardButton.No)
    QFileDialog.getOpenFileName = answer(("", ""))
    QFileDialog.getOpenFileNames = answer(([], ""))
    QFileDialog.getSaveFileName = answer(("", ""))
    QFileDialog.getExistingDirectory = answer("")
    from PySide6.QtGui import QColor

    QColorDialog.getColor = answer(QColor())  # invalid: cancelled
    QInputDialog.getText = answer(("", False))
    QInputDialog.getInt = answer((0, False))
    QInputDialog.getDouble = answer((0.0, False))
    QInputDialog.getItem = answer(("", False))


# --- what the walk touches ---------------------------------------------------------------------
def _editable(widget: QWidget) -> bool:
    """Fields a person edits (not the parts of a compound field, not scroll bars)."""
    if not widget.isEnabled():
        return False
    parent = widget.parentWidget()
    if isinstance(widget, QLineEdit) and isinstance(parent, QAbstractSpinBox | QComboBox):
        return False
    if isinstance(widget, QScrollBar):
        return False
    return isinstance(widget, QAbstractSpinBox | QComboBox | QLineEdit | QCheckBox
                      | QAbstractSlider | QAbstractItemView)


def _fields(dock: QDockWidget) -> list[QWidget]:
    root = dock.widget()
    if root is None:
        return []
    inside = [w for w in root.findChildren(QWidget) if _editable(w) and _shown_in(w, root)]
    return [root, *inside] if _editable(root) else inside


def _shown_in(widget: QWidget, root: QWidget) -> bool:
    """Whether the widget is part of the panel as laid out (not a hidden page or popup)."""
    w: QWidget | None = widget
    while w is not None and w is not root:
        if w.isHidden() or w.isWindow():
            return False
        w = w.parentWidget()
    return True


def describe(widget: QWidget) -> str:
    """A person's name for a field: its group box, its label, its kind."""
    parts = []
    group = widget.parentWidget()
    while group is not None and not isinstance(group, QGroupBox | QDockWidget):
        group = group.parentWidget()
    if isinstance(group, QGroupBox):
        parts.append(group.title())
    label = _label_for(widget)
    if label:
        parts.append(label)
    if widget.objectName():
        parts.append(widget.objectName())
    parts.append(type(widget).__name__)
    return " › ".join(parts)


def _label_for(widget: QWidget) -> str:
    """The form label beside the field (or beside the row holding it), else its text or tip."""
    from PySide6.QtWidgets import QFormLayout

    w: QWidget | None = widget
    while w is not None and not isinstance(w, QGroupBox | QDockWidget):
        parent = w.parentWidget()
        for form in parent.findChildren(QFormLayout) if parent is not None else ():
            label = form.labelForField(w)
            if isinstance(label, QLabel):
                return label.text()
        w = parent
    if isinstance(widget, QAbstractButton):
        return widget.text()
    return widget.toolTip()[:40]


# --- gestures -----------------------------------------------------------------------------------
def _show(widget: QWidget) -> None:
    """Scroll the panel to the field, as a person does before touching it."""
    w = widget.parentWidget()
    while w is not None:
        if isinstance(w, QScrollArea):
            w.ensureWidgetVisible(widget, 10, 10)
        w = w.parentWidget()
    _settle(1)


def _centre(widget: QWidget) -> QPoint:
    return widget.rect().center()


def click(widget: QWidget) -> None:
    _show(widget)
    QTest.mouseClick(widget, Qt.MouseButton.LeftButton, pos=_centre(widget))


def _focus_target(widget: QWidget) -> QWidget:
    line = widget.findChild(QLineEdit) if isinstance(widget, QAbstractSpinBox) else None
    return line or widget


def keys(*sequence: K | str) -> Gesture:
    def act(widget: QWidget) -> None:
        target = QApplication.focusWidget() or widget
        for key in sequence:
            if isinstance(key, str):
                QTest.keyClicks(target, key)
            else:
                QTest.keyClick(target, key)
            target = QApplication.focusWidget() or target
    return act


def type_then(text: str, key: K) -> Gesture:
    def act(widget: QWidget) -> None:
        click(widget)
        target = QApplication.focusWidget() or widget
        QTest.keyClick(target, K.Key_A, Qt.KeyboardModifier.ControlModifier)
        QTest.keyClicks(target, text)
        QTest.keyClick(QApplication.focusWidget() or target, key)
    return act


def focused_keys(*sequence: K | str) -> Gesture:
    def act(widget: QWidget) -> None:
        click(widget)
        keys(*sequence)(widget)
    return act


def wheel(steps: int, focus_first: bool) -> Gesture:
    def act(widget: QWidget) -> None:
        _show(widget)
        if focus_first:
            click(widget)
        else:
            widget.window().setFocus()  # the pointer passes over a field without clicking it
        pos = QPointF(_centre(widget))
        glob = QPointF(widget.mapToGlobal(_centre(widget)))
        event = QWheelEvent(pos, glob, QPoint(), QPoint(0, 120 * steps), Qt.MouseButton.NoButton,
                            Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
        QApplication.sendEvent(widget, event)
    return act


def open_combo(widget: QWidget) -> None:
    assert isinstance(widget, QComboBox)
    click(widget)
    view = widget.view()
    if view.isVisible():
        QTest.keyClick(view, K.Key_Down)
        QTest.keyClick(view, K.Key_Return)
    _settle()
    if isValid(widget) and widget.view().isVisible():  # the choice may rebuild the panel
        widget.hidePopup()


def list_walk(widget: QWidget) -> None:
    assert isinstance(widget, QAbstractItemView)
    _show(widget)
    model = widget.model()
    if model is None or model.rowCount() == 0:
        return
    index = model.index(0, 0)
    rect = widget.visualRect(index)
    QTest.mouseClick(widget.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    for key in (K.Key_Down, K.Key_Down, K.Key_Up, K.Key_End, K.Key_Home):
        QTest.keyClick(widget, key)


def list_rename(widget: QWidget) -> None:
    assert isinstance(widget, QAbstractItemView)
    QTest.keyClick(widget, K.Key_F2)
    _settle()
    editor = QApplication.focusWidget()
    if isinstance(editor, QLineEdit) and editor is not widget:
        QTest.keyClicks(editor, " 2")
        QTest.keyClick(editor, K.Key_Return)


def gestures(widget: QWidget) -> Iterator[tuple[str, Gesture]]:
    if isinstance(widget, QAbstractSpinBox):
        yield "type 1 + Return", type_then("1", K.Key_Return)
        yield "Up", focused_keys(K.Key_Up)
        yield "Down", focused_keys(K.Key_Down)
        yield "type 0 + Tab", type_then("0", K.Key_Tab)
        yield "Page Up", focused_keys(K.Key_PageUp)
        yield "type 2 + Escape", type_then("2", K.Key_Escape)
        yield "wheel (focused)", wheel(1, True)
        yield "wheel (unfocused)", wheel(-1, False)
    elif isinstance(widget, QComboBox):
        yield "open, Down, Return", open_combo
        yield "Down (focused)", focused_keys(K.Key_Down)
        yield "Up (focused)", focused_keys(K.Key_Up)
        yield "wheel (focused)", wheel(-1, True)
        yield "wheel (unfocused)", wheel(1, False)
    elif isinstance(widget, QLineEdit):
        yield "type + Return", type_then("monkey", K.Key_Return)
        yield "type + Tab", type_then("monkey 2", K.Key_Tab)
        yield "type + Escape", type_then("x", K.Key_Escape)
    elif isinstance(widget, QCheckBox):
        yield "click", click
        yield "Space", focused_keys(K.Key_Space)
        yield "click back", click
    elif isinstance(widget, QAbstractSlider):
        yield "click", click
        yield "Right, Left, End, Home", focused_keys(K.Key_Right, K.Key_Left, K.Key_End,
                                                     K.Key_Home)
        yield "PageUp", focused_keys(K.Key_PageUp)
        yield "wheel (focused)", wheel(1, True)
        yield "wheel (unfocused)", wheel(-1, False)
    elif isinstance(widget, QAbstractItemView):
        yield "arrows", list_walk
        yield "F2 rename", list_rename
        yield "Escape", focused_keys(K.Key_Escape)


# --- the walk -----------------------------------------------------------------------------------
# After the selection moves, the panels that show what is selected are walked again.
PHASE_DOCKS = {"start": None, "area": ("Areas", "UV Paint"), "link": ("Areas",),
               "vector area": ("Wrinkle vectors",), "pose": ("Poses", "Timeline"),
               "map": ("Areas",)}
# phases that walk what a gesture just made: the lists are left alone (walking one would move
# the selection off the new area before its fields are reached)
KEEP_SELECTION = ("link",)


def walk(window, phase: str, limit: int = 0) -> int:
    """Every gesture on every field of every panel. Of a run of alike fields (a slider per
    pose, a gain per pose) the first ``ALIKE_IN_FULL`` get every gesture and the others the
    first one: each field is touched, and the walk stays minutes, not hours, on a 53-pose rig."""
    count = 0
    for title, dock in window.docks.items():
        if PHASE_DOCKS.get(phase) is not None and title not in PHASE_DOCKS[phase]:
            continue
        dock.show()
        dock.raise_()
        _settle(20)
        seen: dict[str, int] = {}
        fields = _fields(dock)
        for i in range(min(len(fields), limit or len(fields))):
            fields = _fields(dock)  # a gesture may rebuild the panel
            if i >= len(fields):
                break
            if phase in KEEP_SELECTION and isinstance(fields[i], QAbstractItemView):
                continue
            name = describe(fields[i])
            alike = f"{type(fields[i]).__name__} {name.split(' › ')[0]}"
            seen[alike] = seen.get(alike, 0) + 1
            chosen = list(gestures(fields[i]))
            if seen[alike] > ALIKE_IN_FULL:
                chosen = chosen[:1]
            for what, gesture in chosen:
                fields = _fields(dock)
                if i >= len(fields):
                    break
                _say(f"ACT {phase} | {title} › {name} | {what}")
                gesture(fields[i])
                _settle()
                count += 1
        window.doc.undo_stack.setClean()
    return count


def add_and_link(window) -> None:
    """Add an area and link a pose to it by typing its name in "Add pose…", as a person does
    first: the walk then reaches the fields a panel shows only after a link or an area is
    added (the new link's gain, its curve, its plot), made by that gesture and not present
    when the panel was built."""
    panel = window.mask_tools.panel
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    _settle(20)
    _say("ACT link | Areas › Influence areas › Add | click")
    click(_button(panel, "Add"))
    _settle(20)
    pose = window.doc.project.pose_names[-1]
    _say(f"ACT link | Areas › Add pose… | type {pose} + Return")
    type_then(pose, K.Key_Return)(panel.add_pose)
    _settle(50)


def _select_other(window, phase: str) -> None:
    """Move the selection a person would move between walks, with real clicks and keys."""
    if phase == "area":
        panel = window.mask_tools.panel
        if panel.list.count() > 1:
            list_walk(panel.list)
            QTest.keyClick(panel.list, K.Key_Down)
    elif phase == "link":
        add_and_link(window)
    elif phase == "vector area":
        panel = window.wdv_tools.panel
        view = panel.area_list
        if view.count() > 1:
            list_walk(view)
            QTest.keyClick(view, K.Key_Down)
    elif phase == "pose":
        from PySide6.QtWidgets import QSlider

        sliders = window.pose_panel.findChildren(QSlider)
        if len(sliders) > 1:
            focused_keys(K.Key_End)(sliders[1])
    elif phase == "map":
        combo = window.mask_tools.panel.map_combo
        open_combo(combo)
    _settle(50)


# --- what a person does around a field that is being edited ---------------------------------------
def _button(root: QWidget, text: str) -> QAbstractButton:
    return next(b for b in root.findChildren(QAbstractButton) if b.text() == text
                and b.isVisible())


def _gain_field(window) -> QWidget:
    panel = window.mask_tools.panel
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    _settle(20)
    return next(iter(panel.link_spins.values()))


def _undo_keys(widget: QWidget) -> None:
    for mods in (Qt.KeyboardModifier.ControlModifier,
                 Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier):
        QTest.keyClick(QApplication.focusWidget() or widget, K.Key_Z, mods)
        _settle()


def close_panel_while_typing(window) -> None:
    """Type into a field, then close its panel with the dock's close button (and open it)."""
    spin = _gain_field(window)
    click(spin)
    QTest.keyClicks(QApplication.focusWidget() or spin, "1")
    dock = window.docks["Areas"]
    closer = dock.findChild(QAbstractButton, "qt_dockwidget_closebutton")
    if closer is not None and closer.isVisible():
        QTest.mouseClick(closer, Qt.MouseButton.LeftButton)
    else:
        dock.close()
    _settle(20)
    dock.toggleViewAction().trigger()


def undo_while_a_field_has_focus(window) -> None:
    """Ctrl+Z and Ctrl+Shift+Z with the focus in the field that made the edit."""
    spin = _gain_field(window)
    type_then("1", K.Key_Return)(spin)
    _settle()
    spin = _gain_field(window)
    click(spin)
    _undo_keys(spin)
    menu_undo = window.menus["Edit"].actions()[0]
    menu_undo.trigger()


def delete_the_area_being_edited(window) -> None:
    """Type into the selected area's gain (no Return) and press Delete; then rename a vector
    area inline (F2) and delete it before pressing Return."""
    panel = window.mask_tools.panel
    spin = _gain_field(window)
    click(spin)
    QTest.keyClicks(QApplication.focusWidget() or spin, "0.5")
    QTest.mouseClick(_button(panel, "Delete"), Qt.MouseButton.LeftButton)
    _settle(20)
    _undo_keys(panel)
    wdv = window.wdv_tools.panel
    window.docks["Wrinkle vectors"].show()
    window.docks["Wrinkle vectors"].raise_()
    _settle(20)
    if wdv.area_list.count():
        list_walk(wdv.area_list)
        QTest.keyClick(wdv.area_list, K.Key_F2)
        editor = QApplication.focusWidget()
        if isinstance(editor, QLineEdit):
            QTest.keyClicks(editor, "renamed")
        QTest.mouseClick(_button(wdv, "Delete"), Qt.MouseButton.LeftButton)
        _settle(20)
        _undo_keys(wdv)


def switch_projects_while_autosaving(window) -> None:
    """An edit, its autosave started, and File ▸ Open Sample Face before the write ends."""
    spin = _gain_field(window)
    type_then("1", K.Key_Return)(spin)
    window.autosaver.autosave()
    opener = next(a for a in window.menus["File"].actions() if "Sample" in a.text())
    opener.trigger()
    _settle(50)
    window.autosaver.wait(60)
    _settle(50)


SCENARIOS = {"close a panel while typing": close_panel_while_typing,
             "undo while a field has focus": undo_while_a_field_has_focus,
             "delete the area being edited": delete_the_area_being_edited,
             "switch projects while autosaving": switch_projects_while_autosaving}


def run_scenarios(window) -> int:
    for name, scenario in SCENARIOS.items():
        _say(f"ACT scenarios | {name} | whole")
        scenario(window)
        _settle(20)
    return len(SCENARIOS)


# --- the gain field, value by value -------------------------------------------------------------
def choose(combo: QComboBox, data: object) -> None:
    """Open a combo box and walk its list with the arrow keys to ``data``, then Return."""
    click(combo)
    view = combo.view()
    target = combo.findData(data)
    QTest.keyClick(view, K.Key_Home)
    for _ in range(target):
        QTest.keyClick(view, K.Key_Down)
    QTest.keyClick(view, K.Key_Return)
    _settle(20)


def gain_check(window) -> dict:
    """Link the selected area to an unlinked pose through its gain field with the keys a person
    uses, and say what the document and the picture did after each."""
    import numpy as np

    from tests.gui_helpers import viewport_image

    doc = window.doc
    panel = window.mask_tools.panel
    area = panel.active_area().name
    window.docks["Shading"].show()
    window.docks["Shading"].raise_()
    choose(window.shading_panel.technique, "t1")
    links = doc.project.influence.links
    pose = next(p for p in doc.project.pose_names[1:] if not links.get(p, {}).get(area))
    window.docks["Poses"].show()
    window.docks["Poses"].raise_()
    _settle(20)
    click(_button(window.pose_panel, "Back to neutral"))  # the sample opens mid-expression
    focused_keys(K.Key_End)(window.pose_panel.pose_rows[pose].slider)
    _settle(300)
    before = viewport_image(window)
    _gain_field(window)
    type_then(pose, K.Key_Return)(panel.add_pose)  # "Add pose…": type its name, Return
    _settle(50)
    out: dict = {"area": area, "pose": pose, "weight": doc.pose_weights.get(pose),
                 "added": doc.project.influence.links.get(pose, {}).get(area, 0.0)}
    spin = panel.link_spins[pose]
    for what, gesture in (("type 0.8 + Return", type_then("0.8", K.Key_Return)),
                          ("Up", keys(K.Key_Up)),
                          ("type 0.5 + Tab", type_then("0.5", K.Key_Tab)),
                          ("wheel (focused)", wheel(1, True)),
                          ("Down", focused_keys(K.Key_Down))):
        gesture(spin)
        _settle(50)
        out[what] = doc.project.influence.links.get(pose, {}).get(area, 0.0)
        out[what + ": same field"] = isValid(spin) and panel.link_spins[pose] is spin
    type_then("1", K.Key_Return)(spin)
    _settle(300)
    after = viewport_image(window)
    out["changed"] = float(np.mean(np.any(np.abs(after.astype(int) - before) > 3, axis=2)))
    return out


def main(argv: list[str] | None = None) -> int:
    faulthandler.enable()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--test-face", action="store_true",
                        help="the small procedural face instead of the bundled sample")
    parser.add_argument("--phases", default="start,area,link,vector area,pose,map")
    parser.add_argument("--docks", default="", help="comma-separated dock titles (default all)")
    parser.add_argument("--gain-check", action="store_true",
                        help="type into one gain field and say what the document shows")
    parser.add_argument("--limit", type=int, default=0, help="stop a walk after this many "
                        "fields (0: all)")
    args = parser.parse_args(argv)

    from studio.app import configure_opengl

    configure_opengl()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    _quiet_dialogs()
    from studio.widgets.main_window import MainWindow

    project = None
    if args.test_face:
        from studio.core.sample.synthetic import make_test_face

        project = make_test_face()
    window = MainWindow(project)
    window.set_anti_aliasing(0)  # the monkey tests the panels, not the picture: draw quickly
    window.resize(1440, 900)
    window.show()
    window.activateWindow()
    while window.viewport.frames_rendered == 0:
        QTest.qWait(20)
    if args.docks:
        keep = set(args.docks.split(","))
        window.docks = {t: d for t, d in window.docks.items() if t in keep}
    total = 0
    if args.gain_check:
        import json

        _say("GAIN", json.dumps(gain_check(window)))
        args.phases = ""
    for phase in filter(None, args.phases.split(",")):
        if phase == "scenarios":
            total += run_scenarios(window)
            continue
        if phase != "start":
            _select_other(window, phase)
        total += walk(window, phase, args.limit)
    _say(f"DONE {total}")
    window.doc.undo_stack.setClean()
    window.close()
    app.processEvents()
    return 0


if __name__ == "__main__":
    sys.exit(main())
