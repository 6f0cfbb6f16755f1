"""Engine-ready output besides the glTF: masks as PNGs (one per area, and four areas packed into
the RGBA channels of one image, as engines sample them), the wrinkled normal maps, the pose →
area links and each area's wrinkled map as JSON, and the GLSL of both techniques."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np

from studio.core.errors import StudioError
from studio.core.gltf import save_gltf
from studio.core.images import write_png
from studio.core.project import Project
from studio.paths import shader_dir

SHADERS = ("common.glsl", "relief.glsl", "face.vert", "face.tesc", "face.tese", "face.frag",
           "t1_compose.vert", "t1_compose.frag")


def safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "area"


def packed_masks(project: Project) -> list[np.ndarray]:
    """Areas four at a time in R, G, B, A (8-bit); unused channels are 0."""
    areas = project.influence.areas
    images = []
    for start in range(0, len(areas), 4):
        group = [a.mask for a in areas[start:start + 4]]
        h, w = group[0].shape
        rgba = np.zeros((h, w, 4), np.uint8)
        for c, mask in enumerate(group):
            rgba[:, :, c] = np.round(np.clip(mask, 0, 1) * 255.0)
        images.append(rgba)
    return images


def export_folder(project: Project, folder: str | Path, bits: int = 16,
                  tangent_frame: str | None = None) -> list[Path]:
    """Write everything an engine needs into ``folder``; returns the files written.
    ``tangent_frame`` as for ``save_gltf`` (default: the project's)."""
    folder = Path(folder)
    try:
        (folder / "masks").mkdir(parents=True, exist_ok=True)
        (folder / "shaders").mkdir(exist_ok=True)
        (folder / "maps").mkdir(exist_ok=True)
    except OSError as exc:
        raise StudioError(f"cannot create the export folder: {exc.strerror}", folder) from None
    written = [folder / "face.glb"]
    save_gltf(project, written[0], tangent_frame)
    scale, dtype = (65535.0, np.uint16) if bits == 16 else (255.0, np.uint8)
    areas = project.influence.areas
    layout = []
    for i, area in enumerate(areas):
        path = folder / "masks" / f"{i:02d}_{safe_name(area.name)}.png"
        write_png(path, np.round(np.clip(area.mask, 0, 1) * scale).astype(dtype))
        written.append(path)
    tiles = project.skin_tiles()
    for i, area in enumerate(areas):  # a UDIM face: each skin tile's part, as tools expect
        for tile in tiles:
            path = folder / "masks" / f"{i:02d}_{safe_name(area.name)}.{tile}.png"
            crop = project.uv_tiles.layout.crop(area.mask, tile)
            write_png(path, np.round(np.clip(crop, 0, 1) * scale).astype(dtype))
            written.append(path)
    for k, rgba in enumerate(packed_masks(project)):
        path = folder / "masks" / f"packed_{k:02d}.png"
        write_png(path, rgba)
        written.append(path)
        layout.append({"image": path.name, "channels": [a.name for a in areas[4 * k:4 * k + 4]]})
    textures = project.textures
    maps = []
    for i, (name, image) in enumerate(textures.wrinkle_maps.items()):
        path = folder / "maps" / f"wrinkled_{i}_{safe_name(name)}.png"
        write_png(path, image)
        written.append(path)
        maps.append({"name": name, "index": i, "image": f"maps/{path.name}"})
    path = folder / "maps" / "neutral.png"
    write_png(path, textures.normal_neutral)
    written.append(path)
    for tile in tiles:
        for i, (name, image) in enumerate(textures.wrinkle_maps.items()):
            path = folder / "maps" / f"wrinkled_{i}_{safe_name(name)}.{tile}.png"
            write_png(path, project.uv_tiles.layout.crop(image, tile))
            written.append(path)
    links = {
        "wrinkle_maps": maps,
        "areas": [{"name": a.name, "mask": f"masks/{i:02d}_{safe_name(a.name)}.png",
                   "packed": {"image": f"masks/packed_{i // 4:02d}.png", "channel": "RGBA"[i % 4]},
                   "activation": a.activation,
                   "wrinkle_map": textures.map_index(a.wrinkle_map)}
                  for i, a in enumerate(areas)],
        "pose_links": project.influence.links,
        **({"uv_tiles": {**project.uv_tiles.layout.to_dict(), "skin_tiles": tiles,
                         "note": "masks and maps are atlases (the glTF's UVs); files named "
                                 "NAME.<UDIM>.png hold each skin tile in its own 0-1 square"}}
           if project.uv_tiles is not None else {}),
        "packed_layout": layout,
        "wdv": {"expression_factor": project.wdv.expression_factor,
                "scale_free": project.wdv.scale_free,
                "areas": [{"name": a.name, "pose": a.pose, "cone_angle_deg": a.cone_angle_deg,
                           "wrinkle_map": textures.map_index(a.wrinkle_map),
                           "attributes": [f"_WRINKLE_DIR_{n}", f"_WRINKLE_LEN_{n}"]
                           + ([f"_WRINKLE_CONE_{n}"] if a.cone_angles_deg is not None else [])}
                          for n, a in enumerate(project.wdv.areas)]},
    }
    path = folder / "wrinkles.json"
    path.write_text(json.dumps(links, indent=2), encoding="utf-8")
    written.append(path)
    for name in SHADERS:
        target = folder / "shaders" / name
        shutil.copyfile(shader_dir() / name, target)
        written.append(target)
    return written
