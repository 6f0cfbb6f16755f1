"""A web player: one self-contained ``index.html`` that shows the face with both techniques.

The page is our own small WebGL2 renderer (``resources/web/player.js``) rather than three.js:
the wrinkles are the studio's own shaders (``shaders/face.vert``, ``face.frag``,
``common.glsl``), carried into the page as text and compiled there as GLSL ES 3.00, so the web
shading cannot drift from the studio's; a general-purpose engine would have needed the same
shaders re-written into its material system anyway.

Everything the page needs travels inside the one file, so it opens from ``file://`` with no
network (Chromium refuses ``fetch`` and modules there): the face's arrays and images are one
zlib-compressed, base64 blob in a ``<script type="application/octet-stream">`` element,
inflated by the browser's ``DecompressionStream``.

What the page computes per frame, and where the studio computes the same:

* positions, normals and tangents: the neutral frame plus each pose's weighted deltas of all
  three, taken from ``DeformCache`` (the studio's own normals and tangents at each key pose)
  and renormalised — exact at a key pose, as glTF morph targets are; between poses the studio
  recomputes normals from the blended positions, which differs by a fraction of a degree;
* technique 1's activations: each area's own value plus ``gain · curve(weight)`` of its links,
  clamped, the weight first through its pose's onset (``response.onset_weight``; carried per
  link, not baked into the curve's samples, whose spacing would round the onset's corner) —
  core/formats/player_data.py: the same data and the same JavaScript
  (``resources/web/activations.js``) as the three.js module shipped with glTF exports;
* technique 1's weights (masks × activations) and technique 2's WDV visibility: the shaders,
  technique 2 measuring from a rest moved by what each pose's onset holds back
  (``render/wrinkle_drive.py``; each pose's onset carried with its deltas).
"""

from __future__ import annotations

import base64
import json
import re
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.atomic_write import write_atomic
from studio.core.formats.export import quantise
from studio.core.formats.gltf.animation import pose_weights, sample_frames
from studio.core.formats.player_data import t1_arrays, t1_links, vertex_arrays
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.geometry import DeformCache
from studio.core.project.model import Project
from studio.core.wrinkles.skin_light import Rig
from studio.core.wrinkles.skin_tone import pack_tone
from studio.core.wrinkles.textures import pack_more_maps, pack_normal_maps
from studio.paths import resource_dir, shader_dir

#: the studio's shader files the page compiles (``#include`` is resolved in the page)
WEB_SHADERS = ("common.glsl", "skin.glsl", "face.vert", "face.frag")
#: a pose delta smaller than this (model units, or unit-vector components) is left out
DELTA_EPSILON = 1e-7


@dataclass(frozen=True)
class WebLook:
    """How the studio draws (its render settings' light, blend and tangent frame, which the
    command hands over: core cannot read the renderer's), for the page's uniforms."""

    light_dir: tuple[float, float, float]
    ambient: float
    specular: float
    shininess: float
    background: tuple[float, float, float]
    blend: str
    tangent_frame: str
    rig: Rig | None = None  # the skin look's lights (skin_light.py); None: clay


class _Blob:
    """Arrays laid end to end in one byte string, each named with its dtype, shape and offset,
    so the page reads them back as typed arrays without parsing anything else."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.index: dict[str, dict] = {}
        self.size = 0

    def add(self, name: str, array: np.ndarray) -> None:
        array = np.ascontiguousarray(array)
        kinds = {np.dtype("float32"): "f4", np.dtype("uint32"): "u4", np.dtype("int16"): "i2",
                 np.dtype("uint8"): "u1"}
        if array.dtype not in kinds:
            raise TypeError(f"{name}: {array.dtype} is not a type the page reads")
        pad = -self.size % 4  # typed arrays need aligned offsets
        self.parts.append(b"\0" * pad)
        self.size += pad
        self.index[name] = {"type": kinds[array.dtype], "shape": list(array.shape),
                            "offset": self.size}
        data = array.tobytes()
        self.parts.append(data)
        self.size += len(data)

    def payload(self) -> str:
        return base64.b64encode(zlib.compress(b"".join(self.parts), 6)).decode("ascii")


def as_rgba8(image: np.ndarray) -> np.ndarray:
    """An image as 8-bit RGBA (WebGL2 has no 16-bit normalised textures without an extension):
    16-bit channels keep their top byte, missing channels are 0 (alpha 255)."""
    if image.dtype == np.uint16:
        image = (image >> 8).astype(np.uint8)
    image = np.asarray(image, np.uint8)
    if image.ndim == 2:
        image = image[..., None]
    out = np.zeros((*image.shape[:-1], 4), np.uint8)
    out[..., 3] = 255
    channels = min(image.shape[-1], 4)
    out[..., :channels] = image[..., :channels]
    return out


def pose_deltas(project: Project, frame: str, blob: _Blob) -> list[dict]:
    """Per key pose, the render vertices it changes and the change of their position, normal
    and tangent against the neutral frame (which goes in as ``rest``), as 16-bit integers with
    a scale per pose and per kind: most of a page's bytes are these, and float32 halves
    nothing under zlib. A step is 1/32767 of the pose's largest change of that kind."""
    mesh = project.mesh
    cache = DeformCache(mesh, frame)
    rest = cache.update(mesh.rest).copy()
    blob.add("rest", rest.astype(np.float32))  # (V, 10): position, normal, tangent xyzw
    poses = []
    for k, pose in enumerate(project.poses):
        posed = cache.update(pose.positions)
        delta = posed[:, :9] - rest[:, :9]
        moved = np.flatnonzero(np.abs(delta).max(axis=1) > DELTA_EPSILON)
        kinds = delta[moved].reshape(-1, 3, 3)  # (moved, position | normal | tangent, xyz)
        largest = np.abs(kinds).max(axis=(0, 2)) if len(moved) else np.zeros(3)
        step = np.where(largest > 0, largest, 1.0) / 32767.0
        blob.add(f"pose{k}.vertices", moved.astype(np.uint32))
        blob.add(f"pose{k}.deltas", np.round(kinds / step[None, :, None]).astype(np.int16)
                 .reshape(len(moved), 9))
        poses.append({"name": pose.name, "vertices": len(moved),
                      "step": [float(v) for v in step],
                      "onset": project.furrows.of(pose.name).onset})
    return poses


def timeline_data(project: Project) -> dict | None:
    """The timeline sampled at every frame and key (as the glTF animation is), for playing."""
    timeline = project.timeline
    if timeline is None or not any(t.keys for t in timeline.tracks):
        return None
    frames = sample_frames(timeline)
    names = [p.name for p in project.poses]
    weights = pose_weights(timeline, names, frames)
    return {"fps": float(timeline.fps), "frames": [float(f) for f in frames],
            "weights": np.round(weights, 6).tolist()}


def camera_data(camera: OrbitCamera) -> dict:
    """The studio's orbit camera, for the page's own ``look_at`` and ``perspective``."""
    return {"target": [float(v) for v in camera.target], "distance": float(camera.distance),
            "yaw": float(camera.yaw), "pitch": float(camera.pitch), "fov_y": float(camera.fov_y),
            "radius": float(camera.radius),
            "basis": [float(v) for v in np.asarray(camera.basis).T.ravel()]}  # columns


def web_scene(project: Project, camera: OrbitCamera, look: WebLook) -> tuple[dict, _Blob]:
    """Everything the page shows, as a JSON-able description and the blob of its arrays."""
    mesh, textures = project.mesh, project.textures
    blob = _Blob()
    poses = pose_deltas(project, look.tangent_frame, blob)
    blob.add("uvs", mesh.uvs.astype(np.float32))
    blob.add("triangles", mesh.triangles.astype(np.uint32))
    for name, array in {**vertex_arrays(project), **t1_arrays(project)}.items():
        blob.add(name, array)
    blob.add("diffuse", as_rgba8(textures.diffuse))
    normals = pack_normal_maps(textures.normal_neutral, textures.normal_wrinkled)
    blob.add("normals", as_rgba8(normals))
    more = pack_more_maps(textures, normals)  # x and y only: the page's RG8 array
    blob.add("more_maps", (more >> 8).astype(np.uint8) if more.dtype == np.uint16 else more)
    tone = look.rig is not None and textures.has_tone  # clay shows neither, as in the studio
    if tone:
        blob.add("tone", pack_tone(textures))
    masks = project.influence.mask_stack()
    blob.add("masks", quantise(masks) if len(masks) else np.zeros((1, 1, 1), np.uint8))
    scene = {
        "poses": poses,
        "areas": [a.name for a in project.influence.areas],
        "links": t1_links(project),
        "wrinkle_maps": len(textures.wrinkle_maps),
        "wdv": {"expression_factor": float(project.wdv.expression_factor),
                "scale_free": bool(project.wdv.scale_free)},
        "camera": camera_data(camera),
        "look": {"light_dir": list(look.light_dir), "ambient": look.ambient,
                 "specular": look.specular, "shininess": look.shininess,
                 "background": list(look.background), "blend": look.blend,
                 "rig": None if look.rig is None else {
                     "directions": [list(d) for d in look.rig.directions],
                     "colours": [list(c) for c in look.rig.colours],
                     "ambient": list(look.rig.ambient)},
                 "tone": tone},
        "timeline": timeline_data(project),
        "arrays": blob.index,
    }
    return scene, blob


def _script_json(value: object) -> str:
    """JSON safe inside a ``<script>`` element: no ``<`` at all, so neither ``</script>`` nor
    ``<!--`` in a name or a shader's text can end or hide the element early."""
    return json.dumps(value, separators=(",", ":")).replace("<", "\\u003c")


def web_page(project: Project, camera: OrbitCamera, look: WebLook) -> str:
    """The player page's HTML: the template with the player, the studio's shaders and the
    face's data put in."""
    web = resource_dir() / "web"
    scene, blob = web_scene(project, camera, look)
    shaders = {name: (shader_dir() / name).read_text(encoding="utf-8") for name in WEB_SHADERS}
    fills = {"TITLE": "Wrinkle Studio",
             "SCENE": _script_json(scene),
             "SHADERS": _script_json(shaders),
             "DATA": blob.payload(),
             "PLAYER": "\n".join((web / name).read_text(encoding="utf-8")
                                  for name in ("player.js", "activations.js"))}
    page = (web / "player.html").read_text(encoding="utf-8")
    # one pass: a pose named "{{DATA}}" in the scene is not filled in again
    return re.sub(r"\{\{([A-Z]+)\}\}", lambda m: fills[m.group(1)], page)


def export_web(project: Project, folder: str | Path, camera: OrbitCamera,
               look: WebLook) -> list[Path]:
    """Write ``folder/index.html`` (all or nothing); returns the files written."""
    folder = Path(folder)
    path = folder / "index.html"
    write_atomic(path, web_page(project, camera, look).encode("utf-8"), make_folders=True,
                 what="web page")
    return [path]
