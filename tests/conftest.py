"""Test set-up: OpenGL 3.3 core for the GUI (before pytest-qt creates the QApplication), settings
kept away from the user's, and shared fixtures."""

from __future__ import annotations

import copy
import functools
import gc
import itertools
import json
import os
import tempfile
from pathlib import Path

import pytest

MUTANT_TEST_SECONDS = float(os.environ.get("MUTANT_TEST_SECONDS", "2"))


def pytest_configure(config: pytest.Config) -> None:
    os.environ["XDG_CONFIG_HOME"] = tempfile.mkdtemp(prefix="wrinkle-settings-")
    os.environ["XDG_DATA_HOME"] = tempfile.mkdtemp(prefix="wrinkle-data-")
    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="wrinkle-cache-")
    # Getting started shows itself at a first start: the tests that want it say so
    conf_dir = Path(os.environ["XDG_CONFIG_HOME"]) / "WrinkleStudio"
    conf_dir.mkdir(parents=True, exist_ok=True)
    (conf_dir / "Wrinkle Studio.conf").write_text("[getting_started]\nseen=true\n")
    try:
        from studio.app import configure_opengl
    except ImportError:  # Qt missing: the GUI tests will say so themselves
        return
    configure_opengl()


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Under mutation testing (mutmut names the mutant in MUTANT_UNDER_TEST and runs the tests
    from mutants/, where it keeps each test's duration) a mutant gets the tests that call its
    function quickest first — mutmut stops at the first failure, so a mutant a 10 ms test kills
    need not wait for a 5 s one — and no more of them than MUTANT_TEST_SECONDS of their
    measured time (at least one test). A mutant only a slower test would catch counts as
    surviving: the score can come out lower than the tests deserve, never higher."""
    if "__mutmut_" not in os.environ.get("MUTANT_UNDER_TEST", ""):
        return
    duration = _mutmut_durations()
    items.sort(key=lambda item: duration.get(item.nodeid, 0.0))
    spent = itertools.accumulate(duration.get(item.nodeid, 0.0) for item in items)
    kept = max(1, sum(1 for total in spent if total <= MUTANT_TEST_SECONDS))
    if kept < len(items):
        config.hook.pytest_deselected(items=items[kept:])
        del items[kept:]


def pytest_sessionfinish() -> None:
    """Under mutation testing, freeze the heap once the tests are collected: mutmut forks every
    mutant's run from the process that collected them, and pytest ends each run with full
    garbage collections that otherwise walk every object of Qt, numpy and the test modules
    again (about a second a mutant, more than most mutants' tests take)."""
    if "MUTANT_UNDER_TEST" in os.environ:
        _mutmut_durations()  # read once here, not in every mutant's run
        gc.freeze()


@functools.cache
def _mutmut_durations() -> dict[str, float]:
    stats = Path("mutmut-stats.json")
    return json.loads(stats.read_text()).get("duration_by_test", {}) if stats.is_file() else {}


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
    from studio.core.sample.synthetic import make_test_face

    return copy.deepcopy(make_test_face())


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
def window_size() -> tuple[int, int]:
    """Size of the studio windows a test opens; a test module may override it."""
    return (1200, 800)


@pytest.fixture
def open_window(qtbot, dialogs, window_size):
    """Opens the studio window on a project: shown, active (window shortcuts need it) and drawn
    once; closed afterwards without the unsaved-changes prompt."""
    from studio.widgets.main_window import MainWindow

    opened = []

    def open_(project):
        w = MainWindow(project)
        opened.append(w)
        w.resize(*window_size)
        w.show()
        w.activateWindow()
        qtbot.waitActive(w)
        qtbot.waitUntil(lambda: w.viewport.frames_rendered > 0 or bool(dialogs), timeout=20000)
        assert dialogs == []
        return w

    yield open_
    for w in opened:
        w.timeline_panel.player.stop()
        w.doc.undo_stack.setClean()
        w.close()
        w.deleteLater()


@pytest.fixture
def window(open_window, sample):
    """The studio window on a private copy of the sample face."""
    return open_window(sample)
