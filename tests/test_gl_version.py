"""The studio draws with the highest OpenGL the driver offers, and says which.

NVIDIA's drivers answer a request for 3.3 with exactly 3.3 (no tessellation, so no relief
"displace") although they offer 4.6; Mesa answers with the highest it has."""

from __future__ import annotations

import types

import moderngl
import pytest

from studio.core.files.errors import RenderError
from studio.render import gl_info


def driver(offers: int, exact: bool):
    """A stand-in for ``moderngl.create_standalone_context``: refuses versions above
    ``offers``; gives exactly what was asked for (NVIDIA) or always ``offers`` (Mesa)."""
    asked: list[int] = []

    def create(require: int, **kwargs):
        asked.append(require)
        if require > offers:
            raise Exception("eglCreateContext failed (0x3009)")
        return types.SimpleNamespace(version_code=require if exact else offers,
                                     release=lambda: None)

    return create, asked


@pytest.mark.parametrize(("offers", "exact", "tries"), [(460, True, [460]),
                                                        (450, False, [460, 450]),
                                                        (410, True, [460, 450, 440, 430, 420,
                                                                     410])])
def test_the_highest_version_offered_is_asked_for(monkeypatch, offers, exact, tries):
    create, asked = driver(offers, exact)
    monkeypatch.setattr(moderngl, "create_standalone_context", create)
    assert gl_info.create_standalone_context().version_code == offers
    assert asked == tries
    assert gl_info.highest_gl_version() == (offers // 100, offers % 100 // 10)


def test_no_context_at_all_is_one_error_naming_what_to_install(monkeypatch):
    create, asked = driver(0, True)
    monkeypatch.setattr(moderngl, "create_standalone_context", create)
    with pytest.raises(RenderError, match=r"cannot create an OpenGL 3\.3 context.*0x3009"):
        gl_info.create_standalone_context()
    assert asked == list(gl_info.GL_VERSIONS) * 2  # EGL, then the platform's default
    assert gl_info.highest_gl_version() == (3, 3)


def test_the_version_is_described_as_the_features_see_it(gl_context):
    text = gl_info.describe_gl(gl_context)
    assert text.startswith(f"OpenGL {gl_context.version_code // 100}."
                           f"{gl_context.version_code % 100 // 10} core, ")
    assert gl_context.info["GL_RENDERER"] in text
    assert gl_context.version_code >= 330


def test_the_viewport_gets_the_highest_version_and_about_names_it(open_window, monkeypatch):
    from PySide6.QtGui import QSurfaceFormat
    from PySide6.QtWidgets import QMessageBox

    from studio.core.sample.synthetic import make_test_face
    from studio.widgets.about import about_text

    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "about",
                        staticmethod(lambda parent, title, text: shown.append(text)))

    window = open_window(make_test_face(561))
    major, minor = gl_info.highest_gl_version()
    asked = QSurfaceFormat.defaultFormat()  # Mesa gives the highest whatever is asked for
    assert (asked.majorVersion(), asked.minorVersion()) == (major, minor)
    ctx = window.viewport.ctx
    assert ctx.version_code == major * 100 + minor * 10
    assert window.viewport.gl_description == gl_info.describe_gl(ctx)
    window.show_about()
    assert len(shown) == 1 and f"Drawing with OpenGL {major}.{minor} core, " in shown[0]
    assert "could not start OpenGL" in about_text(None)
