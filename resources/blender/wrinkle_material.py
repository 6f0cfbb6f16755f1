"""Wrinkle Studio's technique 1 in Blender: run this in Blender (Scripting ▸ Run Script, or
``blender --python blender_wrinkles.py``) with the studio's face.glb imported (it imports the
face.glb beside it if no mesh with the face's shape keys is in the scene).

It rebuilds the face's material so that moving a shape key shows its wrinkles in the viewport
and in renders (Cycles and EEVEE): each area's activation is a driver on the shape keys that
link to it (its own value plus gain × response curve of each, clamped to 0…1), each wrinkled
map's weight is the sum of its areas' masks × activations (clamped), and the normal map is the
neutral map blended with the wrinkled maps by those weights (scaled down where they add past 1),
as the studio's shader does; where the export wrote a wrinkled map's cavity and colour maps,
they are blended by the same weights and tint and darken the base colour (the cavity the
specular too), as the studio's skin look does. Technique 2 (wrinkle vectors) is not built here.

The drivers are simple expressions (min, max, arithmetic), so they run without Blender's
"Auto Run Python Scripts". The object's custom property ``wrinkle_strength`` (0…1) scales every
activation: 0 shows the face without wrinkles.

Written by the studio's export; SETUP below is this face's set-up.
"""

import json
from pathlib import Path

import bpy

SETUP = json.loads("{}")  # this face's set-up, written by the export


def folder() -> Path:
    try:
        return Path(__file__).resolve().parent
    except NameError:  # run from Blender's text editor: beside the .blend, else here
        return Path(bpy.path.abspath("//") or ".")


def face_object():
    """The mesh object with the set-up's shape keys (face.glb imported if there is none)."""
    wanted = set(SETUP["poses"])

    def find():
        for obj in bpy.context.scene.objects:
            keys = obj.type == "MESH" and obj.data.shape_keys
            if keys and wanted <= set(keys.key_blocks.keys()):
                return obj
        return None

    obj = find()
    if obj is None:
        bpy.ops.import_scene.gltf(filepath=str(folder() / SETUP["model"]))
        obj = find()
    if obj is None:
        raise RuntimeError("no mesh with the face's shape keys: import the studio's face.glb")
    return obj


def image(name: str, file: str):
    """An image the glTF import brought (by name), else the export folder's file."""
    found = bpy.data.images.get(name)
    if found is None:
        found = bpy.data.images.load(str(folder() / file), check_existing=True)
    found.colorspace_settings.name = "Non-Color"
    return found


def drive_activation(socket, obj, area: dict) -> None:
    """``socket``'s value: the area's activation, following the shape keys."""
    driver = socket.driver_add("default_value").driver
    driver.type = "SCRIPTED"
    strength = driver.variables.new()
    strength.name = "strength"
    strength.targets[0].id_type = "OBJECT"
    strength.targets[0].id = obj
    strength.targets[0].data_path = '["wrinkle_strength"]'
    terms = [repr(area["activation"])]
    for k, link in enumerate(area["links"]):
        var = driver.variables.new()
        var.name = f"p{k}"
        var.targets[0].id_type = "KEY"
        var.targets[0].id = obj.data.shape_keys
        var.targets[0].data_path = f'key_blocks["{link["pose"]}"].value'
        terms.append(link["term"].format(x=var.name))  # gain × its response curve of x
    driver.expression = f"strength * min(max({' + '.join(terms)}, 0.0), 1.0)"


def build(obj) -> None:
    obj["wrinkle_strength"] = 1.0
    material = obj.active_material or bpy.data.materials.new("skin")
    if obj.active_material is None:
        obj.data.materials.append(material)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    normal_map = next((n for n in nodes if n.type == "NORMAL_MAP"), None)
    if normal_map is None:
        normal_map = nodes.new("ShaderNodeNormalMap")
        links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    uv = nodes.new("ShaderNodeUVMap")
    uv.uv_map = obj.data.uv_layers[0].name
    normal_map.uv_map = uv.uv_map

    def texture(img, x: float, y: float):
        node = nodes.new("ShaderNodeTexImage")
        node.image, node.location = img, (x, y)
        links.new(uv.outputs["UV"], node.inputs["Vector"])
        return node

    def math(operation: str, a, b, x: float, y: float, clamp: bool = False):
        node = nodes.new("ShaderNodeMath")
        node.operation, node.use_clamp, node.location = operation, clamp, (x, y)
        for socket, value in zip(node.inputs[:2], (a, b), strict=True):
            if isinstance(value, float):
                socket.default_value = value
            else:
                links.new(value, socket)
        return node.outputs[0]

    maps = SETUP["wrinkle_maps"]
    weights = []
    for m in range(len(maps)):  # w_m = clamp(sum of mask x activation of its areas)
        total = None
        for k, area in enumerate(a for a in SETUP["areas"] if a["map"] == m):
            y = -300.0 * (len(weights) * 8 + k)
            mask = texture(image(area["image"], area["file"]), -1400.0, y)
            value = nodes.new("ShaderNodeValue")
            value.label, value.location = f"activation: {area['name']}", (-1400.0, y - 150)
            drive_activation(value.outputs[0], obj, area)
            product = math("MULTIPLY", mask.outputs["Color"], value.outputs[0], -1100.0, y)
            total = product if total is None else math("ADD", total, product, -900.0, y)
        weights.append(None if total is None
                       else math("ADD", total, 0.0, -700.0, -300.0 * m, clamp=True))
    used = [(m, w) for m, w in enumerate(weights) if w is not None]
    if not used:
        return
    skin = not_face_gate(obj, nodes, links, math)
    if skin is not None:  # eyes, lashes and teeth often share the skin's UVs: never wrinkled
        used = [(m, math("MULTIPLY", w, skin, -600.0, -300.0 * m)) for m, w in used]
    total = used[0][1]
    for _, w in used[1:]:
        total = math("ADD", total, w, -500.0, 0.0)
    scale = math("DIVIDE", 1.0, math("MAXIMUM", total, 1.0, -350.0, 0.0), -200.0, 0.0)
    rest = math("SUBTRACT", 1.0, math("MULTIPLY", total, scale, -100.0, 100.0), 0.0, 100.0)
    neutral = texture(image(SETUP["neutral"]["image"], SETUP["neutral"]["file"]), -700.0, 400.0)
    colour = vector("SCALE", neutral.outputs["Color"], rest, nodes, links, (150.0, 300.0))
    for m, w in used:
        wrinkled = texture(image(maps[m]["image"], maps[m]["file"]), -700.0, 700.0 + 300 * m)
        share = math("MULTIPLY", w, scale, 0.0, -200.0 - 150 * m)
        part = vector("SCALE", wrinkled.outputs["Color"], share, nodes, links,
                      (150.0, -200.0 - 150 * m))
        colour = vector("ADD", colour, part, nodes, links, (300.0, 150.0 * m))
    links.new(colour, normal_map.inputs["Color"])
    tone(nodes, links, bsdf, [(m, math("MULTIPLY", w, scale, 0.0, -900.0 - 150 * m))
                              for m, w in used], rest, math, texture)


def tone(nodes, links, bsdf, shares, rest, math, texture) -> None:
    """Each wrinkled map's cavity and colour maps (where the export wrote them), blended by
    the same shares as its normals: the colour (value / 128) tints the base colour, the cavity
    (255 open skin) darkens it and the specular, as the studio's skin look does
    (core/wrinkles/skin_tone.py). Nothing changes where every weight is 0."""
    maps = SETUP["wrinkle_maps"]
    shares = [(m, share) for m, share in shares if "cavity" in maps[m] or "colour" in maps[m]]
    if not shares:
        return
    ones = nodes.new("ShaderNodeCombineXYZ")
    ones.location = (-700.0, -1600.0)
    for socket in ones.inputs:
        socket.default_value = 1.0
    tint = vector("SCALE", ones.outputs[0], rest, nodes, links, (450.0, -1600.0))
    kept = rest
    for m, share in shares:
        y = -1800.0 - 300 * m
        spec = maps[m].get("colour")
        colour = (texture(image(spec["image"], spec["file"]), -700.0, y).outputs["Color"]
                  if spec else ones.outputs[0])
        scaled = math("MULTIPLY", share, 255.0 / 128.0 if spec else 1.0, 300.0, y)
        tint = vector("ADD", tint, vector("SCALE", colour, scaled, nodes, links, (450.0, y)),
                      nodes, links, (600.0, y))
        spec = maps[m].get("cavity")
        cavity = (texture(image(spec["image"], spec["file"]), -700.0, y - 150).outputs["Color"]
                  if spec else 1.0)
        kept = math("ADD", kept, math("MULTIPLY", share, cavity, 300.0, y - 150), 600.0, y - 150)
    base = bsdf.inputs["Base Color"]
    if base.links:
        albedo = base.links[0].from_socket
    else:
        rgb = nodes.new("ShaderNodeRGB")
        rgb.outputs[0].default_value = base.default_value
        rgb.location, albedo = (600.0, -1400.0), rgb.outputs[0]
    toned = vector("MULTIPLY", albedo, tint, nodes, links, (750.0, -1400.0))
    links.new(vector("SCALE", toned, kept, nodes, links, (900.0, -1400.0)), base)
    specular = bsdf.inputs.get("Specular IOR Level") or bsdf.inputs.get("Specular")
    if specular is not None:
        level = specular.links[0].from_socket if specular.links else specular.default_value
        links.new(math("MULTIPLY", level, kept, 900.0, -1600.0), specular)


def not_face_gate(obj, nodes, links, math):
    """1 on the skin, 0 on the parts marked not face (the glTF's vertex attribute, imported
    by Blender as a mesh attribute), None where the mesh has no such attribute."""
    spec = SETUP.get("not_face")
    if not spec or spec["attribute"] not in obj.data.attributes:
        return None
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_name, attribute.location = spec["attribute"], (-1000.0, 400.0)
    split = nodes.new("ShaderNodeSeparateXYZ")
    split.location = (-850.0, 400.0)
    links.new(attribute.outputs["Vector"], split.inputs[0])
    return math("SUBTRACT", 1.0, split.outputs["XYZ"[spec["column"]]], -700.0, 400.0)


def vector(operation: str, a, b, nodes, links, location):
    node = nodes.new("ShaderNodeVectorMath")
    node.operation, node.location = operation, location
    links.new(a, node.inputs[0])
    links.new(b, node.inputs["Scale"] if operation == "SCALE" else node.inputs[1])
    return node.outputs[0]


if __name__ == "__main__":
    build(face_object())
