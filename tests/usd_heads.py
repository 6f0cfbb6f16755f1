"""USD heads for the tests, written with usd-core as a DCC's exporter writes them: the ICT head
(Y up, centimetres) turned Z up as Blender and 3ds Max keep it, its eyes a ``materialBind``
subset of their own, blend shapes with sparse ``pointIndices`` and an in-between, UVs as an
indexed face-varying ``primvars:st`` over the head's UDIM tiles, a ``UsdPreviewSurface`` whose
``diffuseColor`` is a ``UsdUVTexture`` reading ``st`` through the material's
``frame:stPrimvarName`` input (as Blender writes it), a helmet beside it without blend shapes,
and the same as ``.usdc`` and as a ``.usdz`` package that carries its texture inside."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from studio.core.files.images import write_png
from studio.core.sample.ict_head import expression_offsets, resource_path

POSES = ("browInnerUp_L", "browDown_L", "mouthSmile_L")
INBETWEEN = ("browDown_L", 0.5, 0.6)  # (shape, weight, share of the full offsets it moves)
TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Y up → Z up


def skin_texture() -> np.ndarray:
    """A 64 × 48 image no default map could be: a gradient with a mark in one corner."""
    image = np.zeros((48, 64, 3), np.uint8)
    image[..., 0] = np.linspace(90, 230, 64, dtype=np.uint8)[None, :]
    image[..., 1] = np.linspace(60, 160, 48, dtype=np.uint8)[:, None]
    image[..., 2] = 120
    image[:6, :6] = (10, 250, 10)
    return image


def ict_arrays(poses: tuple[str, ...] = POSES) -> dict[str, object]:
    """The bundled ICT head as a DCC holds it: welded points, triangles over them, UVs per
    corner through an index, the not-face flags, and each pose's sparse offsets."""
    with np.load(resource_path(), allow_pickle=False) as data:
        rest = data["rest"].astype(np.float64)
        triangles, uvs, weld = data["triangles"], data["uvs"], data["weld"]
        names = [str(n) for n in data["names"]]
        offsets = {p: expression_offsets(data, names.index(p), len(rest)).astype(np.float64)
                   for p in poses}
        not_face = data["not_face"].astype(bool)
    return {"points": rest, "corners": weld[triangles].reshape(-1), "uvs": uvs,
            "uv_index": triangles.reshape(-1), "not_face": not_face, "offsets": offsets}


def _material(stage, path: str, texture: str | None, colour=(0.8, 0.6, 0.5)):
    from pxr import Sdf, UsdShade

    material = UsdShade.Material.Define(stage, path)
    surface = UsdShade.Shader.Define(stage, f"{path}/Principled_BSDF")
    surface.CreateIdAttr("UsdPreviewSurface")
    diffuse = surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f)
    if texture is None:
        diffuse.Set(colour)
    else:
        name = material.CreateInput("frame:stPrimvarName", Sdf.ValueTypeNames.Token)
        name.Set("st")
        reader = UsdShade.Shader.Define(stage, f"{path}/uvmap")
        reader.CreateIdAttr("UsdPrimvarReader_float2")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).ConnectToSource(name)
        image = UsdShade.Shader.Define(stage, f"{path}/Image_Texture")
        image.CreateIdAttr("UsdUVTexture")
        image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(texture)
        image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
            reader.ConnectableAPI(), "result")
        diffuse.ConnectToSource(image.ConnectableAPI(), "rgb")
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    return material


def add_blend_shapes(stage, mesh_path: str, shapes: dict[str, tuple[np.ndarray, np.ndarray]],
                     inbetweens: dict[str, tuple[float, np.ndarray]] | None = None) -> None:
    """``shapes``: name → (point indices, offsets), each a BlendShape prim under the mesh, with
    an in-between where ``inbetweens`` gives one (weight, offsets of the same points)."""
    from pxr import UsdSkel

    targets = []
    for name, (index, offset) in shapes.items():
        shape = UsdSkel.BlendShape.Define(stage, f"{mesh_path}/{name}")
        shape.CreateOffsetsAttr([tuple(map(float, o)) for o in offset])
        shape.CreatePointIndicesAttr([int(i) for i in index])
        if inbetweens and name in inbetweens:
            weight, between = inbetweens[name]
            made = shape.CreateInbetween("IBT_1")
            made.SetWeight(weight)
            made.SetOffsets([tuple(map(float, o)) for o in between])
        targets.append(shape.GetPath())
    binding = UsdSkel.BindingAPI.Apply(stage.GetPrimAtPath(mesh_path))
    binding.CreateBlendShapesAttr(list(shapes))
    binding.CreateBlendShapeTargetsRel().SetTargets(targets)


def write_usd_head(folder: Path, name: str = "head") -> dict[str, Path]:
    """The ICT head as ``name.usda`` (its texture beside it), ``name.usdc`` and ``name.usdz``,
    Z up in centimetres; the paths by suffix."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, UsdUtils, Vt

    folder.mkdir(parents=True, exist_ok=True)
    head = ict_arrays()
    write_png(folder / "skin_albedo.png", skin_texture())
    usda = folder / f"{name}.usda"
    stage = Usd.Stage.CreateNew(str(usda))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    root = UsdGeom.Xform.Define(stage, "/root")
    stage.SetDefaultPrim(root.GetPrim())
    UsdGeom.Xform.Define(stage, "/root/HeadMesh")
    mesh = UsdGeom.Mesh.Define(stage, "/root/HeadMesh/HeadMesh")
    points = head["points"] @ TO_Z_UP.T
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points.astype(np.float32)))
    corners = head["corners"]
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(corners) // 3, 3,
                                                                  np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(corners.astype(np.int32)))
    st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                 UsdGeom.Tokens.faceVarying)
    st.Set(Vt.Vec2fArray.FromNumpy(head["uvs"].astype(np.float32)))
    st.SetIndices(Vt.IntArray.FromNumpy(head["uv_index"].astype(np.int32)))
    skin = _material(stage, "/root/_materials/Skin", "./skin_albedo.png")
    eyes = _material(stage, "/root/_materials/Eyes", None, (0.9, 0.9, 0.9))
    binding = UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim())
    binding.Bind(skin)
    eye_faces = np.flatnonzero(head["not_face"][corners.reshape(-1, 3)].all(axis=1))
    subset = binding.CreateMaterialBindSubset("Eyes", Vt.IntArray.FromNumpy(
        eye_faces.astype(np.int32)))
    UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(eyes)
    shapes, inbetweens = {}, {}
    for pose, offset in head["offsets"].items():
        moved = np.flatnonzero(np.abs(offset).max(axis=1) > 0)
        shapes[pose] = (moved, offset[moved] @ TO_Z_UP.T)
    shape, weight, share = INBETWEEN
    inbetweens[shape] = (weight, share * shapes[shape][1])
    add_blend_shapes(stage, str(mesh.GetPath()), shapes, inbetweens)
    helmet = UsdGeom.Cube.Define(stage, "/root/Helmet")  # a prim that is not a mesh
    helmet.AddTranslateOp().Set(Gf.Vec3d(0, 0, 200))
    cube = UsdGeom.Mesh.Define(stage, "/root/Cube/Cube")
    cube.CreatePointsAttr([(-5, -5, 180), (5, -5, 180), (5, 5, 180), (-5, 5, 180)])
    cube.CreateFaceVertexCountsAttr([4])
    cube.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    stage.Save()
    usdc = folder / f"{name}.usdc"
    stage.Export(str(usdc))
    usdz = folder / f"{name}.usdz"
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(usda)), str(usdz))
    return {".usda": usda, ".usdc": usdc, ".usdz": usdz}
