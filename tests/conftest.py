"""Test set-up: OpenGL 3.3 core for the GUI (before pytest-qt creates the QApplication), settings
kept away from the user's, and shared fixtures."""

from __future__ import annotations

import copy
import os
import tempfile

import pytest


def pytest_configure(config: pytest.Config) -> None:
    os.environ["XDG_CONFIG_HOME"] = tempfile.mkdtemp(prefix="wrinkle-settings-")
    os.environ["XDG_DATA_HOME"] = tempfile.mkdtemp(prefix="wrinkle-data-")
    try:
        from studio.app import configure_opengl
    except ImportError:  # Qt missing: the GUI tests will say so themselves
        return
    configure_opengl()


@pytest.fixture(scope="module")
def gl_context():
    """A standalone EGL context for a module's renderer tests (no display needed); released
    afterwards, because a standalone context left current stops Qt's viewport drawing."""
    from studio.render.offscreen import create_standalone_context

    ctx = create_standalone_context()
    yield ctx
    ctx.release()


@pytest.fixture
def sample():
    """A private copy of the bundled sample face (2172 vertices) that a test may change."""
    from studio.core.sample import make_sample

    return copy.deepcopy(make_sample())


@pytest.fixture
def dialogs(monkeypatch):
    """Message boxes a GUI test provoked, recorded instead of waiting for a click."""
    shown: list[tuple[str, str]] = []
    try:
        from PySide6.QtWidgets import QMessageBox
    except ImportError:
        return shown

    def record(kind, answer):
        def show(parent, title, text, *args, **kwargs):
            shown.append((kind, text))
            return answer
        return show

    for kind, answer in (("critical", QMessageBox.StandardButton.Ok),
                         ("warning", QMessageBox.StandardButton.Discard),
                         ("information", QMessageBox.StandardButton.Ok),
                         ("question", QMessageBox.StandardButton.Yes)):
        monkeypatch.setattr(QMessageBox, kind, staticmethod(record(kind, answer)))
    return shown


@pytest.fixture
def window(qtbot, sample, dialogs):
    """The studio window on a private copy of the sample, shown, active and drawn once; closed
    afterwards without the unsaved-changes prompt."""
    from studio.widgets.main_window import MainWindow

    w = MainWindow(sample)
    w.resize(1200, 800)
    w.show()
    w.activateWindow()
    qtbot.waitActive(w)  # window shortcuts (Ctrl+Z, F) need an active window
    qtbot.waitUntil(lambda: w.viewport.frames_rendered > 0 or bool(dialogs), timeout=20000)
    assert dialogs == []
    yield w
    w.doc.undo_stack.setClean()
    w.close()
    w.deleteLater()
