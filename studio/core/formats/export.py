"""Engine-ready output besides the glTF: masks as PNGs (one per area, and four areas packed into
the RGBA channels of one image, as engines sample them), the wrinkled normal maps, the pose →
area links with their response curves and each area's wrinkled map as JSON, the GLSL of both
techniques, and a Blender script building technique 1 driven by the shape keys."""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from studio.core.files.atomic_write import write_atomic
from studio.core.files.errors import StudioError
from studio.core.files.images import write_png
from studio.core.formats.blender_material import SCRIPT, blender_script, blender_setup
from studio.core.formats.gltf.codec import save_gltf, wdv_attributes
from studio.core.formats.three_module import three_module_paths
from studio.core.project.model import Project
from studio.core.wrinkles.response import curves_to_dict
from studio.paths import shader_dir

SHADERS = ("common.glsl", "skin.glsl", "relief.glsl", "face.vert", "face.tesc", "face.tese",
           "face.frag", "t1_compose.vert", "t1_compose.frag")


def safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "area"


def quantise(values: np.ndarray, bits: int = 8) -> np.ndarray:
    """Unit-range values as 8- or 16-bit integers (rounded, clamped), as PNGs store them."""
    scale, dtype = (65535.0, np.uint16) if bits == 16 else (255.0, np.uint8)
    return np.round(np.clip(values, 0, 1) * scale).astype(dtype)


def packed_masks(project: Project) -> list[np.ndarray]:
    """Areas four at a time in R, G, B, A (8-bit); unused channels are 0."""
    areas = project.influence.areas
    images = []
    for start in range(0, len(areas), 4):
        group = [a.mask for a in areas[start:start + 4]]
        h, w = group[0].shape
        rgba = np.zeros((h, w, 4), np.uint8)
        for c, mask in enumerate(group):
            rgba[:, :, c] = quantise(mask)
        images.append(rgba)
    return images


def tile_copies(project: Project, path: Path, image: np.ndarray,
                write: Callable[[Path, np.ndarray], None] = write_png) -> list[Path]:
    """A UDIM face's atlas image cut back into each skin tile's own 0–1 square, written as
    ``NAME.<tile>.ext`` beside ``path`` (as tools that read UDIM sets expect); none for a face
    on one tile."""
    written = []
    for tile in project.skin_tiles():
        target = path.with_name(f"{path.stem}.{tile}{path.suffix}")
        write(target, project.uv_tiles.layout.crop(image, tile))
        written.append(target)
    return written


def make_folders(folder: Path, names: Iterable[str]) -> None:
    """The export folder and its subfolders, as a StudioError naming the folder on failure."""
    try:
        for name in names:
            (folder / name).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise StudioError(f"cannot create the export folder: {exc.strerror}", folder) from None


def uv_tiles_note(project: Project) -> dict:
    """The sheet's record of a UDIM face's tiles (empty for a face on one tile)."""
    if project.uv_tiles is None:
        return {}
    return {"uv_tiles": {**project.uv_tiles.layout.to_dict(), "skin_tiles": project.skin_tiles(),
                         "note": "masks and maps are atlases (the glTF's UVs); files named "
                                 "NAME.<UDIM>.png hold each skin tile in its own 0-1 square"}}


def onsets_note(project: Project) -> dict:
    """The sheet's record of each pose's onset where it has one (empty when none has): the
    weight goes through max(0, (w - onset) / (1 - onset)) before the links' curves
    (core/wrinkles/response.py onset_weight), which an engine's own curves must do too."""
    onsets = {p.name: onset for p in project.poses
              if (onset := project.furrows.of(p.name).onset) > 0}
    return {"pose_onsets": onsets} if onsets else {}


def export_folder(project: Project, folder: str | Path, bits: int = 16,
                  tangent_frame: str | None = None) -> list[Path]:
    """Write everything an engine needs into ``folder``; returns the files written.
    ``tangent_frame`` as for ``save_gltf`` (default: the project's)."""
    folder = Path(folder)
    make_folders(folder, ("masks", "shaders", "maps"))
    written = [folder / "face.glb"]
    save_gltf(project, written[0], tangent_frame)
    written += three_module_paths(written[0])  # save_gltf writes wrinkles.js beside it
    areas = project.influence.areas
    layout = []
    mask_files = [f"masks/{i:02d}_{safe_name(a.name)}.png" for i, a in enumerate(areas)]
    for area, name in zip(areas, mask_files, strict=True):
        path = folder / name
        image = quantise(area.mask, bits)
        write_png(path, image)
        written += [path, *tile_copies(project, path, image)]
    for k, rgba in enumerate(packed_masks(project)):
        path = folder / "masks" / f"packed_{k:02d}.png"
        write_png(path, rgba)
        written += [path, *tile_copies(project, path, rgba)]
        layout.append({"image": path.name, "channels": [a.name for a in areas[4 * k:4 * k + 4]]})
    textures = project.textures
    maps = []
    for i, (name, image) in enumerate(textures.wrinkle_maps.items()):
        path = folder / "maps" / f"wrinkled_{i}_{safe_name(name)}.png"
        write_png(path, image)
        written += [path, *tile_copies(project, path, image)]
        maps.append({"name": name, "index": i, "image": f"maps/{path.name}"})
        for kind, tone in (("cavity", textures.cavity_maps), ("colour", textures.colour_maps)):
            if name in tone:  # how deep in a crease (255 open) / the albedo's tint (128: none)
                path = folder / "maps" / f"{kind}_{i}_{safe_name(name)}.png"
                write_png(path, tone[name])
                written += [path, *tile_copies(project, path, tone[name])]
                maps[-1][kind] = f"maps/{path.name}"
    path = folder / "maps" / "neutral.png"
    write_png(path, textures.normal_neutral)
    written.append(path)
    path = folder / SCRIPT  # technique 1 in Blender, driven by the shape keys
    setup = blender_setup(project, written[0].name, mask_files, maps, "maps/neutral.png")
    write_atomic(path, blender_script(setup), what="Blender script")
    written.append(path)
    links = {
        "wrinkle_maps": maps,
        "areas": [{"name": a.name, "mask": f"masks/{i:02d}_{safe_name(a.name)}.png",
                   "packed": {"image": f"masks/packed_{i // 4:02d}.png", "channel": "RGBA"[i % 4]},
                   "activation": a.activation,
                   "wrinkle_map": textures.map_index(a.wrinkle_map)}
                  for i, a in enumerate(areas)],
        "pose_links": project.influence.links,
        # the non-linear links' response curves: contribution = gain · curve(pose weight)
        "pose_curves": curves_to_dict(project.influence.curves),
        **onsets_note(project),
        **uv_tiles_note(project),
        "packed_layout": layout,
        "wdv": {"expression_factor": project.wdv.expression_factor,
                "scale_free": project.wdv.scale_free,
                "areas": [{"name": a.name, "pose": a.pose, "cone_angle_deg": a.cone_angle_deg,
                           "wrinkle_map": textures.map_index(a.wrinkle_map),
                           "attributes": list(wdv_attributes(n)),
                           "painted_cones": a.cone_angles_deg is not None}
                          for n, a in enumerate(project.wdv.areas)]},
    }
    path = folder / "wrinkles.json"
    write_atomic(path, json.dumps(links, indent=2).encode("utf-8"), what="link sheet")
    written.append(path)
    for name in SHADERS:
        target = folder / "shaders" / name
        write_atomic(target, (shader_dir() / name).read_bytes(), what="shader")
        written.append(target)
    return written
