"""The Blender script every glTF export carries (``blender_wrinkles.py``): run in Blender with
the exported model, it builds techniques 1 and 2 into the face's material, driven by the shape
keys (resources/blender/wrinkle_material.py), so moving a shape key shows its wrinkles in
Blender's viewport and renders; the object's ``wrinkle_technique`` (1 or 2) chooses.

Why a script and not a material in the glTF: glTF has no way to say "this weight follows that
morph target through this curve"; Blender's drivers do, and the studio's links, gains and
response curves map onto them one for one. The script is the template with this face's set-up
written into it as JSON: the images by the names the glTF gives them (the folder's files
beside them, where a name is missing), each area's wrinkled map, own activation and links, and
each technique-2 area's vertex attributes, cone and wrinkled map.
"""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path

from studio.core.files.atomic_write import write_atomic
from studio.core.formats.gltf_names import VERTEX_DATA, image_names, wdv_attributes
from studio.core.project.model import Project
from studio.core.project.view_settings import saved_view
from studio.core.wrinkles.response import ResponseCurve, curve_of
from studio.paths import resource_dir

TEMPLATE = "blender/wrinkle_material.py"
PLACEHOLDER = 'SETUP = json.loads("{}")'
SCRIPT = "blender_wrinkles.py"


def blender_setup(project: Project, model: str, mask_files: list[str] | None = None,
                  map_files: list[dict] | None = None, neutral_file: str | None = None) -> dict:
    """What the script needs of the face: the model and image files relative to the export
    folder (used where the imported model lacks an image of the name; None beside a plain
    glTF, whose images are all inside it). ``map_files``: each wrinkled map's ``image`` file
    and, where it has them, its ``cavity`` and ``colour`` files (the glTF holds neither: found
    by file)."""
    influence, textures = project.influence, project.textures
    map_images, mask_images = image_names(project)
    mask_files = mask_files or [None] * len(mask_images)
    map_files = map_files or [{"image": None}] * len(map_images)
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
            "wrinkle_maps": [{"name": name, "image": image, "file": files["image"],
                              **{kind: {"image": Path(files[kind]).stem, "file": files[kind]}
                                 for kind in ("cavity", "colour") if kind in files}}
                             for name, image, files in zip(textures.wrinkle_map_names,
                                                           map_images, map_files, strict=True)],
            "areas": areas,
            # the parts never wrinkled: column 1 of the glTF's per-vertex data
            **({"not_face": {"attribute": VERTEX_DATA, "column": 1}}
               if project.not_face is not None else {}),
            "technique": 1 if saved_view(project.view).technique == "t1" else 2,
            "wdv": wdv_setup(project)}


def wdv_setup(project: Project) -> dict:
    """Technique 2 as the script reads it: per enabled area, its two vertex attributes (as the
    glTF names them, core/formats/gltf/codec.py), its cone and wrinkled map; the formula's
    constants; and the onset of every pose that has one (the script holds those poses' motion
    back, as the studio's WrinkleDrive does)."""
    wdv, textures = project.wdv, project.textures
    areas = [{"name": area.name, "pose": area.pose,
              **dict(zip(("directions", "sizes"), wdv_attributes(n), strict=True)),
              "cone": float(area.cone_angle_deg), "map": textures.map_index(area.wrinkle_map)}
             for n, area in enumerate(wdv.areas) if area.enabled]
    onsets = {pose.name: project.furrows.of(pose.name).onset for pose in project.poses}
    return {"areas": areas, "expression_factor": float(wdv.expression_factor),
            "scale_free": bool(wdv.scale_free),
            "held": [{"pose": pose, "term": held_term(onset)}
                     for pose, onset in onsets.items() if onset > 0.0]}


def link_term(gain: float, curve: ResponseCurve, onset: float = 0.0) -> str:
    """A link's contribution, ``gain · curve(x)``, as a Blender driver's simple expression of
    ``{x}`` (the shape key's variable, filled in by the script): min, max and arithmetic only,
    so it runs without "Auto Run Python Scripts". The same curves as core/wrinkles/response.py:
    the cubics in t = clamp((x - start) / (end - start), 0, 1), custom points piecewise linear
    and flat beyond the ends. A pose's onset is baked in: the weight goes through
    ``response.onset_weight`` first (an onset of 0 leaves the expression as it was)."""
    x = onset_term(onset)
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


def onset_term(onset: float) -> str:
    """The weight ``{x}`` as the wrinkles see it with ``onset``
    (``response.onset_weight``), as a driver's simple expression."""
    return "{x}" if onset <= 0.0 else f"max(({{x}} - {onset!r}) / {1.0 - onset!r}, 0.0)"


def held_term(onset: float) -> str:
    """How much of a pose's shape technique 2 does not measure at weight ``{x}``: the weight
    less what its onset lets through (so the motion measured is the studio's drive)."""
    return f"{{x}} - {onset_term(onset)}"


def ship_blender_script(project: Project, model: str | Path) -> Path:
    """Write the script beside the export ``model`` (a plain glTF: every image inside it);
    returns its path."""
    path = Path(model).with_name(SCRIPT)
    write_atomic(path, blender_script(blender_setup(project, Path(model).name)),
                 what="Blender script")
    return path


def blender_script(setup: dict) -> bytes:
    """The template with ``setup`` written in (as a Python string literal of its JSON)."""
    template = (resource_dir() / TEMPLATE).read_text(encoding="utf-8")
    if template.count(PLACEHOLDER) != 1:
        raise ValueError(f"{TEMPLATE} must hold '{PLACEHOLDER}' once")
    text = json.dumps(setup, separators=(",", ":"))
    return template.replace(PLACEHOLDER, f"SETUP = json.loads({text!r})").encode("utf-8")
