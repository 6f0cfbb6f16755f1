"""The names a glTF export gives the studio's vertex attributes and images, apart from the codec
(core/formats/gltf/codec.py, which uses them): the Blender script (blender_material.py) reads
them too, and is shipped by the codec beside every glTF, so it must not import the codec."""

from __future__ import annotations

from studio.core.project.model import Project

VERTEX_DATA = "_WELD_NOTFACE_TILE"


def wdv_attributes(n: int) -> tuple[str, str]:
    """The two VEC3 attributes of technique-2 area ``n``: its directions, and (length, painted
    cone angle in degrees — 0 the area's own —, 1 where the area's cones are painted)."""
    return f"_WRINKLE_DIR_{n}", f"_WRINKLE_LEN_CONE_{n}"


def image_names(project: Project) -> tuple[list[str], list[str]]:
    """The names the export gives the wrinkled maps' and the masks' images. The studio's extras
    (and the Blender script, core/formats/blender_material.py) refer to images by these: other
    tools keep names and renumber images."""
    return (["normal_wrinkled", *(f"wrinkled: {name}"
                                  for name in project.textures.wrinkle_map_names[1:])],
            [f"mask: {a.name}" for a in project.influence.areas])
