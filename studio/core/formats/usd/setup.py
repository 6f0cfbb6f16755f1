"""The studio's set-up back from its own USD export (core/formats/usd/writer.py): the extras in
the mesh's ``customData["wrinkleStudio"]``, the images in the package by the paths they name,
the per-vertex data from ``primvars:wrinkleStudio:*``. Applied by the glTF reader's own code
(``read_studio_extras``), so both formats bring a set-up back the same way."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from studio.core.files.errors import MeshError
from studio.core.files.images import decode_image
from studio.core.formats.gltf.codec import read_studio_extras
from studio.core.formats.gltf.materials import _rgb
from studio.core.formats.usd.materials import ImageBudget
from studio.core.formats.usd.writer import EXTRAS_KEY, NEUTRAL_FILE, VERTEX_PRIMVAR
from studio.core.project.model import Project

Array = np.ndarray


def studio_mesh(stage):
    """The mesh prim carrying the studio's set-up, None in any other stage."""
    from pxr import Usd, UsdGeom

    return next((p for p in Usd.PrimRange(stage.GetPseudoRoot())
                 if p.IsA(UsdGeom.Mesh) and p.GetCustomDataByKey(EXTRAS_KEY)), None)


def package_image(prim, ref: str, path: Path, budget: ImageBudget) -> Array:
    """An image of the package (``ref``: its path there), through USD's resolver."""
    from pxr import Ar, Sdf

    resolved = Sdf.ComputeAssetPathRelativeToLayer(prim.GetStage().GetRootLayer(), ref)
    opened = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved)) if resolved else None
    if opened is None:
        raise MeshError(f"the studio's set-up names an image '{ref}' the package does not hold",
                        path)
    data = bytes(opened.GetBuffer())
    budget.take(data, f"image {ref}")
    return decode_image(data, f"{path} ({ref})")


def neutral_map(prim, path: Path) -> Array:
    """The neutral normal map of the studio's export (the skin material's, by its path)."""
    return _rgb(package_image(prim, NEUTRAL_FILE, path, ImageBudget(path)))


def restore_setup(prim, project: Project, path: Path, report: list[str]) -> None:
    """The set-up ``prim`` carries, put on ``project`` (read from that prim's points, so its
    welded vertices are the points in order)."""
    from pxr import UsdGeom

    try:
        extras = json.loads(prim.GetCustomDataByKey(EXTRAS_KEY))
    except (TypeError, ValueError) as exc:
        raise MeshError(f"the studio's set-up (customData {EXTRAS_KEY}) is malformed ({exc})",
                        path) from None
    budget = ImageBudget(path)

    def image(ref: object) -> Array:
        return package_image(prim, str(ref), path, budget)

    n = project.mesh.n_welded
    carried = {}
    for primvar in UsdGeom.PrimvarsAPI(prim).GetPrimvarsWithValues():
        name = primvar.GetPrimvarName()
        if name.startswith(VERTEX_PRIMVAR):
            values = np.asarray(primvar.Get(), np.float32)
            key = name[len(VERTEX_PRIMVAR):].replace(":", ".")
            if len(values) % max(n, 1) == 0 and len(values):
                carried[key] = values.reshape(n, -1).squeeze(1) if len(values) == n \
                    else values.reshape(n, -1)
    if "not_face" in carried:
        carried["not_face"] = carried["not_face"] > 0.5
    try:
        read_studio_extras(None, project, extras, {}, np.arange(n), carried, report, image)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise MeshError(f"the studio's set-up (customData {EXTRAS_KEY}) is malformed ({exc})",
                        path) from None
    project.name = str(extras.get("name", project.name))
