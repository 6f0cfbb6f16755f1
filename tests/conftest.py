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


@pytest.fixture(scope="session")
def gl_context():
    """One standalone EGL context for every renderer test (no display needed)."""
    from studio.render.offscreen import create_standalone_context

    ctx = create_standalone_context()
    yield ctx
    ctx.release()


@pytest.fixture
def sample():
    """A private copy of the bundled sample face (2172 vertices) that a test may change."""
    from studio.core.sample import make_sample

    return copy.deepcopy(make_sample())
