"""Starting the studio window: OpenGL surface format, application object, command-line options."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from PySide6.QtGui import QSurfaceFormat


def configure_opengl() -> None:
    """The highest OpenGL core version the driver offers (3.3 at least) with a depth buffer;
    must run before the QApplication exists. Asked for 3.3, NVIDIA's drivers give exactly 3.3
    and no tessellation; so a throwaway standalone context finds the highest first.

    On X11, Qt is asked for EGL rather than GLX: the command line's and the exporter's
    standalone contexts are EGL, and GLX and EGL contexts in one process break Qt's.
    """
    if sys.platform.startswith("linux"):
        os.environ.setdefault("QT_XCB_GL_INTEGRATION", "xcb_egl")
    from studio.render.gl_info import highest_gl_version

    fmt = QSurfaceFormat()
    fmt.setVersion(*highest_gl_version())
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    fmt.setSamples(0)  # the viewport multisamples its own framebuffer: the user's choice, live
    QSurfaceFormat.setDefaultFormat(fmt)


def run(project_path: str | None = None, screenshot: str | None = None) -> int:
    from PySide6.QtWidgets import QApplication

    from studio.widgets.crash_log import enable_crash_log
    from studio.widgets.main_window import MainWindow

    configure_opengl()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("Wrinkle Studio")
    app.setOrganizationName("WrinkleStudio")
    enable_crash_log()  # a native crash leaves its Python stacks where the next start finds them
    window = MainWindow()
    window.show()
    if project_path is not None and not window.open_path(Path(project_path)) and screenshot:
        return 2
    if project_path is None and not screenshot:
        window.timeline_panel.player.play()  # the bundled sample moves the moment it opens
    if screenshot:
        out = Path(screenshot)

        def done(ok: bool) -> None:
            print(f"wrote {out}" if ok else f"wrinkle-studio: error: cannot write {out}",
                  file=sys.stdout if ok else sys.stderr)
            window.doc.undo_stack.setClean()
            app.exit(0 if ok else 2)

        window.grab_when_rendered(out, done)
    return app.exec()
