"""The studio's own errors: each names the file (where there is one) and what is wrong with it.

Everything a user can cause — a bad mesh, a corrupt project, an unknown pose name — raises a
``StudioError``; the GUI shows its text in a dialog, the command line prints it on one line and
exits with code 2. Anything else escaping is a bug.
"""

from __future__ import annotations

from pathlib import Path


class StudioError(Exception):
    """A problem the user can understand and fix."""

    def __init__(self, message: str, path: str | Path | None = None) -> None:
        self.path = None if path is None else Path(path)
        self.problem = message
        super().__init__(f"{self.path}: {message}" if self.path is not None else message)


class MeshError(StudioError):
    """A mesh or key pose that cannot be used."""


class ProjectError(StudioError):
    """A project file that cannot be read or written."""


class ImageError(StudioError):
    """A texture or mask image that cannot be used."""


class RenderError(StudioError):
    """OpenGL is missing or too old, or the GPU cannot hold what was asked."""


class Cancelled(Exception):
    """The user cancelled long work (a load, a bake); nothing was changed. Not a StudioError:
    there is nothing to explain to the user."""
