"""FBX files written by stock Blender (the ``bpy`` test extra) from the ICT head, as a user of
Maya or Blender would hand them over: one mesh with the 53 expressions as shape keys, a helmet
mesh without any beside it, optionally an armature parenting the head (skinned to one bone).

    python tests/fbx_blender.py OUT.fbx [--skeleton] [--up Y|Z] [--poses a,b,c]

Why a subprocess: importing bpy loads all of Blender into the process, and a crash inside it
must not end the test run; each file wants a fresh scene. The head is built in Blender's own
frame (Z up, metres as Blender counts units) from the ICT head's centimetres, Y up: so the FBX
exporter's axis conversion and unit scale are the ones a Blender user's file carries.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def write_fbx(path: Path, skeleton: bool = False, up: str = "Y",
              poses: list[str] | None = None, uvs: bool = True,
              texture: Path | None = None, normal: Path | None = None,
              embed: bool = False) -> Path:
    """Run this file under the test's Python (which has bpy) and return ``path``.
    ``texture`` and ``normal``: images the skin material's Principled BSDF shows as its base
    colour and through a Normal Map node, embedded in the file (``embed``) or named by
    relative path, as Blender's exporter writes them."""
    args = [sys.executable, str(Path(__file__).resolve()), str(path), "--up", up]
    if texture is not None:
        args += ["--texture", str(texture)]
    if normal is not None:
        args += ["--normal", str(normal)]
    if embed:
        args.append("--embed")
    if skeleton:
        args.append("--skeleton")
    if not uvs:
        args.append("--no-uvs")
    if poses:
        args += ["--poses", ",".join(poses)]
    done = subprocess.run(args, capture_output=True, text=True, timeout=600, cwd=ROOT)
    if done.returncode != 0 or not path.is_file():
        raise RuntimeError(f"Blender did not write {path}:\n{done.stdout[-3000:]}\n"
                           f"{done.stderr[-3000:]}")
    return path


def _skin_textures(material, texture: str | None, normal: str | None) -> None:
    """The skin material's node tree: base colour from ``texture``, normals from ``normal``."""
    import bpy

    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = nodes["Principled BSDF"]
    if texture:
        image = nodes.new("ShaderNodeTexImage")
        image.image = bpy.data.images.load(texture)
        links.new(image.outputs["Color"], bsdf.inputs["Base Color"])
    if normal:
        image = nodes.new("ShaderNodeTexImage")
        image.image = bpy.data.images.load(normal)
        image.image.colorspace_settings.name = "Non-Color"
        bump = nodes.new("ShaderNodeNormalMap")
        links.new(image.outputs["Color"], bump.inputs["Color"])
        links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])


def _build(out: str, skeleton: bool, up: str, poses: list[str] | None, uvs: bool,
           texture: str | None = None, normal: str | None = None, embed: bool = False) -> None:
    import bpy
    import numpy as np

    sys.path.insert(0, str(ROOT))
    from studio.core.sample.ict_head import load_ict_head

    project = load_ict_head(poses=poses)
    mesh = project.mesh
    bpy.ops.wm.read_factory_settings(use_empty=True)

    def blender_frame(points: np.ndarray) -> np.ndarray:  # Y up -> Blender's Z up, metres
        p = np.asarray(points, np.float64) * 0.01
        return np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)

    data = bpy.data.meshes.new("HeadMesh")
    tris = mesh.welded_triangles
    data.from_pydata(blender_frame(mesh.rest).tolist(), [], tris.tolist())
    if uvs:
        uv = data.uv_layers.new(name="UVMap")
        uv.data.foreach_set("uv", mesh.uvs[mesh.triangles].reshape(-1).astype(np.float32))
    skin = bpy.data.materials.new("M_Skin")
    eyes = bpy.data.materials.new("M_EyesTeeth")
    if texture or normal:
        _skin_textures(skin, texture, normal)
    data.materials.append(skin)
    data.materials.append(eyes)
    not_face = project.not_face[tris].all(axis=1).astype(np.int32)
    data.polygons.foreach_set("material_index", not_face)
    data.update()
    head = bpy.data.objects.new("Head", data)
    bpy.context.scene.collection.objects.link(head)
    head.shape_key_add(name="Basis", from_mix=False)
    for pose in project.poses:
        key = head.shape_key_add(name=pose.name, from_mix=False)
        key.data.foreach_set("co", blender_frame(pose.positions).reshape(-1).astype(np.float32))

    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.0, 0.0, 0.5))
    bpy.context.active_object.name = "Helmet"

    if skeleton:
        arm_data = bpy.data.armatures.new("Rig")
        rig = bpy.data.objects.new("Armature", arm_data)
        bpy.context.scene.collection.objects.link(rig)
        bpy.context.view_layer.objects.active = rig
        bpy.ops.object.mode_set(mode="EDIT")
        for name, head_at, tail_at in (("spine", (0, 0, -0.4), (0, 0, -0.15)),
                                       ("head", (0, 0, -0.15), (0, 0, 0.15))):
            bone = arm_data.edit_bones.new(name)
            bone.head, bone.tail = head_at, tail_at
            if name == "head":
                bone.parent = arm_data.edit_bones["spine"]
        bpy.ops.object.mode_set(mode="OBJECT")
        head.parent = rig
        group = head.vertex_groups.new(name="head")
        group.add(list(range(len(mesh.rest))), 1.0, "REPLACE")
        head.modifiers.new("Armature", "ARMATURE").object = rig

    forward = "-Z" if up.upper() == "Y" else "Y"
    bpy.ops.export_scene.fbx(filepath=out, axis_up=up.upper(), axis_forward=forward,
                             add_leaf_bones=False, bake_anim=False,
                             path_mode="COPY" if embed else "RELATIVE", embed_textures=embed)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--skeleton", action="store_true")
    parser.add_argument("--up", default="Y")
    parser.add_argument("--poses")
    parser.add_argument("--no-uvs", action="store_true")
    parser.add_argument("--texture")
    parser.add_argument("--normal")
    parser.add_argument("--embed", action="store_true")
    args = parser.parse_args()
    _build(args.out, args.skeleton, args.up, args.poses.split(",") if args.poses else None,
           not args.no_uvs, args.texture, args.normal, args.embed)


if __name__ == "__main__":
    main()
