"""``export --layout``: a planned engine layout written out — the mask textures channel-packed as
the engine samples them, the wrinkle normal maps it expects, the mesh, and a JSON sheet saying
which area, pose and engine region each channel holds.

The plan (core/layout_plan.py) is made and checked first, and every destination is checked
against the inputs, so a refused layout writes nothing. Images go through the atomic writers;
on a UDIM face each texture is the packed atlas (the glTF's UVs) plus one copy per skin tile.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from functools import partial
from pathlib import Path

import numpy as np

from studio.core.engines.layouts import CHANNELS, MODEL_FILE
from studio.core.engines.plan import MapSlot, MaskTexture, Plan, linked_poses, plan_export
from studio.core.engines.tone_maps import tone_images
from studio.core.files.atomic_write import write_atomic
from studio.core.files.images import write_image
from studio.core.files.safe_io import check_output
from studio.core.formats.export import (
    export_folder,
    make_folders,
    onsets_note,
    quantise,
    tile_copies,
    uv_tiles_note,
)
from studio.core.formats.gltf.codec import save_gltf
from studio.core.project.model import Project
from studio.core.wrinkles.textures import resize_nearest

Array = np.ndarray
SHEET = "engine_layout.json"
FLEX_TABLE = "flex_wrinkles.csv"  # Source: per-vertex wrinkle weight of each flex


def export_layout(project: Project, folder: str | Path, key: str, bits: int = 16,
                  inputs: Iterable[str | Path | None] = (),
                  tangent_frame: str | None = None,
                  merge: bool = False) -> tuple[Plan, list[Path]]:
    """Write the layout ``key`` into ``folder``; (the plan, the files written). The model's
    tangents are in ``tangent_frame`` (default: the project's saved view's), the frame the
    maps were made for. ``merge``: fold the weakest masks into others where the engine holds
    fewer than the project has and that can be done (``plan.merged`` says which).

    Raises a LayoutError (nothing written) when the engine cannot hold the project, and a
    StudioError when a destination is one of ``inputs`` or cannot be written.
    """
    plan = plan_export(project, key, merge)
    plan.check()
    folder = Path(folder)
    inputs = list(inputs)
    for name in planned_files(plan):
        check_output(folder / name, inputs, make_folders=True, what="export file")
    if plan.layout.kind == "per_area":  # the studio's own folder export, as it always was
        written = export_folder(project, folder, bits, tangent_frame)
    else:
        written = _write_engine(project, plan, folder, tangent_frame)
    sheet = folder / SHEET
    write_atomic(sheet, json.dumps(layout_sheet(project, plan), indent=2).encode("utf-8"),
                 what="layout sheet")
    return plan, [*written, sheet]


def planned_files(plan: Plan) -> list[str]:
    """The atlases the layout writes (relative paths), the model and the sheet."""
    extra = [FLEX_TABLE, "maps/compress.png", "maps/stretch.png"] if plan.flexes else []
    return [MODEL_FILE, SHEET, *(m.file for m in plan.masks), *(m.file for m in plan.maps),
            *extra]


def _write_engine(project: Project, plan: Plan, folder: Path,
                  tangent_frame: str | None) -> list[Path]:
    files = planned_files(plan)
    make_folders(folder, sorted({str(Path(f).parent) for f in files}))
    written = [folder / MODEL_FILE]
    save_gltf(project, written[0], tangent_frame)
    for texture in plan.masks:
        written += _write_tiled(project, folder / texture.file, mask_texture(project, texture))
    for slot in plan.maps:
        written += _write_tiled(project, folder / slot.file, map_image(project, slot))
        for path, image in tone_images(project, plan.layout.key, slot.file, partial(
                slot_image, project, slot)):
            written += _write_tiled(project, folder / path, image)
    if plan.flexes:  # VertexLitGeneric's $compress and $stretch: the skin's own colour
        for name in ("compress", "stretch"):
            written += _write_tiled(project, folder / "maps" / f"{name}.png",
                                    project.textures.diffuse)
        table = folder / FLEX_TABLE
        write_atomic(table, flex_table(project, plan).encode("utf-8"), what="flex table")
        written.append(table)
    return written


def _write_tiled(project: Project, path: Path, image: Array) -> list[Path]:
    write_image(path, image)
    return [path, *tile_copies(project, path, image, write_image)]


def channel_values(project: Project, sources: Sequence[tuple[int, float]]) -> Array:
    """(H, W) float32: the areas' masks times their gains, added and clamped to [0, 1]."""
    areas = project.influence.areas
    shape = project.influence.resolution or project.textures.normal_neutral.shape[:2]
    values = np.zeros(shape, np.float32)
    for i, gain in sources:
        values += np.float32(gain) * areas[i].mask
    return np.clip(values, 0.0, 1.0)


def mask_texture(project: Project, texture: MaskTexture) -> Array:
    """(H, W, 4) uint8: each channel's areas, quantised as engines store masks."""
    shape = project.influence.resolution or project.textures.normal_neutral.shape[:2]
    rgba = np.zeros((*shape, 4), np.uint8)
    for channel in texture.channels:
        rgba[:, :, CHANNELS.index(channel.channel)] = quantise(
            channel_values(project, channel.sources))
    return rgba


def map_image(project: Project, slot: MapSlot) -> Array:
    """The wrinkle normal map an engine slot gets: a project map as it is, or — when the slot's
    areas reveal several — each texel from the map of the area strongest there (the neutral
    map where none reaches), so each area still shows its own wrinkles."""
    textures = project.textures
    return slot_image(project, slot, textures.wrinkle_maps, textures.normal_neutral)


def slot_image(project: Project, slot: MapSlot, images: dict[str, Array],
               neutral: Array) -> Array:
    """What a slot gets of one kind of per-map image (``images`` by project map; ``neutral``
    where a map has none, or no area reaches): ``map_image``'s rule, shared by the normal maps
    and their cavity and colour maps (engines/tone_maps.py)."""
    textures = project.textures
    if slot.source is not None:
        return images.get(slot.source, neutral)
    areas = [project.influence.areas[i] for i in slot.areas]
    names = [textures.wrinkle_map_names[textures.map_index(a.wrinkle_map)] for a in areas]
    if not names:
        return neutral
    if len(set(names)) == 1:
        return images.get(names[0], neutral)
    chosen = [neutral, *(images.get(n, neutral) for n in names)]
    h = max(im.shape[0] for im in chosen)
    w = max(im.shape[1] for im in chosen)
    wide = np.uint16 if any(im.dtype == np.uint16 for im in chosen) else np.uint8

    def fit(image: Array) -> Array:
        image = resize_nearest(image, h, w) if image.shape[:2] != (h, w) else image
        return image.astype(np.uint16) * 257 if wide is np.uint16 and image.dtype == np.uint8 \
            else image

    strength = np.stack([resize_nearest(a.mask, h, w) for a in areas])
    choice = np.where(strength.max(axis=0) > 0, strength.argmax(axis=0) + 1, 0)
    stack = np.stack([fit(im) for im in chosen])
    return stack[choice, np.arange(h)[:, None], np.arange(w)[None, :]]


def vertex_values(project: Project, values: Array) -> Array:
    """A UV-space image's value at each render vertex (the texel under its UV)."""
    h, w = values.shape
    uv = project.mesh.uvs
    rows = np.clip(((1.0 - uv[:, 1]) * h).astype(int), 0, h - 1)
    cols = np.clip((uv[:, 0] * w).astype(int), 0, w - 1)
    return values[rows, cols]


def flex_table(project: Project, plan: Plan) -> str:
    """CSV: a row per glTF vertex, a column per flex: the vertex's wrinkle weight for that flex
    (positive: the $bumpcompress map), for the DMX delta states' ``wrinkle`` data."""
    columns = [vertex_values(project, channel_values(project, f.sources)) for f in plan.flexes]
    header = ",".join(["vertex", *(f.name.replace(",", "_") for f in plan.flexes)])
    rows = [",".join([str(v), *(f"{c[v]:.4f}" for c in columns)])
            for v in range(project.mesh.n_vertices)]
    return "\n".join([header, *rows]) + "\n"


def layout_sheet(project: Project, plan: Plan) -> dict:
    """The JSON sheet: texture X channel R = region Z = areas …, driven by poses …"""
    layout, areas = plan.layout, project.influence.areas
    drivers = linked_poses(project)

    curves = project.influence.curves

    def names(sources: Sequence[tuple[int, float]]) -> list[dict]:
        """Each area with its gain, its driving poses, and the response curve of each
        non-linear link (an engine applies its own curve per region: a technical artist
        reproduces these there)."""
        out = []
        for i, gain in sources:
            poses = [p for p, _ in drivers.get(i, [])]
            response = {p: c.to_dict() for p in poses
                        if (c := curves.get(p, {}).get(areas[i].name)) is not None
                        and not c.linear}
            out.append({"area": areas[i].name, "gain": gain, "poses": poses,
                        **({"response": response} if response else {})})
        return out

    textures = [{"texture": t.name, "file": t.file,
                 "channels": {c.channel: {"region": c.region, "side": c.side,
                                          "wrinkle_map": None if c.map_slot is None
                                          else layout.maps[c.map_slot] if layout.maps
                                          else project.textures.wrinkle_map_names[c.map_slot],
                                          "areas": names(c.sources)}
                              for c in t.channels}}
                 for t in plan.masks]
    placed: dict[str, list[dict]] = {a.name: [] for a in areas}
    for t in plan.masks:
        for c in t.channels:
            for i, _ in c.sources:
                placed[areas[i].name].append({"texture": t.name, "channel": c.channel,
                                              "region": c.region})
    return {
        "layout": layout.key, "engine": layout.label, "doc": f"docs/engines/{layout.doc}.md",
        "samplers": plan.samplers, "limit": {"used": plan.used, "most": layout.limit,
                                             "counts": layout.limit_unit,
                                             "why": layout.limit_why},
        "model": MODEL_FILE,
        "mask_textures": textures,
        "wrinkle_maps": [{"name": m.name, "file": m.file, "project_map": m.source,
                          "areas": [areas[i].name for i in m.areas]} for m in plan.maps],
        "areas": [{"area": name, "channels": where} for name, where in placed.items()],
        "flexes": [{"flex": f.name, "wrinkle_scale": 1.0, "wrinkle": "compress",
                    "areas": names(f.sources), "table": FLEX_TABLE} for f in plan.flexes],
        "unassigned": [{"area": a, "why": why} for a, why in plan.unassigned],
        **({"merged": [{"mask": m.mask, "into": m.into, "strength": round(m.strength, 6),
                        "overlap": round(m.overlap, 4), "note": m.describe()}
                       for m in plan.merged]} if plan.merged else {}),
        **onsets_note(project),
        **uv_tiles_note(project),
    }
