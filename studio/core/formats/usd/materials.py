"""A USD mesh's materials: which polygons each one covers, the UV set its texture reads and the
image its ``UsdPreviewSurface``'s ``diffuseColor`` shows.

A mesh is bound to one material, and ``GeomSubset``s of the ``materialBind`` family bind their
polygons to others (Blender and Maya write a subset per material slot). A preview surface's
``diffuseColor`` is a colour or a ``UsdUVTexture``'s ``rgb``; the texture names its image by an
asset path (inside the package for a ``.usdz``) and its UVs by a ``UsdPrimvarReader_float2``'s
``varname``, often through an input of the material (``inputs:frame:stPrimvarName``). Every
connection is followed to the attribute that gives the value, as USD's own renderers do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.files.budgets import FILE_BYTES
from studio.core.files.errors import MeshError
from studio.core.files.images import decode_image
from studio.core.formats.head_maps import ImageBudget

Array = np.ndarray
PREVIEW_SURFACE = "UsdPreviewSurface"
TEXTURE = "UsdUVTexture"
UV_READER = "UsdPrimvarReader_float2"


@dataclass
class FaceMaterials:
    """The materials of one mesh: names, their prims (None where none is bound) and the one
    each polygon shows."""

    names: list[str]
    materials: list[object]  # UsdShade.Material or None
    face_material: Array  # (P,) int64 into ``names``


def face_materials(prim, n_faces: int, where: str, path: object) -> FaceMaterials:
    """Each polygon's material: the mesh's own binding, replaced on a ``materialBind``
    subset's polygons by the subset's."""
    from pxr import UsdShade

    binding = UsdShade.MaterialBindingAPI(prim)
    whole, _ = binding.ComputeBoundMaterial()
    out = FaceMaterials([whole.GetPrim().GetName() if whole else ""],
                        [whole if whole else None], np.zeros(n_faces, np.int64))
    index = {str(whole.GetPath()): 0} if whole else {}
    for subset in binding.GetMaterialBindSubsets():
        material, _ = UsdShade.MaterialBindingAPI(subset.GetPrim()).ComputeBoundMaterial()
        if not material:
            continue
        faces = np.asarray(subset.GetIndicesAttr().Get() or [], np.int64).reshape(-1)
        outside = faces[(faces < 0) | (faces >= n_faces)]
        if len(outside):
            raise MeshError(f"{where}'s subset {subset.GetPrim().GetName()} lists face "
                            f"{int(outside[0])}: the mesh has {n_faces}", path)
        key = str(material.GetPath())
        if key not in index:
            index[key] = len(out.names)
            out.names.append(material.GetPrim().GetName())
            out.materials.append(material)
        out.face_material[faces] = index[key]
    return out


def _source(attribute, kind: str):
    """The shader a connected input comes from when it is a shader of ``kind``, else None."""
    from pxr import UsdShade

    if attribute is None:
        return None
    for produced in attribute.GetValueProducingAttributes():
        shader = UsdShade.Shader(produced.GetPrim())
        if shader and shader.GetIdAttr().Get() == kind:
            return shader
    return None


def _diffuse_texture(material):
    """The ``UsdUVTexture`` a material's preview surface takes its diffuse colour from."""
    if material is None:
        return None
    surface, _, _ = material.ComputeSurfaceSource()
    if not surface or surface.GetIdAttr().Get() != PREVIEW_SURFACE:
        return None
    return _source(surface.GetInput("diffuseColor"), TEXTURE)


def uv_name(material) -> str | None:
    """The primvar a material's diffuse texture reads its UVs from, None when it says none."""
    texture = _diffuse_texture(material)
    reader = _source(texture.GetInput("st"), UV_READER) if texture is not None else None
    name = reader.GetInput("varname") if reader is not None else None
    for produced in name.GetValueProducingAttributes() if name is not None else ():
        value = produced.Get()
        if value:
            return str(value)
    return None


def _texture_asset(material):
    """The ``Sdf.AssetPath`` of a material's diffuse texture, None when it has none."""
    texture = _diffuse_texture(material)
    file_input = texture.GetInput("file") if texture is not None else None
    asset = file_input.Get() if file_input is not None else None
    return asset if asset is not None and asset.path else None


def texture_path(material) -> str | None:
    """The asset path of a material's diffuse texture as written, None when it has none."""
    asset = _texture_asset(material)
    return asset.path if asset is not None else None


@dataclass
class Diffuse:
    """A material's diffuse image, or why it has none that can be shown."""

    image: Array | None
    note: str | None  # what the report says when the texture named cannot be found


def diffuse_image(material, budget: ImageBudget) -> Diffuse:
    """A material's diffuse texture, read through USD's resolver (so a ``.usdz``'s own files
    are found); a texture whose file is missing is said, not refused (Blender shows such a
    material untextured), one that is not an image is refused, naming it."""
    from pxr import Ar

    asset = _texture_asset(material)
    if asset is None:
        return Diffuse(None, None)
    if "<UDIM>" in asset.path.upper():  # one file per tile: the project's maps take such sets
        return Diffuse(None, f"texture {asset.path} of material "
                             f"{material.GetPrim().GetName()} is a UDIM set: give it as the "
                             "diffuse map (--diffuse, or Diffuse in New from Files)")
    resolved = asset.resolvedPath
    opened = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved)) if resolved else None
    if opened is None:
        return Diffuse(None, f"texture {asset.path} of material {material.GetPrim().GetName()}"
                             " not found: plain skin colour")
    what = f"texture {asset.path}"
    FILE_BYTES.check(opened.GetSize(), what, budget.path, MeshError)
    data = bytes(opened.GetBuffer())
    budget.take(data, what)
    return Diffuse(decode_image(data, resolved), None)
