"""The exported face played by the exported ``wrinkles.js`` on three.js, in headless Chromium
(tests/js/three_page.html): the export's folder served over HTTP (browsers load no modules from
``file://``) with three.js from ``.node`` (scripts/setup.sh's test extra), seen by the camera and
lit by the light of ``render --frame face --yaw 0``."""

from __future__ import annotations

import functools
import http.server
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from urllib.parse import urlencode

import numpy as np
import pytest

from scripts import web_picture
from studio.commands.export import web_look
from studio.core.mesh.camera import OrbitCamera
from studio.core.project.model import Project
from studio.core.setup.face_frame import aim

ROOT = Path(__file__).resolve().parent.parent
THREE = ROOT / ".node" / "node_modules" / "three"
PAGE = Path(__file__).parent / "js" / "three_page.html"


def three() -> Path:
    if not (THREE / "build" / "three.module.js").is_file():
        pytest.fail("three.js is not installed: run 'bash scripts/setup.sh test' (it installs "
                    "three@0.160.1 into .node/)")
    return THREE


@contextmanager
def served(folder: Path) -> Iterator[str]:
    """``folder`` (the export, with the test page and three.js put in) over HTTP on localhost."""
    shutil.copy(PAGE, folder / "page.html")
    link = folder / "three"
    if not link.exists():
        link.symlink_to(three(), target_is_directory=True)

    ready = threading.Event()

    class Handler(http.server.SimpleHTTPRequestHandler):
        """Files, and ``wait``, answered only once the page posts ``ready``: the page's
        ``<img src="wait">`` holds its load event, after which Chromium takes its picture,
        until the face is drawn (three.js decodes images off the main thread, which Chromium's
        virtual time does not wait for)."""

        def do_GET(self) -> None:
            if self.path.startswith("/wait"):
                ready.wait(150)
                ready.clear()
                self.send_response(204)
                self.end_headers()
                return
            super().do_GET()

        def do_POST(self) -> None:
            self.rfile.read(int(self.headers.get("Content-Length", 0)))
            ready.set()
            self.send_response(204)
            self.end_headers()

        def log_message(self, *args: object) -> None:
            pass

    server = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(Handler, directory=str(folder)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/page.html"
    finally:
        server.shutdown()
        server.server_close()


def studio_view(project: Project) -> dict[str, str]:
    """The camera and light ``render --frame face --yaw 0`` draws with, as the page's query."""
    camera = OrbitCamera.from_dict(project.view.get("camera", {}))
    aim(camera, project, "face")
    camera.yaw = 0.0
    look = web_look()
    column_major = lambda m: ",".join(f"{v:.9g}" for v in np.asarray(m).T.ravel())  # noqa: E731
    return {"view": column_major(camera.view_matrix()),
            "proj": column_major(camera.projection_matrix(1.0)),
            "light": ",".join(map(str, look.light_dir)), "ambient": str(look.ambient),
            "specular": str(look.specular), "shininess": str(look.shininess),
            "background": ",".join(map(str, look.background))}


def shoot(url: str, query: dict[str, str], out: Path | None, size: int) -> str:
    """Chromium's screenshot of the page into ``out`` (or its DOM, ``out=None``); returns the
    DOM or what Chromium printed."""
    try:
        chromium = web_picture.chromium()
    except web_picture.NoChromium as exc:
        pytest.fail(str(exc))
    with tempfile.TemporaryDirectory() as profile:
        args = [chromium, *web_picture.FLAGS, f"--window-size={size},{size}",
                f"--user-data-dir={profile}"]
        args += [f"--screenshot={out}"] if out is not None else ["--dump-dom"]
        address = f"{url}?{urlencode({**query, 'size': size})}"
        done = subprocess.run([*args, address], capture_output=True, text=True, timeout=180,
                              check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout
