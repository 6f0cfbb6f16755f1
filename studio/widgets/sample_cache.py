"""The ready sample head, kept set up on disk so that the studio opens on it in seconds.

Why: setting the ICT head up (the automatic set-up of its 17 wrinkling expressions and the
synthesis of their wrinkled maps) takes 5–6 s on a two-core machine, and the studio did it at
every start. The set-up is the same each time for the same code, so the first start keeps its
result as an ordinary project file in the user's cache folder and later starts open that file
(about 1.5 s). The file's name carries a fingerprint of the code that builds the sample (every
module under studio/core) and of the head's resource, so a changed studio never opens a stale
set-up; older files are removed. The file is written on a worker thread from a private copy,
after the window is up, and atomically: a start killed meanwhile leaves no half-written cache.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import threading
from pathlib import Path

from PySide6.QtCore import QStandardPaths

from studio.core.files.errors import StudioError
from studio.core.project import reader, writer
from studio.core.project.model import Project
from studio.core.sample.ict_head import resource_path

_CORE = Path(__file__).resolve().parents[1] / "core"


def cache_dir() -> Path:
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.CacheLocation)
    return (Path(base) if base else Path.home() / ".cache" / "WrinkleStudio") / "sample"


def fingerprint() -> str:
    """Of the code that builds the sample and of the head it is built from."""
    digest = hashlib.sha256()
    for source in sorted(_CORE.rglob("*.py")):
        digest.update(source.relative_to(_CORE).as_posix().encode())
        digest.update(source.read_bytes())
    resource = resource_path()
    digest.update(resource.read_bytes() if resource.is_file() else b"")
    return digest.hexdigest()[:16]


def cached_sample() -> Project:
    """The ready sample: from the cache when it holds this studio's, else built (and kept)."""
    from studio.core.setup.sample_setup import sample_project

    path = cache_dir() / f"sample-{fingerprint()}.wrinkle"
    if path.is_file():
        try:
            return reader.load_project(path)
        except StudioError:  # damaged: built again below, and replaced
            with contextlib.suppress(OSError):
                path.unlink()
    project = sample_project()
    _frame_face(project)
    keep = copy.deepcopy(project)  # the window may change its copy while this one is written
    # not a daemon: a studio closed seconds after its first start still finishes the write
    # (the interpreter waits for it), or the next start would set the sample up again
    threading.Thread(target=_keep, args=(keep, path), name="sample-cache", daemon=False).start()
    return project


def _frame_face(project: Project) -> None:
    """Keep the camera framing the face with the set-up: finding the face's axes takes about a
    second, which later starts then spend on nothing (the window opens on this camera)."""
    from studio.core.mesh.camera import OrbitCamera
    from studio.core.setup.face_frame import aim

    if "camera" not in project.view:
        camera = OrbitCamera()
        aim(camera, project, "face")
        project.view["camera"] = camera.to_dict()


def _keep(project: Project, path: Path) -> None:
    """Write the cache (a failure only costs the next start its speed) and drop older ones."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        writer.save_project(project, path, backup=False)
    except (OSError, StudioError):
        return
    for old in path.parent.glob("sample-*.wrinkle"):
        if old != path:
            with contextlib.suppress(OSError):
                old.unlink()
