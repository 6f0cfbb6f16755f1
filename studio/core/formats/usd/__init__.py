"""USD in (``.usd``, ``.usda``, ``.usdc``, ``.usdz``): what Pixar's, Apple's, NVIDIA's and
Blender's pipelines exchange, read with usd-core (PyPI ``usd-core``, Pixar's own library).

A stage opens like a glTF or FBX head: every visible mesh placed in the world (a skinned one in
its skeleton's bind pose), ``UsdSkelBlendShape`` targets (and each in-between, a key pose of its
own) as key poses, ``primvars:st`` (any interpolation, indexed or not) as UVs, and each
``UsdPreviewSurface``'s ``diffuseColor`` texture as the albedo; the face is then found among the
meshes as a glTF's is (core/formats/gltf/face.py). The stage's ``upAxis`` and ``metersPerUnit``
are read: a Z-up stage is turned Y up, lengths stay in the stage's unit and it is said.

Self-contained: it shares only the glTF path's face finding (gltf_face.py), the polygon
primitives FBX uses too (polygons.py), the table of file kinds and the budgets, so that foreign
formats can move into a package of their own. Modules: stage.py (opening, USD's errors and
warnings, axes and unit), meshes.py (meshes, placement, UVs), shapes.py (blend shapes and
in-betweens), materials.py (material subsets, the diffuse texture), reader.py (the project).
usd-core is imported only when a USD file is opened: the studio starts without it.
"""

from __future__ import annotations

from pathlib import Path

from studio.core.mesh.file_kinds import suffixes

SUFFIXES = tuple(suffixes(("USD",)))


def is_usd(path: str | Path) -> bool:
    """Whether a path names a USD file (by its suffix, as USD itself picks its reader)."""
    return Path(path).suffix.lower() in SUFFIXES
