"""USD out: the face as one ``.usdz`` package, for Omniverse, Houdini, Maya, Unreal and Blender.

What goes in, and where each importer looks for it:

* the mesh (``UsdGeom.Mesh``: the welded vertices, triangles, ``primvars:st`` per face corner);
* each key pose as a ``UsdSkelBlendShape`` (sparse offsets) named in ``skel:blendShapes``,
  bound to a skeleton whose ``SkelAnimation`` plays the timeline's weights: UsdSkel only
  applies blend shapes under a skeleton, and Blender and Houdini import them from there;
* the skin as a ``UsdPreviewSurface`` (diffuse and neutral normal map); the wrinkled maps and
  the masks ride in the package as PNGs beside them;
* the set-up as the mesh's ``customData["wrinkleStudio"]``: the glTF export's extras (areas,
  links, curves, technique-2 areas, timeline, images named by their paths in the package), and
  the per-vertex data the glTF carries (not-face, each technique-2 area's directions, lengths,
  cones) as ``primvars:wrinkleStudio:*`` over the points; ``wrinkleStudio:images`` lists every
  image. Read back by core/formats/usd/setup.py.

usd-core is imported only when a file is written. The package is written whole or not at all.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from studio.core.files.atomic_write import write_atomic
from studio.core.files.png import encode_png
from studio.core.formats.gltf.codec import _studio_extras, carried_arrays
from studio.core.project.model import Project
from studio.core.project.view_settings import saved_view

EXTRAS_KEY = "wrinkleStudio"
VERTEX_PRIMVAR = "wrinkleStudio:"  # the per-point arrays' primvar names start so
NEUTRAL_FILE = "textures/normal_neutral.png"
IMAGES_ATTRIBUTE = "wrinkleStudio:images"  # the mesh's list of every image in the package
DELTA_EPSILON = 1e-9  # a blend shape leaves out the points it moves less than this


def safe_name(text: str) -> str:
    """A file or prim name from any area or map name (USD names: letters, digits, _)."""
    out = "".join(c if c.isalnum() and c.isascii() else "_" for c in text)
    return out if out and not out[0].isdigit() else f"_{out}"


def image_files(project: Project) -> tuple[list[str], list[str]]:
    """The package paths of the wrinkled maps' and the masks' PNGs (the extras name these)."""
    maps = [f"textures/wrinkled_{k}_{safe_name(n)}.png"
            for k, n in enumerate(project.textures.wrinkle_map_names)]
    masks = [f"textures/mask_{k}_{safe_name(a.name)}.png"
             for k, a in enumerate(project.influence.areas)]
    return maps, masks


def save_usdz(project: Project, path: str | Path) -> None:
    """Write the project as a ``.usdz`` package (the stage and its textures in one file)."""
    path = Path(path)
    with tempfile.TemporaryDirectory(prefix="wrinkle-usd-") as temp:
        folder = Path(temp)
        layer = folder / "face.usdc"
        files = _write_stage(project, layer)
        from pxr import Sdf

        package = folder / "face.usdz"
        writer = Sdf.ZipFileWriter.CreateNew(str(package))  # the layer first, as usdz wants
        for name in ["face.usdc", *files]:  # their paths kept: the set-up names them
            writer.AddFile(str(folder / name), name)
        writer.Save()
        write_atomic(path, package.read_bytes(), make_folders=True, what="USD package")


def _write_stage(project: Project, layer: Path) -> list[str]:
    """The stage written to ``layer``, its textures beside it; returns their paths."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdSkel, Vt

    folder = layer.parent
    (folder / "textures").mkdir()
    tex = project.textures
    maps, masks = image_files(project)
    pictures = {"textures/diffuse.png": tex.diffuse,
                NEUTRAL_FILE: tex.normal_neutral,
                **dict(zip(maps, tex.wrinkle_maps.values(), strict=True)),
                **{name: np.round(a.mask * 65535.0).astype(np.uint16)
                   for name, a in zip(masks, project.influence.areas, strict=True)}}
    for name, image in pictures.items():
        (folder / name).write_bytes(encode_png(image))

    stage = Usd.Stage.CreateNew(str(layer))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)  # the studio's up
    # the project keeps no unit: one model unit is said to be a metre, as Blender's scene unit
    # (and its USD export) has it; usdchecker wants a unit said
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdSkel.Root.Define(stage, "/Face")
    stage.SetDefaultPrim(root.GetPrim())
    mesh_data = project.mesh
    mesh = UsdGeom.Mesh.Define(stage, "/Face/Mesh")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(mesh_data.rest.astype(np.float32)))
    welded = mesh_data.welded_triangles
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(welded), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(welded.ravel().astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateOrientationAttr(UsdGeom.Tokens.rightHanded)
    low, high = mesh_data.rest.min(axis=0), mesh_data.rest.max(axis=0)
    mesh.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, low)), Gf.Vec3f(*map(float, high))]))
    primvars = UsdGeom.PrimvarsAPI(mesh)
    st = primvars.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                UsdGeom.Tokens.faceVarying)
    st.Set(Vt.Vec2fArray.FromNumpy(mesh_data.uvs[mesh_data.triangles.ravel()]
                                   .astype(np.float32)))
    for name, values in carried_arrays(project).items():
        values = np.asarray(values, np.float32).reshape(mesh_data.n_welded, -1)
        primvar = primvars.CreatePrimvar(VERTEX_PRIMVAR + name.replace(".", ":"),
                                         Sdf.ValueTypeNames.FloatArray, UsdGeom.Tokens.vertex,
                                         values.shape[1])
        primvar.Set(Vt.FloatArray.FromNumpy(values.ravel()))
    frame = saved_view(project.view).tangent_frame
    extras = _studio_extras(project, frame, maps, masks)
    mesh.GetPrim().SetCustomDataByKey(EXTRAS_KEY, json.dumps(extras, separators=(",", ":")))
    mesh.GetPrim().CreateAttribute(IMAGES_ATTRIBUTE, Sdf.ValueTypeNames.AssetArray).Set(
        Sdf.AssetPathArray(list(pictures)))  # every image, for tools that follow assets

    _blend_shapes(stage, project, mesh)
    _material(stage, mesh)
    stage.GetRootLayer().Save()
    return list(pictures)


def _blend_shapes(stage, project: Project, mesh) -> None:
    """Each key pose as a sparse blend shape, under a one-joint skeleton whose animation plays
    the timeline's weights (at every key of any track)."""
    from pxr import Gf, UsdSkel, Vt

    rest = project.mesh.rest.astype(np.float64)
    names, targets = [], []
    for k, pose in enumerate(project.poses):
        shape = UsdSkel.BlendShape.Define(stage, f"/Face/Mesh/pose_{k}")
        offsets = pose.positions.astype(np.float64) - rest
        moved = np.flatnonzero(np.abs(offsets).max(axis=1) > DELTA_EPSILON)
        shape.CreateOffsetsAttr(Vt.Vec3fArray.FromNumpy(offsets[moved].astype(np.float32)))
        shape.CreatePointIndicesAttr(Vt.IntArray.FromNumpy(moved.astype(np.int32)))
        names.append(pose.name)
        targets.append(shape.GetPath())
    skeleton = UsdSkel.Skeleton.Define(stage, "/Face/Skeleton")
    skeleton.CreateJointsAttr(["root"])
    skeleton.CreateBindTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(1.0)]))
    skeleton.CreateRestTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(1.0)]))
    animation = UsdSkel.Animation.Define(stage, "/Face/Skeleton/Weights")
    animation.CreateBlendShapesAttr(names)
    weights = animation.CreateBlendShapeWeightsAttr()
    timeline = project.timeline
    frames = sorted({k.frame for t in timeline.tracks for k in t.keys})
    if frames:
        from studio.core.formats.gltf.animation import pose_weights

        values = pose_weights(timeline, names, np.asarray(frames, np.float64))
        for frame, row in zip(frames, values, strict=True):
            weights.Set(Vt.FloatArray.FromNumpy(row.astype(np.float32)), float(frame))
        stage.SetStartTimeCode(float(frames[0]))
        stage.SetEndTimeCode(float(frames[-1]))
        stage.SetTimeCodesPerSecond(float(timeline.fps))
    else:
        weights.Set(Vt.FloatArray.FromNumpy(np.zeros(len(names), np.float32)))
    UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets(
        [animation.GetPath()])
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skeleton.GetPath()])
    binding.CreateBlendShapesAttr(names)
    binding.CreateBlendShapeTargetsRel().SetTargets(targets)


def _material(stage, mesh) -> None:
    """The skin: a UsdPreviewSurface with the diffuse and neutral normal maps."""
    from pxr import Sdf, UsdShade

    material = UsdShade.Material.Define(stage, "/Face/Materials/skin")
    surface = UsdShade.Shader.Define(stage, "/Face/Materials/skin/surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.7)
    surface.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    reader = UsdShade.Shader.Define(stage, "/Face/Materials/skin/st")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
    for name, file, source, output, extra in (
            ("diffuse", "textures/diffuse.png", "sRGB", "rgb", {}),
            ("normal", NEUTRAL_FILE, "raw", "rgb",
             {"scale": (2.0, 2.0, 2.0, 1.0), "bias": (-1.0, -1.0, -1.0, 0.0)})):
        texture = UsdShade.Shader.Define(stage, f"/Face/Materials/skin/{name}")
        texture.CreateIdAttr("UsdUVTexture")
        texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(file)
        texture.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set(source)
        texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
            reader.ConnectableAPI(), "result")
        for key, value in extra.items():
            texture.CreateInput(key, Sdf.ValueTypeNames.Float4).Set(value)
        out = texture.CreateOutput(output, Sdf.ValueTypeNames.Float3)
        target = "diffuseColor" if name == "diffuse" else "normal"
        surface.CreateInput(target, Sdf.ValueTypeNames.Color3f if name == "diffuse"
                            else Sdf.ValueTypeNames.Normal3f).ConnectToSource(out)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
