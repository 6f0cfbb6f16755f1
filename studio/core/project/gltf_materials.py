"""A glTF face's materials as one set of maps: each material its own cell of an atlas.

The meshes of an avatar each have a material with its own images over the whole 0–1 UV square
(the head's skin, the eyes', the teeth'): one diffuse map cannot serve them all as they lie. So
each distinct base-colour image (or each material without one) gets its own UDIM tile, the
skin's 1001, and the face is packed as a UDIM face is (core/mesh/uv_tiles.py): the skin a
full-size cell, the rest half-size cells never wrinkled, each image resized into its cell and
a material without an image filled with its base colour. Faces whose UVs already leave the
0–1 square (UDIM layouts) are left as they are; one material needs no atlas.
"""

from __future__ import annotations

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import (
    FIRST_TILE,
    UvTiles,
    atlas_size,
    compose_atlas,
    pack_mesh,
    tile_origin,
)
from studio.core.project.gltf_container import _Gltf
from studio.core.project.gltf_face import FaceChoice, MergedFace
from studio.core.wrinkles.textures import SKIN, FaceTextures, flat_normal_map, plain_diffuse

Array = np.ndarray
FLAT_NORMAL = (128, 128, 255)
EDGE = 1e-3  # UVs this far outside 0–1 still count as inside (rounding at the square's edge)


def _rgb(image: Array | None, fallback: Array | None = None) -> Array | None:
    """An image as RGB (grey repeated, alpha dropped), ``fallback`` when there is none."""
    if image is None:
        return fallback
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    return np.ascontiguousarray(image[:, :, :3])


def _material(g: _Gltf, index: int | None) -> dict:
    return g.doc["materials"][index] if index is not None else {}


def _image_key(g: _Gltf, material: dict, index: int | None) -> object:
    """What decides a tile: the base-colour image's texture, else the material itself."""
    info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture")
    if isinstance(info, dict) and "index" in info:
        return ("texture", info["index"])
    return ("material", index)


def _colour(material: dict) -> tuple[int, int, int]:
    factor = material.get("pbrMetallicRoughness", {}).get("baseColorFactor", (1, 1, 1, 1))
    try:
        red, green, blue = (round(float(c) * 255) for c in list(factor)[:3])
    except (TypeError, ValueError):
        return (255, 255, 255)
    return red, green, blue


def atlas_textures(g: _Gltf, choice: FaceChoice, merged: MergedFace
                   ) -> tuple[FaceMesh, UvTiles | None, FaceTextures]:
    """The face's mesh with its UVs in the atlas, its tiles, and the maps; the mesh as it was,
    no tiles and the skin material's own maps when one material (or a UDIM layout) serves."""
    mesh = merged.mesh
    materials = [choice.meshes[i].primitives[j].material for i, j in choice.kept]
    keys = [_image_key(g, _material(g, m), m) for m in materials]
    sizes = np.bincount(merged.primitive_of_triangle, minlength=len(keys))
    skin = [k for k, key in enumerate(choice.kept) if key not in choice.not_face] or [0]
    face_key = keys[max(skin, key=lambda k: sizes[k])]
    order = [face_key, *dict.fromkeys(k for k in keys if k != face_key)]
    tile_of_key = {key: FIRST_TILE + n for n, key in enumerate(order)}
    uvs = mesh.uvs
    inside = (uvs.min() >= -EDGE) and (uvs.max() <= 1.0 + EDGE)
    face_material = _material(g, materials[keys.index(face_key)])
    if len(order) == 1 or not inside:
        return mesh, None, _own_maps(g, face_material)
    vertex_prim = np.zeros(mesh.n_vertices, np.int64)
    vertex_prim[mesh.triangles] = merged.primitive_of_triangle[:, None]
    tile = np.array([tile_of_key[key] for key in keys])[vertex_prim]
    origin = np.array([tile_origin(t) for t in tile], np.float64).reshape(-1, 2)
    shifted = np.clip(uvs, 0.0, 1.0 - 1e-6) + origin
    skin_vertices = None if merged.not_face is None else ~merged.not_face
    packed, tiles = pack_mesh(FaceMesh(mesh.rest, mesh.triangles, shifted, mesh.weld,
                                       mesh.source), skin_vertices)
    assert tiles is not None  # two tiles at least
    first = {key: materials[keys.index(key)] for key in order}
    diffuse, normal = {}, {}
    for key, index in first.items():
        material = _material(g, index)
        image = _rgb(g.texture_image(material.get("pbrMetallicRoughness", {}).get(
            "baseColorTexture")))
        fill = SKIN if key == face_key else _colour(material)
        diffuse[tile_of_key[key]] = image if image is not None else np.full((4, 4, 3), fill,
                                                                            np.uint8)
        bump = _rgb(g.texture_image(material.get("normalTexture")))
        if bump is not None:
            normal[tile_of_key[key]] = bump
    side = max((max(im.shape[:2]) for im in [*diffuse.values(), *normal.values()]),
               default=256)
    size = atlas_size(tiles.layout, side)
    textures = FaceTextures(
        diffuse=compose_atlas(diffuse, tiles.layout, np.array(SKIN, np.uint8), size),
        normal_neutral=compose_atlas(normal, tiles.layout, np.array(FLAT_NORMAL, np.uint8),
                                     size) if normal else flat_normal_map(),
        normal_wrinkled=flat_normal_map())
    return packed, tiles, textures


def _own_maps(g: _Gltf, material: dict) -> FaceTextures:
    """One material's maps as they are (a missing one plain or flat)."""
    pbr = material.get("pbrMetallicRoughness", {})
    return FaceTextures(
        diffuse=_rgb(g.texture_image(pbr.get("baseColorTexture")), plain_diffuse()),
        normal_neutral=_rgb(g.texture_image(material.get("normalTexture")), flat_normal_map()),
        normal_wrinkled=_rgb(g.texture_image(material.get("extras", {}).get(
            "wrinkleNormalTexture")), flat_normal_map()))
