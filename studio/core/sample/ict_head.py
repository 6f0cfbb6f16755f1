"""The ICT-FaceKit light head (USC Institute for Creative Technologies, MIT licence): a real
scanned head with 53 ARKit-style expressions, bundled as ``resources/ict_head/ict_head.npz``
(made by ``scripts/make_ict_head.py``; licence and credits beside it).

It is read here into a ``Project`` as if the user had imported its OBJ set with the ten eye,
lash, teeth and gum materials marked not-face: the same mesh, the same UDIM tiles packed into
the same atlas, every expression a key pose.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import pack_mesh
from studio.core.project.model import Project
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map, plain_diffuse
from studio.paths import resource_dir

Array = np.ndarray

NOT_SKIN_MATERIALS = ("M_EyeBlend", "M_EyeLashes", "M_EyeOcclusion", "M_GumsTongue",
                      "M_IrisLeft", "M_IrisRight", "M_LacrimalFluid", "M_ScleraLeft",
                      "M_ScleraRight", "M_Teeth")
CREDIT = ("ICT-FaceKit light head, USC Institute for Creative Technologies (MIT licence)")


def resource_path() -> Path:
    """Where the bundled head is, installed or in a checkout."""
    return resource_dir() / "ict_head" / "ict_head.npz"


def expression_offsets(data, index: int, n_welded: int) -> Array:
    """(W, 3) float32 offsets of expression ``index`` from its sparse int16 steps."""
    offsets = np.zeros((n_welded, 3), np.float32)
    steps = data[f"steps_{index}"].astype(np.float64) * float(data[f"scale_{index}"])
    offsets[data[f"index_{index}"]] = steps.astype(np.float32)
    return offsets


def load_ict_head(path: str | Path | None = None, poses: list[str] | None = None) -> Project:
    """The head with every expression (or those named) as a key pose, UDIM tiles packed."""
    path = Path(path) if path is not None else resource_path()
    try:
        with np.load(path, allow_pickle=False) as data:
            mesh = FaceMesh(data["rest"], data["triangles"], data["uvs"], data["weld"], str(path))
            names = [str(n) for n in data["names"]]
            wanted = names if poses is None else list(poses)
            unknown = [n for n in wanted if n not in names]
            if unknown:
                raise StudioError(f"the ICT head has no expression {', '.join(unknown)}", path)
            key_poses = [KeyPose(n, mesh.rest + expression_offsets(data, names.index(n),
                                                                   mesh.n_welded))
                         for n in wanted]
            not_face = data["not_face"].astype(bool)
    except (OSError, KeyError, ValueError) as exc:
        raise StudioError(f"the bundled ICT head cannot be read ({exc}); reinstall the studio",
                          path) from exc
    packed, tiles = pack_mesh(mesh, ~not_face)
    textures = FaceTextures(plain_diffuse(), flat_normal_map(), flat_normal_map())
    return Project("ICT-FaceKit head", packed, key_poses, textures, not_face=not_face,
                   uv_tiles=tiles)



def landmark_vertices(path: str | Path | None = None) -> Array:
    """(68,) welded vertex indices of the kit's facial landmarks, in the iBUG 300-W order
    (jaw 0–16, brows 17–26, nose 27–35, eyes 36–47, mouth 48–67)."""
    path = Path(path) if path is not None else resource_path()
    with np.load(path, allow_pickle=False) as data:
        return data["landmarks"].astype(np.int64)
