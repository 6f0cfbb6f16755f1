"""An avatar .glb as avatar makers export them, built by the tests themselves.

Ten meshes, the eyes first: EyeLeft, EyeRight, Head, Teeth, Hair, Glasses, Body, OutfitTop,
OutfitBottom, Shoes; metres, Y up, the head 1.6 m above the feet. Head, eyes and teeth carry
the same 67 morph targets (the 52 ARKit names as avatar files spell them, browDownLeft …, and
15 visemes); the ones that move nothing are sparse accessors of one zero. Head and eyes are
skinned to one skin of 65 joints (their bind pose is stored as they stand, and the Head node's
own transform, which glTF ignores for a skinned mesh, is set to mislead); the teeth are placed by
a node tree (TRS under a parent's matrix) holding quantized int16 positions; the head's UVs are
quantized uint16; the skin's and eyes' images are JPEG. The skin is the production test head's
(tests/production_head.py), so each pose's region is known.
"""

from __future__ import annotations

import io
import json
import struct
from pathlib import Path

import numpy as np
from PIL import Image

from tests.production_head import COMPRESSING, EYES_ONLY, STRETCH_ONLY, build_head
from tests.test_gltf_load_core import Doc

ARKIT = [
    "browDownLeft", "browDownRight", "browInnerUp", "browOuterUpLeft", "browOuterUpRight",
    "cheekPuff", "cheekSquintLeft", "cheekSquintRight", "eyeBlinkLeft", "eyeBlinkRight",
    "eyeLookDownLeft", "eyeLookDownRight", "eyeLookInLeft", "eyeLookInRight", "eyeLookOutLeft",
    "eyeLookOutRight", "eyeLookUpLeft", "eyeLookUpRight", "eyeSquintLeft", "eyeSquintRight",
    "eyeWideLeft", "eyeWideRight", "jawForward", "jawLeft", "jawOpen", "jawRight", "mouthClose",
    "mouthDimpleLeft", "mouthDimpleRight", "mouthFrownLeft", "mouthFrownRight", "mouthFunnel",
    "mouthLeft", "mouthLowerDownLeft", "mouthLowerDownRight", "mouthPressLeft",
    "mouthPressRight", "mouthPucker", "mouthRight", "mouthRollLower", "mouthRollUpper",
    "mouthShrugLower", "mouthShrugUpper", "mouthSmileLeft", "mouthSmileRight",
    "mouthStretchLeft", "mouthStretchRight", "mouthUpperUpLeft", "mouthUpperUpRight",
    "noseSneerLeft", "noseSneerRight", "tongueOut"]
VISEMES = ["viseme_sil", "viseme_PP", "viseme_FF", "viseme_TH", "viseme_DD", "viseme_kk",
           "viseme_CH", "viseme_SS", "viseme_nn", "viseme_RR", "viseme_aa", "viseme_E",
           "viseme_I", "viseme_O", "viseme_U"]
TARGETS = ARKIT + VISEMES
MESHES = ["EyeLeft", "EyeRight", "Head", "Teeth", "Hair", "Glasses", "Body", "OutfitTop",
          "OutfitBottom", "Shoes"]
HEAD_HEIGHT = 1.6  # metres: where the sample head's origin stands
SCALE = 0.1  # metres per sample unit


def arkit_name(pose: str) -> str:
    """The production head's pose names as avatar files spell them (browDown_L → browDownLeft)."""
    return pose.replace("_L", "Left").replace("_R", "Right")


def to_world(points: np.ndarray) -> np.ndarray:
    """Sample units (x left, y up, z front) to the avatar's metres, Y up, standing."""
    return np.asarray(points, np.float64) * SCALE + [0.0, HEAD_HEIGHT, 0.0]


class GlbDoc(Doc):
    """The tests' glTF document, with int16 and normalized accessors, sparse zeros, JPEG
    images, and written as a .glb."""

    def data(self, array: np.ndarray, kind: str | None = None, normalized: bool = False) -> int:
        array = np.ascontiguousarray(array)
        if array.dtype == np.int16:
            index = super().data(array.view(np.uint16), kind)
            self.doc["accessors"][index]["componentType"] = 5122
        else:
            index = super().data(array, kind)
        if normalized:
            self.doc["accessors"][index]["normalized"] = True
        return index

    def zeros(self, count: int) -> int:
        """A VEC3 accessor of ``count`` zeros: sparse, one stored zero, no base view."""
        self.doc["accessors"].append({
            "componentType": 5126, "count": count, "type": "VEC3",
            "sparse": {"count": 1,
                       "indices": {"bufferView": self.view(np.zeros(1, np.uint32).tobytes()),
                                   "componentType": 5125},
                       "values": {"bufferView": self.view(np.zeros(3, np.float32).tobytes())}}})
        return len(self.doc["accessors"]) - 1

    def jpeg_texture(self, colour: tuple[int, int, int], size: int = 64) -> dict:
        out = io.BytesIO()
        Image.fromarray(np.full((size, size, 3), colour, np.uint8)).save(out, "JPEG",
                                                                         quality=95)
        images = self.doc.setdefault("images", [])
        images.append({"bufferView": self.view(out.getvalue()), "mimeType": "image/jpeg"})
        textures = self.doc.setdefault("textures", [])
        textures.append({"source": len(images) - 1})
        return {"index": len(textures) - 1}

    def material(self, name: str, colour: tuple[int, int, int] | None) -> int:
        materials = self.doc.setdefault("materials", [])
        pbr: dict = {"metallicFactor": 0.0}
        if colour is not None:
            pbr["baseColorTexture"] = self.jpeg_texture(colour)
        else:
            pbr["baseColorFactor"] = [0.3, 0.2, 0.1, 1.0]
        materials.append({"name": name, "pbrMetallicRoughness": pbr})
        return len(materials) - 1

    def write_glb(self, path: Path) -> Path:
        self.doc["buffers"] = [{"byteLength": len(self.blob)}]
        path.write_bytes(glb_bytes(self.doc, bytes(self.blob)))
        return path


def _box(centre: tuple[float, float, float], size: tuple[float, float, float]
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed box (hair, glasses, body, clothes stand-ins), metres."""
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    uv = (corners[:, :2] + 0.5)
    return corners * size + centre, faces, uv


BROW_CARDS = ("MASK", "BLEND", "texture")


def brow_card(skin, face_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                   np.ndarray]:
    """Eyebrow cards as a VRoid avatar has them: the skin's triangles over both brows copied
    half a millimetre in front of it, moving with it in every pose (so a brow lowerer squeezes
    them as it squeezes the brow). (welded skin vertex each card vertex copies, its offset
    along the skin's normal in sample units, triangles, UVs over the brow texture)."""
    from studio.core.sample.mesh import BROW_Y, vertex_normals

    x, y = face_xy[:, 0], face_xy[:, 1]
    over = (np.abs(x) > 0.04) & (np.abs(x) < 0.36) & (np.abs(y - BROW_Y) < 0.05)
    over &= skin.rest[:, 2] > 0.2
    welded = skin.weld[skin.triangles]
    tris = welded[over[welded].all(axis=1)]
    source, local = np.unique(tris, return_inverse=True)
    normals = vertex_normals(skin.rest, welded)[source]
    uv = np.column_stack([(x[source] + 0.36) / 0.72, (y[source] - BROW_Y + 0.05) / 0.1])
    return source, 0.005 * normals, local.reshape(-1, 3), uv


def card_texture(d: GlbDoc, size: int = 64) -> dict:
    """A brow texture as avatar makers paint them: hair strokes on a clear ground (a fifth of
    the texels opaque, in thin diagonal strokes)."""
    u, v = np.meshgrid(np.arange(size), np.arange(size))
    rgba = np.zeros((size, size, 4), np.uint8)
    rgba[..., :3] = (60, 40, 30)
    rgba[..., 3] = np.where((u + 2 * v) % 10 < 2, 255, 0)
    out = io.BytesIO()
    Image.fromarray(rgba, "RGBA").save(out, "PNG")
    images = d.doc.setdefault("images", [])
    images.append({"bufferView": d.view(out.getvalue()), "mimeType": "image/png"})
    textures = d.doc.setdefault("textures", [])
    textures.append({"source": len(images) - 1})
    return {"index": len(textures) - 1}


def build_avatar(path: Path, vertices: int = 2172, squint: str = "corner", brows: str = "",
                 skin_colour: tuple[int, int, int] = (200, 150, 130)) -> Path:
    """The avatar .glb (see the module's docstring); returns its path. ``squint``: see
    ``production_head.build_head``. ``brows``: eyebrow cards as a second primitive of the
    Head mesh (``brow_card``), their material alpha-cut ("MASK"), blended ("BLEND"), or
    opaque by its mode but with a mostly clear texture ("texture")."""
    head = build_head("m", vertices=vertices, up="y", squint=squint)
    skin, eye_l, eye_r, teeth = head.parts
    d = GlbDoc()
    d.doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    d.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    poses = {arkit_name(p): p for p in (*COMPRESSING, STRETCH_ONLY, EYES_ONLY)}
    skin_mat = d.material("Skin", skin_colour)
    eye_mat = d.material("EyeMaterial", (240, 240, 240))
    teeth_mat = d.material("TeethMaterial", None)
    cloth = d.material("Cloth", (40, 60, 90))
    nodes: list[dict] = []
    joints = list(range(65))  # a chain of 65 joints: Hips, Spine, …
    nodes += [{"name": f"Joint{j}", "children": [j + 1] if j < 64 else []} for j in joints]
    d.doc["skins"] = [{"joints": joints, "inverseBindMatrices": d.data(
        np.tile(np.eye(4, dtype=np.float32).ravel(), (65, 1)), "MAT4")}]

    def targets(part, world_rest, linear=None) -> list[dict]:
        out = []
        for name in TARGETS:
            pose = poses.get(name)
            moved = part.poses.get(pose) if pose else None
            if moved is None or np.array_equal(moved, part.rest):
                out.append({"POSITION": d.zeros(len(part.uvs))})
                continue
            delta = to_world(moved) - world_rest
            if part.weld is not None:
                delta = delta[part.weld]
            out.append({"POSITION": d.data(delta.astype(np.float32))})
        return out

    def skinned_mesh(name: str, part, material: int, quantize_uv: bool = False) -> dict:
        world = to_world(part.rest)
        weld = part.weld if part.weld is not None else np.arange(len(part.rest))
        uvs = np.column_stack([part.uvs[:, 0], 1.0 - part.uvs[:, 1]])  # glTF v points down
        n = len(weld)
        attributes = {
            "POSITION": d.data(world[weld].astype(np.float32)),
            "TEXCOORD_0": (d.data(np.round(uvs * 65535).astype(np.uint16), normalized=True)
                           if quantize_uv else d.data(uvs.astype(np.float32))),
            "JOINTS_0": d.data(np.zeros((n, 4), np.uint8), "VEC4"),
            "WEIGHTS_0": d.data(np.tile(np.float32([1, 0, 0, 0]), (n, 1))),
        }
        return {"name": name, "primitives": [{
            "attributes": attributes, "material": material,
            "indices": d.data(part.triangles.astype(np.uint16).ravel()),
            "targets": targets(part, world)}],
            "extras": {"targetNames": TARGETS}}

    meshes = {"EyeLeft": skinned_mesh("EyeLeft", eye_l, eye_mat),
              "EyeRight": skinned_mesh("EyeRight", eye_r, eye_mat),
              "Head": skinned_mesh("Head", skin, skin_mat, quantize_uv=True)}
    if brows:
        source, lift, card_tris, card_uv = brow_card(skin, head.face_xy)
        material = {"name": "FaceBrow", "pbrMetallicRoughness": {
            "baseColorTexture": card_texture(d), "metallicFactor": 0.0}}
        if brows != "texture":
            material["alphaMode"] = brows
        d.doc["materials"].append(material)
        card_rest = to_world(skin.rest[source] + lift)
        card_targets = []
        for name in TARGETS:
            pose = poses.get(name)
            moved = skin.poses.get(pose) if pose else None
            if moved is None or np.array_equal(moved, skin.rest):
                card_targets.append({"POSITION": d.zeros(len(source))})
            else:
                delta = to_world(moved[source] + lift) - card_rest
                card_targets.append({"POSITION": d.data(delta.astype(np.float32))})
        n = len(source)
        meshes["Head"]["primitives"].append({
            "attributes": {
                "POSITION": d.data(card_rest.astype(np.float32)),
                "TEXCOORD_0": d.data(np.column_stack([card_uv[:, 0], 1.0 - card_uv[:, 1]])
                                     .astype(np.float32)),
                "JOINTS_0": d.data(np.zeros((n, 4), np.uint8), "VEC4"),
                "WEIGHTS_0": d.data(np.tile(np.float32([1, 0, 0, 0]), (n, 1)))},
            "material": len(d.doc["materials"]) - 1,
            "indices": d.data(card_tris.astype(np.uint16).ravel()),
            "targets": card_targets})
    # the teeth: int16 positions, dequantized by their node's scale and translation
    world = to_world(teeth.rest)
    low, high = world.min(axis=0), world.max(axis=0)
    step = (high - low).max() / 32000.0
    quantized = np.round((world - low) / step).astype(np.int16)
    uvs = np.column_stack([teeth.uvs[:, 0], 1.0 - teeth.uvs[:, 1]]).astype(np.float32)
    meshes["Teeth"] = {"name": "Teeth", "primitives": [{
        "attributes": {"POSITION": d.data(quantized), "TEXCOORD_0": d.data(uvs)},
        "material": teeth_mat, "indices": d.data(teeth.triangles.astype(np.uint16).ravel()),
        "targets": [{"POSITION": d.zeros(len(world))} for _ in TARGETS]}],
        "extras": {"targetNames": TARGETS}}
    boxes = {"Hair": ((0, 1.72, -0.02), (0.2, 0.1, 0.22)), "Glasses": ((0, 1.62, 0.06),
             (0.16, 0.04, 0.02)), "Body": ((0, 1.1, 0), (0.4, 0.7, 0.25)),
             "OutfitTop": ((0, 1.2, 0), (0.42, 0.4, 0.27)),
             "OutfitBottom": ((0, 0.6, 0), (0.38, 0.5, 0.25)), "Shoes": ((0, 0.05, 0.05),
                                                                      (0.3, 0.1, 0.3))}
    for name, (centre, size) in boxes.items():
        pos, tris, uv = _box(centre, size)
        meshes[name] = {"name": name, "primitives": [{
            "attributes": {"POSITION": d.data(pos.astype(np.float32)),
                           "TEXCOORD_0": d.data(uv.astype(np.float32))},
            "material": cloth, "indices": d.data(tris.astype(np.uint16).ravel())}]}
    d.doc["meshes"] = [meshes[name] for name in MESHES]
    mesh_nodes = []
    for index, name in enumerate(MESHES):
        node: dict = {"name": name, "mesh": index}
        if name in ("EyeLeft", "EyeRight", "Head", "Body"):
            node["skin"] = 0
        if name == "Head":  # ignored for a skinned mesh, as glTF says
            node["translation"] = [5.0, 0.0, 0.0]
        if name == "Teeth":
            node.update(translation=(low / 2).tolist(), scale=[step] * 3)
        mesh_nodes.append(len(nodes))
        nodes.append(node)
    # the teeth's parent holds the other half of their offset as a column-major matrix
    teeth_node = mesh_nodes[MESHES.index("Teeth")]
    holder = np.eye(4)
    holder[:3, 3] = low / 2
    nodes.append({"name": "TeethHolder", "matrix": holder.T.ravel().tolist(),
                  "children": [teeth_node]})
    others = [n for n in mesh_nodes if n != teeth_node]
    nodes.append({"name": "Armature", "children": [0, *others, len(nodes) - 1]})
    d.doc["nodes"] = nodes
    d.doc["scenes"] = [{"nodes": [len(nodes) - 1]}]
    d.doc["scene"] = 0
    return d.write_glb(path)


def glb_bytes(doc: dict, blob: bytes) -> bytes:
    """A binary glTF: the header, the JSON chunk (space-padded) and the BIN chunk (zero-padded)."""
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob = blob + b"\0" * (-len(blob) % 4)
    return (struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(blob))
            + struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(blob), 0x004E4942) + blob)
