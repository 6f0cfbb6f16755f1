"""The studio's set-up after another tool re-encoded its images (Blender's exporter with Images
set to JPEG or WebP).

The set-up rides in the neutral normal map's PNG data (core/formats/gltf/carry.py); a JPEG or
WebP copy of the map has none. What such a re-export still holds of the studio's: the second
UV map (``TEXCOORD_1``: the welding and the UDIM tiles), the images under the names the studio
gave them (``mask: AREA``, the wrinkled maps) and the variant materials ``wrinkled map: MAP``
that name the wrinkled maps (``skin, wrinkled: MAP`` with the map as its normal texture in
files written before), and the timeline as the weights animation. From those the set-up's
areas, masks and maps are rebuilt, with one line saying what could not come back and why.
"""

from __future__ import annotations

from studio.core.formats.gltf.carry import STUDIO_UV
from studio.core.formats.gltf.container import _Gltf, _list
from studio.core.formats.gltf.materials import texture_source

NEUTRAL_IMAGE = "normal_neutral"  # the name the export gives the neutral normal map's image
MASK_PREFIX = "mask: "
MAP_PREFIX = "wrinkled map: "  # a wrinkled map shown as a picture (its base colour)
VARIANT_PREFIX = "skin, wrinkled: "  # older files: the map as a skin's normal texture
FORMATS = {"image/jpeg": "JPEG", "image/webp": "WebP"}


def survived_setup(g: _Gltf, attrs: dict) -> tuple[dict, str] | None:
    """(extras naming what survived, the line saying what was lost) for a studio export whose
    images another tool re-encoded; None for any other file."""
    images = [spec if isinstance(spec, dict) else {} for spec in _list(g, g.doc, "images")]
    names = [spec.get("name") for spec in images]
    if NEUTRAL_IMAGE not in names or STUDIO_UV not in attrs:
        return None
    neutral = images[names.index(NEUTRAL_IMAGE)]
    kind = FORMATS.get(str(neutral.get("mimeType", "")))
    if kind is None and "uri" in neutral:
        kind = next((f for f in ("JPEG", "WebP") if str(neutral["uri"]).lower().endswith(
            (".jpg", ".jpeg") if f == "JPEG" else ".webp")), None)
    if kind is None:
        return None  # a PNG without the set-up: not a re-encoding
    areas = [n[len(MASK_PREFIX):] for n in names
             if isinstance(n, str) and n.startswith(MASK_PREFIX)]
    maps, unshown = [], []
    for material in _list(g, g.doc, "materials"):
        name = material.get("name", "") if isinstance(material, dict) else ""
        info = _map_texture(material, name)
        if info is not None:
            maps.append({"name": name.split(": ", 1)[1], "image": names[texture_source(g, info)]})
        elif isinstance(name, str) and name.startswith(MASK_PREFIX) and name not in names:
            unshown.append(name[len(MASK_PREFIX):])  # its material came, its mask did not
    extras = {"influence": {"areas": [{"name": a, "image": MASK_PREFIX + a} for a in areas],
                            "links": {}},
              "wrinkle_maps": maps}
    line = (f"the studio's set-up rides in the neutral normal map's PNG data, which the "
            f"other tool dropped when it wrote the images as {kind}: rebuilt from what survived "
            f"(the welding from {STUDIO_UV}, {len(areas)} areas from their masks, {len(maps)} "
            "wrinkled maps, the timeline's keys); lost: the links, response curves"
            + (f", {len(unshown)} areas (the other tool wrote their masks' materials without "
               "their images)" if unshown else "")
            + " and technique-2 areas (set them up again with Auto Setup, or export the images "
            "as PNG to keep them)")
    return extras, line


def _map_texture(material: object, name: object) -> dict | None:
    """The texture reference of a material showing a wrinkled map, None for any other."""
    if not (isinstance(material, dict) and isinstance(name, str)):
        return None
    if name.startswith(MAP_PREFIX):
        info = (material.get("pbrMetallicRoughness") or {}).get("baseColorTexture")
    elif name.startswith(VARIANT_PREFIX):
        info = material.get("normalTexture")
    else:
        return None
    return info if isinstance(info, dict) else None
