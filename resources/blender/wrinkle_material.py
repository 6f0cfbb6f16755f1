"""Wrinkle Studio's techniques 1 and 2 in Blender: run this in Blender (Scripting ▸ Run Script,
or ``blender --python blender_wrinkles.py``) with the studio's export imported (it imports the
model beside it if no mesh with the face's shape keys is in the scene).

It rebuilds the face's material so that moving a shape key shows its wrinkles in the viewport
and in renders (Cycles and EEVEE): the normal map is the neutral map blended with the wrinkled
maps by one weight per wrinkled map (scaled down where they add past 1), as the studio's shader
does; where the export wrote a wrinkled map's cavity and colour maps, they are blended by the
same weights and tint and darken the base colour (the cavity the specular too), as the studio's
skin look does. The object's custom property ``wrinkle_technique`` (1 or 2) chooses the weights:

1. areas and links: each area's activation is a driver on the shape keys that link to it (its
   own value plus gain × response curve of each, clamped to 0…1); a map's weight is the sum of
   its areas' masks × activations (clamped).
2. wrinkle direction vectors: a Geometry Nodes modifier after the shape keys takes each
   vertex's motion (its position less the ``rest_position`` Blender keeps from before the shape
   keys, less what the poses' onsets hold back: drivers on those shape keys) against each
   area's direction, authored length and cone (the glTF's vertex attributes, read by Named
   Attribute nodes): ``clamp(m · (1 − α/θ) · k, 0, 1)``, m the motion over the authored length,
   α its angle to the direction, θ the cone, 0 outside it; a map's weight is the strongest of
   its areas', stored per vertex and read by the material's Attribute nodes, interpolated as the
   studio's vertex shader's result is. (Per vertex, so EEVEE's limit of attributes per material
   holds for any number of areas.)

The drivers are simple expressions (min, max, arithmetic), so they run without Blender's
"Auto Run Python Scripts". The object's custom property ``wrinkle_strength`` (0…1) scales every
weight: 0 shows the face without wrinkles.

Written by the studio's export; SETUP below is this face's set-up.
"""

import json
from pathlib import Path

import bpy
import numpy as np

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


def image(name: str, file: str | None):
    """An image the glTF import brought (by name), else the export folder's file."""
    found = bpy.data.images.get(name)
    if found is None and file is None:
        raise RuntimeError(f"no image '{name}' in the scene: import the studio's "
                           f"{SETUP['model']} again (its images are inside it)")
    if found is None:
        found = bpy.data.images.load(str(folder() / file), check_existing=True)
    found.colorspace_settings.name = "Non-Color"
    return found


def driven(nodes, obj, label: str, expression: str, variables: dict, location):
    """A Value node that is a driver: ``expression`` of ``variables`` (name → ("OBJECT", a
    custom property's path) or ("KEY", a shape key's))."""
    value = nodes.new("ShaderNodeValue")
    value.label, value.location = label, location
    driver = value.outputs[0].driver_add("default_value").driver
    driver.type = "SCRIPTED"
    for name, (kind, path) in variables.items():
        var = driver.variables.new()
        var.name = name
        var.targets[0].id_type = kind
        var.targets[0].id = obj if kind == "OBJECT" else obj.data.shape_keys
        var.targets[0].data_path = path
    driver.expression = expression
    return value.outputs[0]


def shape_key(pose: str) -> tuple[str, str]:
    return "KEY", f'key_blocks["{pose}"].value'


STRENGTH = ("OBJECT", '["wrinkle_strength"]')


def activation(nodes, obj, area: dict, location):
    """Technique 1: the area's activation, following the shape keys."""
    terms = [repr(area["activation"])]
    variables = {"strength": STRENGTH}
    for k, link in enumerate(area["links"]):
        variables[f"p{k}"] = shape_key(link["pose"])
        terms.append(link["term"].format(x=f"p{k}"))  # gain × its response curve of x
    return driven(nodes, obj, f"activation: {area['name']}",
                  f"strength * min(max({' + '.join(terms)}, 0.0), 1.0)", variables, location)


def build(obj) -> None:
    obj["wrinkle_strength"] = 1.0
    obj["wrinkle_technique"] = SETUP["technique"]
    obj.add_rest_position_attribute = True  # technique 2 measures the motion from it
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
        return node_math(nodes, links, operation, a, b, (x, y), clamp)

    maps = SETUP["wrinkle_maps"]
    weights = []
    for m in range(len(maps)):  # technique 1: w_m = clamp(sum of mask x activation of its areas)
        total = None
        for k, area in enumerate(a for a in SETUP["areas"] if a["map"] == m):
            y = -300.0 * (len(weights) * 8 + k)
            mask = texture(image(area["image"], area["file"]), -1400.0, y)
            value = activation(nodes, obj, area, (-1400.0, y - 150))
            product = math("MULTIPLY", mask.outputs["Color"], value, -1100.0, y)
            total = product if total is None else math("ADD", total, product, -900.0, y)
        weights.append(None if total is None
                       else math("ADD", total, 0.0, -700.0, -300.0 * m, clamp=True))
    t2 = wdv_weights(obj, nodes, math, len(maps))
    used = [(m, w) for m, w in enumerate(choose_technique(obj, nodes, math, weights, t2))
            if w is not None]
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


def choose_technique(obj, nodes, math, t1: list, t2: list) -> list:
    """Each map's weight: technique 1's or technique 2's, as ``wrinkle_technique`` says."""
    second = driven(nodes, obj, "technique 2", "min(max(t - 1.0, 0.0), 1.0)",
                    {"t": ("OBJECT", '["wrinkle_technique"]')}, (-900.0, 900.0))
    first = math("SUBTRACT", 1.0, second, -750.0, 900.0)
    out = []
    for m, (a, b) in enumerate(zip(t1, t2, strict=True)):
        parts = [math("MULTIPLY", w, s, -650.0, 900.0 - 150 * m)
                 for w, s in ((a, first), (b, second)) if w is not None]
        out.append(None if not parts else parts[0] if len(parts) == 1
                   else math("ADD", *parts, -600.0, 900.0 - 150 * m))
    return out


T2_ATTRIBUTE = "wrinkle_t2_{}"  # technique 2's weight of wrinkled map {}, per vertex


def wdv_weights(obj, nodes, math, n_maps: int) -> list:
    """Technique 2: each wrinkled map's weight (None for a map no area reveals; all None
    where the import lost the vertex attributes), worked out per vertex by the modifier
    (wdv_modifier) and read here interpolated, as the studio's vertex shader hands it on."""
    revealed = wdv_modifier(obj)
    strength = driven(nodes, obj, "technique 2 strength", "strength", {"strength": STRENGTH},
                      (-1900.0, 1650.0))
    out = []
    for m in range(n_maps):
        if m not in revealed:
            out.append(None)
            continue
        weight = nodes.new("ShaderNodeAttribute")
        weight.attribute_name = T2_ATTRIBUTE.format(m)
        weight.location = (-1900.0, 1500.0 - 200.0 * m)
        out.append(math("MULTIPLY", weight.outputs["Fac"], strength, -1700.0, 1500.0 - 200 * m))
    return out


def wdv_modifier(obj) -> set[int]:
    """A Geometry Nodes modifier (after the shape keys) that stores, per vertex, each wrinkled
    map's technique-2 weight as ``T2_ATTRIBUTE``; returns the maps it stores."""
    spec = SETUP["wdv"]
    names = obj.data.attributes.keys()
    areas = [a for a in spec["areas"] if a["directions"] in names and a["sizes"] in names]
    if not areas:
        return set()
    tree = bpy.data.node_groups.new("wrinkle vectors", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links

    def math(operation: str, a, b, x: float, y: float, clamp: bool = False):
        return node_math(nodes, links, operation, a, b, (x, y), clamp)

    motion = face_motion(obj, nodes, links, math)
    length = vector("LENGTH", motion, None, nodes, links, (-1900.0, 1500.0), "Value")
    out = {}
    for k, area in enumerate(areas):
        x, y = -1800.0, 2000.0 + 400.0 * k
        directions, _ = named(nodes, links, area["directions"], (x, y))
        _, sizes = named(nodes, links, area["sizes"], (x, y - 200.0))
        unit = vector("NORMALIZE", directions, None, nodes, links, (x + 300, y))
        along = vector("DOT_PRODUCT", motion, unit, nodes, links, (x + 450, y), "Value")
        angle = math("ARCCOSINE", math("DIVIDE", along, length, x + 600, y), 0.0, x + 750, y)
        painted = sizes["Y"]  # a painted cone of 0 is the area's
        cone = math("ADD", math("MULTIPLY", math("GREATER_THAN", painted, 0.0, x + 300, y - 300),
                                math("SUBTRACT", painted, area["cone"], x + 300, y - 350),
                                x + 450, y - 300), area["cone"], x + 600, y - 300)
        cone = math("RADIANS", cone, 0.0, x + 750, y - 300)
        falloff = math("SUBTRACT", 1.0, math("DIVIDE", angle, cone, x + 900, y), x + 1050, y)
        size = (math("DIVIDE", length, sizes["X"], x + 900, y - 150) if spec["scale_free"]
                else length)
        w = math("MULTIPLY", math("MULTIPLY", size, falloff, x + 1200, y),
                 spec["expression_factor"], x + 1350, y, clamp=True)
        w = math("MULTIPLY", w, math("GREATER_THAN", cone, 0.0, x + 900, y - 300), x + 1500, y)
        m = area["map"]
        out[m] = w if m not in out else math("MAXIMUM", out[m], w, x + 1650, y)
    geometry = nodes.new("NodeGroupInput").outputs[0]
    for m, w in out.items():
        store = nodes.new("GeometryNodeStoreNamedAttribute")
        store.data_type, store.domain, store.location = "FLOAT", "POINT", (200.0, -200.0 * m)
        store.inputs["Name"].default_value = T2_ATTRIBUTE.format(m)
        links.new(geometry, store.inputs["Geometry"])
        links.new(w, store.inputs["Value"])
        geometry = store.outputs["Geometry"]
    links.new(geometry, nodes.new("NodeGroupOutput").inputs[0])
    obj.modifiers.new("wrinkle vectors", "NODES").node_group = tree
    return set(out)


def named(nodes, links, name: str, location):
    """The mesh attribute ``name`` as a vector, and split into its three columns."""
    node = nodes.new("GeometryNodeInputNamedAttribute")
    node.data_type, node.location = "FLOAT_VECTOR", location
    node.inputs["Name"].default_value = name
    split = nodes.new("ShaderNodeSeparateXYZ")
    split.location = (location[0] + 150.0, location[1])
    links.new(node.outputs["Attribute"], split.inputs[0])
    return node.outputs["Attribute"], split.outputs


def face_motion(obj, nodes, links, math):
    """Each vertex's motion from the neutral face as the studio measures it, in the glTF's
    axes (the direction attributes' and the studio's): its position less ``rest_position``,
    less each pose with an onset times the weight its onset holds back."""
    position = nodes.new("GeometryNodeInputPosition")
    position.location = (-2600.0, 1500.0)
    rest, _ = named(nodes, links, "rest_position", (-2600.0, 1300.0))
    motion = vector("SUBTRACT", position.outputs["Position"], rest, nodes, links,
                    (-2300.0, 1500.0))
    blocks = obj.data.shape_keys.key_blocks
    for k, held in enumerate(h for h in SETUP["wdv"]["held"] if h["pose"] in blocks):
        name = f"wrinkle_held_{k}"
        store_shape(obj, blocks[held["pose"]], name)
        shape, _ = named(nodes, links, name, (-2600.0, 1100.0 - 200.0 * k))
        factor = driven(nodes, obj, f"held back: {held['pose']}", held["term"].format(x="w"),
                        {"w": shape_key(held["pose"])}, (-2450.0, 1000.0 - 200.0 * k))
        back = vector("SCALE", shape, factor, nodes, links, (-2300.0, 1100.0 - 200.0 * k))
        motion = vector("SUBTRACT", motion, back, nodes, links, (-2150.0, 1500.0 - 50.0 * k))
    split = nodes.new("ShaderNodeSeparateXYZ")
    split.location = (-2000.0, 1500.0)
    links.new(motion, split.inputs[0])
    axes = nodes.new("ShaderNodeCombineXYZ")  # Blender's (x, -z, y) is the glTF's (x, y, z)
    axes.location = (-1850.0, 1500.0)
    links.new(split.outputs["X"], axes.inputs["X"])
    links.new(split.outputs["Z"], axes.inputs["Y"])
    links.new(math("MULTIPLY", split.outputs["Y"], -1.0, -1950.0, 1350.0), axes.inputs["Z"])
    return axes.outputs[0]


def store_shape(obj, block, name: str) -> None:
    """A shape key's offset from its reference key, as a point attribute ``name``."""
    n = len(obj.data.vertices)
    shape, reference = np.empty(3 * n, np.float32), np.empty(3 * n, np.float32)
    block.data.foreach_get("co", shape)
    block.relative_key.data.foreach_get("co", reference)
    if name in obj.data.attributes:
        obj.data.attributes.remove(obj.data.attributes[name])
    obj.data.attributes.new(name, "FLOAT_VECTOR", "POINT").data.foreach_set(
        "vector", shape - reference)


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


def node_math(nodes, links, operation: str, a, b, location, clamp: bool = False):
    """A Math node of ``a`` and ``b`` (sockets or numbers), in a material or a node group."""
    node = nodes.new("ShaderNodeMath")
    node.operation, node.use_clamp, node.location = operation, clamp, location
    for socket, value in zip(node.inputs[:2], (a, b), strict=True):
        if isinstance(value, float):
            socket.default_value = value
        else:
            links.new(value, socket)
    return node.outputs[0]


def vector(operation: str, a, b, nodes, links, location, output: str = "Vector"):
    """A Vector Math node of ``a`` and ``b`` (None for one-input operations)."""
    node = nodes.new("ShaderNodeVectorMath")
    node.operation, node.location = operation, location
    links.new(a, node.inputs[0])
    if b is not None:
        links.new(b, node.inputs["Scale"] if operation == "SCALE" else node.inputs[1])
    return node.outputs[output]


if __name__ == "__main__":
    build(face_object())
