"""Help ▸ About: what the studio is, and the OpenGL it draws with (features such as relief
"displace" need more than the 3.3 the studio runs on, so a bug report needs the version)."""

from __future__ import annotations

from PySide6.QtWidgets import QMessageBox, QWidget

from studio import __version__


def about_text(gl_description: str | None) -> str:
    """The About box's rich text; ``gl_description`` from ``describe_gl`` (None: the viewport
    has no OpenGL, which the box says)."""
    gl = gl_description or "not available: the viewport could not start OpenGL"
    return (f"<h3>Wrinkle Studio {__version__}</h3>"
            "<p>Author and preview real-time facial expression wrinkles.</p>"
            "<p>Implements the two GPU techniques of C. D. G. Reis, <i>Animação em tempo real de "
            "rugas faciais explorando as modernas GPUs</i> (UNICAMP, 2010): influence areas with "
            "an activation vector, and wrinkle direction vectors.</p>"
            f"<p>Drawing with {gl}.</p>")


def show_about(parent: QWidget, gl_description: str | None) -> None:
    QMessageBox.about(parent, "About Wrinkle Studio", about_text(gl_description))
