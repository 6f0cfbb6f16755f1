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

from urllib.parse import unquote

import numpy as np

from studio.core.files.errors import ImageError, MeshError
from studio.core.files.naming import shown
from studio.core.formats.gltf.container import _Gltf, _item, _list, _whole
from studio.core.formats.gltf.face import FaceChoice, MergedFace
from studio.core.formats.gltf.scene import Primitive
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import (
    FIRST_TILE,
    UvTiles,
    atlas_size,
    compose_atlas,
    pack_mesh,
    tile_origin,
)
from studio.core.wrinkles.textures import (
    MAP_WORDS,
    SKIN,
    FaceTextures,
    flat_normal_map,
    plain_diffuse,
)

Array = np.ndarray
FLAT_NORMAL = (128, 128, 255)
EDGE = 1e-3  # UVs this far outside 0–1 still count as inside (rounding at the square's edge)
CLEAR_ALPHA = 128  # a texel under half opaque is see-through (glTF's default alphaCutoff)
MOSTLY_CLEAR = 0.5  # a primitive whose texture is see-through over this share of it is a card


def _rgb(image: Array | None, fallback: Array | None = None) -> Array | None:
    """An image as RGB (grey repeated, alpha dropped), ``fallback`` when there is none."""
    if image is None:
        return fallback
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    return np.ascontiguousarray(image[:, :, :3])


def texture_source(g: _Gltf, info: dict) -> int:
    """The image a texture reference shows (its EXT_texture_webp source where it has one)."""
    try:
        texture = _item(g, "textures", info["index"])
        webp = (texture.get("extensions") or {}).get("EXT_texture_webp") or {}
        return webp["source"] if "source" in webp else texture["source"]
    except (MeshError, KeyError, TypeError):
        raise MeshError("a material refers to a texture that does not exist", g.path) from None


def image_data(g: _Gltf, index: int) -> bytes | None:
    """An image's encoded bytes as the file holds them (None for an image behind a URI): what
    rides in them beside the pixels (core/formats/gltf/carry.py) is read from these."""
    spec = _item(g, "images", index)
    if "bufferView" not in spec:
        return None
    view = _item(g, "bufferViews", spec["bufferView"])
    start, length = view.get("byteOffset", 0), view.get("byteLength")
    buffer = _item(g, "buffers", view.get("buffer"), g.buffers)
    if not (_whole(start) and _whole(length)) or start + length > len(buffer):
        raise MeshError(f"image {index}'s buffer view is out of its buffer", g.path)
    return bytes(memoryview(buffer)[start:start + length])


def image_index(g: _Gltf, ref: object) -> int:
    """An image named by the studio's extras: by its name (what other tools keep; Blender cuts
    names at 63 bytes), or by its index (files written before names)."""
    if not isinstance(ref, str):
        return ref  # type: ignore[return-value]  # an index: g.image checks it
    names = [spec.get("name") if isinstance(spec, dict) else None
             for spec in _list(g, g.doc, "images")]
    cut = ref.encode("utf-8")[:63].decode("utf-8", "ignore")
    for wanted in (ref, cut):
        if wanted in names:
            return names.index(wanted)
    raise MeshError(f"the studio's extras name an image '{ref}' the file does not hold", g.path)


def wrinkle_image(g: _Gltf, material: dict) -> Array | None:
    """The wrinkled normal map a material's extras name (``wrinkleNormalTexture``): by the
    image's name where it gives one (another tool may have renumbered the textures and copied
    the extras as they were), else by the texture's index."""
    info = (material.get("extras") or {}).get("wrinkleNormalTexture")
    if isinstance(info, dict) and isinstance(info.get("image"), str):
        try:
            return g.image(image_index(g, info["image"]))
        except MeshError:
            pass  # renamed too: the index, as the file says
    return g.texture_image(info) if isinstance(info, dict) else None


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


def shown_texture(g: _Gltf, info: dict | None, material: dict, slot: str,
                  lines: list[str]) -> Array | None:
    """A material's base-colour or normal texture (``slot``: "diffuse" or "normal"), None
    when it has none, or when its image file is missing or unreadable: that is said in
    ``lines`` and the head keeps plain skin or a flat map (core/formats/head_maps.py), as
    Blender opens such a material untextured. A damaged file structure is still refused."""
    if not (isinstance(info, dict) and "index" in info):
        return None
    word, fallback = MAP_WORDS[slot]
    source = texture_source(g, info)
    spec = _item(g, "images", source)
    said = (f"{word}: image {shown(spec.get('uri') or source)} of material "
            f"{shown(material.get('name') or '(unnamed)')}")
    uri = spec.get("uri")
    if isinstance(uri, str) and not uri.startswith("data:") and ":" not in uri.split("/")[0] \
            and not (g.path.parent / unquote(uri)).is_file():
        lines.append(f"{said} not found beside the file: {fallback}")
        return None
    try:
        return _rgb(g.image(source))
    except ImageError as exc:
        lines.append(f"{said} is unreadable ({exc.problem}): {fallback}")
        return None


def atlas_textures(g: _Gltf, choice: FaceChoice, merged: MergedFace, lines: list[str]
                   ) -> tuple[FaceMesh, UvTiles | None, FaceTextures]:
    """The face's mesh with its UVs in the atlas, its tiles, and the maps; the mesh as it was,
    no tiles and the skin material's own maps when one material (or a UDIM layout) serves.
    A texture missing or unreadable is said in ``lines`` (``shown_texture``)."""
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
        return mesh, None, _own_maps(g, face_material, lines)
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
        image = shown_texture(g, material.get("pbrMetallicRoughness", {}).get(
            "baseColorTexture"), material, "diffuse", lines)
        fill = SKIN if key == face_key else _colour(material)
        diffuse[tile_of_key[key]] = image if image is not None else np.full((4, 4, 3), fill,
                                                                            np.uint8)
        bump = shown_texture(g, material.get("normalTexture"), material, "normal", lines)
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


def _own_maps(g: _Gltf, material: dict, lines: list[str]) -> FaceTextures:
    """One material's maps as they are (a missing one plain or flat)."""
    pbr = material.get("pbrMetallicRoughness", {})
    diffuse = shown_texture(g, pbr.get("baseColorTexture"), material, "diffuse", lines)
    normal = shown_texture(g, material.get("normalTexture"), material, "normal", lines)
    return FaceTextures(
        diffuse=diffuse if diffuse is not None else plain_diffuse(),
        normal_neutral=normal if normal is not None else flat_normal_map(),
        normal_wrinkled=_rgb(wrinkle_image(g, material), flat_normal_map()))


def see_through(g: _Gltf, choice: FaceChoice) -> dict[tuple[int, int], str]:
    """The kept primitives whose material says they are not skin, and why: alpha-cut
    (``alphaMode`` MASK) or blended (BLEND) — the brow, lash and hair cards of an avatar —
    or a base-colour texture under half opaque over most of the primitive (a card exported
    as opaque). The face's largest primitive is never asked (the skin's texture, the largest,
    is not decoded for it), nor is a primitive without UVs."""
    kept = list(choice.kept)
    if len(kept) < 2:
        return {}
    largest = max(kept, key=lambda k: len(choice.meshes[k[0]].primitives[k[1]].triangles))
    out: dict[tuple[int, int], str] = {}
    alphas: dict[object, Array | None] = {}
    for key in kept:
        if key == largest:
            continue
        prim = choice.meshes[key[0]].primitives[key[1]]
        material = _material(g, prim.material)
        mode = material.get("alphaMode", "OPAQUE")
        if mode == "MASK":
            out[key] = "alpha-cut material"
        elif mode == "BLEND":
            out[key] = "blended material"
        elif prim.has_uvs:
            info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture")
            if not (isinstance(info, dict) and "index" in info):
                continue
            if info["index"] not in alphas:
                alphas[info["index"]] = _alpha(g.texture_image(info))
            alpha = alphas[info["index"]]
            if alpha is not None and _clear_share(alpha, prim) > MOSTLY_CLEAR:
                out[key] = "mostly transparent texture"
    return out


def _alpha(image: Array | None) -> Array | None:
    """An image's alpha channel as 0–255 (None without one: opaque)."""
    if image is None or image.ndim != 3 or image.shape[2] not in (2, 4):
        return None
    alpha = image[:, :, -1]
    return (alpha // 257).astype(np.uint8) if alpha.dtype == np.uint16 else alpha


def _clear_share(alpha: Array, prim: Primitive) -> float:
    """The share of a primitive's area (its triangles' corners and centres, area-weighted)
    where its texture is see-through: its UVs repeat, v up."""
    p = prim.positions[prim.triangles]
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    if area.sum() <= 0:
        return 0.0
    uv = prim.uvs[prim.triangles]  # (m, 3, 2)
    points = np.concatenate([uv, uv.mean(axis=1, keepdims=True)], axis=1)  # corners, centre
    h, w = alpha.shape
    col = np.floor(np.mod(points[..., 0], 1.0) * w).astype(np.int64).clip(0, w - 1)
    row = np.floor(np.mod(1.0 - points[..., 1], 1.0) * h).astype(np.int64).clip(0, h - 1)
    clear = (alpha[row, col] < CLEAR_ALPHA).mean(axis=1)
    return float(np.sum(clear * area) / area.sum())
