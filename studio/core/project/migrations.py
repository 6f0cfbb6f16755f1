"""Upgrades of project.json from older file format versions, one version at a time."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, NoReturn

try:  # advisory locks: POSIX only
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

import numpy as np

from studio.core.project.schema import FORMAT_VERSION

Array = np.ndarray

# MIGRATIONS[v] turns the project.json of a version-v file into version v + 1 (pure JSON in,
# JSON out: a migration that moves members points the new JSON at the old member names).
# load_project applies them in turn, so a file of any older version reaches FORMAT_VERSION.
MIGRATIONS: dict[int, Callable[[dict[str, Any]], dict[str, Any]]] = {
    1: lambda doc: doc,  # 2 adds optional keys only: several wrinkled maps, not-face, cones
    2: lambda doc: {**doc, "furrows": doc.get("furrows", {})},  # 3: the furrow controls,
    # all at 1 (the maps as they were synthesised); no records: a map synthesised before
    # version 3 is kept as it is, like one the user made
    3: lambda doc: doc,  # 4: each pose's onset among the furrow controls; absent = 0, the
    # lines appearing from the first movement as before (a version-3 studio refuses the key)
}


def migrate(doc: dict[str, Any], fail: Callable[[str], NoReturn]) -> dict[str, Any]:
    """``doc`` (a checked project.json of any version this studio reads) upgraded to
    FORMAT_VERSION; ``fail`` is called with one sentence when it cannot be."""
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        fail(f"project.json has an invalid format version {version!r}")
    if version > FORMAT_VERSION:
        fail(f"this project was made by a newer Wrinkle Studio (file format version "
             f"{version}; this one reads up to version {FORMAT_VERSION}); please update")
    while version < FORMAT_VERSION:
        step = MIGRATIONS.get(version)
        if step is None:
            fail(f"file format version {version} is no longer supported")
        doc = step(doc)
        version += 1
        if not isinstance(doc, dict):
            fail(f"the project could not be upgraded from format version {version - 1}")
        doc["version"] = version
    return doc
