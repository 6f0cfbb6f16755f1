"""The Blender script an export folder carries (``blender_wrinkles.py``): run in Blender with the
folder's face.glb, it builds technique 1 into the face's material, driven by the shape keys
(resources/blender/wrinkle_material.py), so moving a shape key shows its wrinkles in Blender's
viewport and renders.

Why a script and not a material in the glTF: glTF has no way to say "this weight follows that
morph target through this curve"; Blender's drivers do, and the studio's links, gains and
response curves map onto them one for one. The script is the template with this face's set-up
written into it as JSON: the images by the names the glTF gives them (the folder's files
beside them, where a name is missing), each area's wrinkled map, own activation and links.
"""

from __future__ import annotations

import json
from itertools import pairwise

from studio.core.formats.gltf.codec import VERTEX_DATA, image_names
from studio.core.project.model import Project
from studio.core.wrinkles.response import ResponseCurve, curve_of
from studio.paths import resource_dir

TEMPLATE = "blender/wrinkle_material.py"
PLACEHOLDER = 'SETUP = json.loads("{}")'
SCRIPT = "blender_wrinkles.py"


def blender_setup(project: Project, model: str, mask_files: list[str], map_files: list[str],
                  neutral_file: str) -> dict:
    """What the script needs of the face: the model and image files relative to the export
    folder (used where the imported model lacks an image of the name)."""
    influence, textures = project.influence, project.textures
    map_images, mask_images = image_names(project)
    areas = []
    for area, image, file in zip(influence.areas, mask_images, mask_files, strict=True):
        links = [{"pose": pose, "term": link_term(
                      float(gains[area.name]), curve_of(influence.curves, pose, area.name),
                      project.furrows.of(pose).onset)}
                 for pose, gains in influence.links.items() if gains.get(area.name, 0.0) > 0]
        if area.visible and (links or area.activation > 0):
            areas.append({"name": area.name, "image": image, "file": file,
                          "map": textures.map_index(area.wrinkle_map),
                          "activation": float(area.activation), "links": links})
    return {"model": model,
            "poses": sorted({link["pose"] for a in areas for link in a["links"]}),
            "neutral": {"image": "normal_neutral", "file": neutral_file},
            "wrinkle_maps": [{"name": name, "image": image, "file": file}
                             for name, image, file in zip(textures.wrinkle_map_names,
                                                          map_images, map_files, strict=True)],
            "areas": areas,
            # the parts never wrinkled: column 1 of the glTF's per-vertex data
            **({"not_face": {"attribute": VERTEX_DATA, "column": 1}}
               if project.not_face is not None else {})}


def link_term(gain: float, curve: ResponseCurve, onset: float = 0.0) -> str:
    """A link's contribution, ``gain · curve(x)``, as a Blender driver's simple expression of
    ``{x}`` (the shape key's variable, filled in by the script): min, max and arithmetic only,
    so it runs without "Auto Run Python Scripts". The same curves as core/wrinkles/response.py:
    the cubics in t = clamp((x - start) / (end - start), 0, 1), custom points piecewise linear
    and flat beyond the ends. A pose's onset is baked in: the weight goes through
    ``response.onset_weight`` first (an onset of 0 leaves the expression as it was)."""
    x = "{x}" if onset <= 0.0 else f"max(({{x}} - {onset!r}) / {1.0 - onset!r}, 0.0)"
    if curve.kind == "linear":
        return f"{gain!r} * {x}"
    if curve.kind == "custom":
        points = curve.points
        terms = [repr(float(points[0][1]))]
        for (a, ya), (b, yb) in pairwise(points):
            terms.append(f"{(yb - ya) / (b - a)!r} * (min(max({x}, {a!r}), {b!r}) - {a!r})")
        return f"{gain!r} * ({' + '.join(terms)})"
    t = f"min(max(({x} - {curve.start!r}) / {curve.end - curve.start!r}, 0.0), 1.0)"
    shape = {"ease_in": "{t} ** 2", "ease_out": "(1.0 - (1.0 - {t}) ** 2)",
             "ease_in_out": "(3.0 * {t} ** 2 - 2.0 * {t} ** 3)",
             "smooth_step": "(3.0 * {t} ** 2 - 2.0 * {t} ** 3)"}[curve.kind]
    return f"{gain!r} * " + shape.replace("{t}", f"({t})")


def blender_script(setup: dict) -> bytes:
    """The template with ``setup`` written in (as a Python string literal of its JSON)."""
    template = (resource_dir() / TEMPLATE).read_text(encoding="utf-8")
    if template.count(PLACEHOLDER) != 1:
        raise ValueError(f"{TEMPLATE} must hold '{PLACEHOLDER}' once")
    text = json.dumps(setup, separators=(",", ":"))
    return template.replace(PLACEHOLDER, f"SETUP = json.loads({text!r})").encode("utf-8")
