"""Small hand-built faces whose every pixel's inputs are known: a flat square grid facing the
camera, its UVs the square itself, with hand-made maps.

The grid spans x, y in [-1, 1] at z = 0, facing +Z; u = (x + 1) / 2, v = (y + 1) / 2, so the
tangent is +X, the bitangent +Y and the normal +Z, and an image's column c of w covers
x in [-1 + 2c/w, -1 + 2(c+1)/w], row r of h (row 0 at the top, v = 1) y in
[1 - 2(r+1)/h, 1 - 2r/h].
"""

from __future__ import annotations

import numpy as np

from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map

FLAT = (128, 128, 255)


def grid_mesh(cells: int = 8) -> FaceMesh:
    """``cells`` × ``cells`` squares over [-1, 1]², two triangles each, one UV island."""
    x, y = np.meshgrid(np.linspace(-1, 1, cells + 1), np.linspace(-1, 1, cells + 1))
    idx = np.arange(x.size).reshape(x.shape)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    rest = np.stack([x, y, np.zeros_like(x)], -1).reshape(-1, 3)
    uvs = np.stack([(x + 1) / 2, (y + 1) / 2], -1).reshape(-1, 2)
    return FaceMesh(rest, tris, uvs, np.arange(x.size))


def tilted_map(size: int, x: int, where=None) -> np.ndarray:
    """A normal map flat but for the texels ``where`` (an index or boolean mask; all when
    None), whose red (tangent x) is ``x``: a furrow's wall, tilted along u."""
    image = flat_normal_map(size)
    selected = np.ones((size, size), bool)
    if where is not None:
        selected[...] = False
        selected[where] = True
    image[selected, 0] = x
    return image


def front_camera(cells_margin: float = 1.05) -> OrbitCamera:
    """Looking at the grid straight from +Z, the grid filling the view."""
    camera = OrbitCamera(yaw=0.0, pitch=0.0)
    camera.frame(np.array([-1.0, -1.0, 0.0]), np.array([1.0, 1.0, 0.0]), cells_margin)
    return camera


def grid_face(maps: dict[str, np.ndarray], neutral: np.ndarray | None = None,
              diffuse: np.ndarray | None = None, cells: int = 8) -> Project:
    """The grid with these wrinkled maps (names in order), a flat neutral map unless given and
    a grey diffuse unless given; the camera saved in front of it."""
    size = next(iter(maps.values())).shape[0]
    neutral = flat_normal_map(size) if neutral is None else neutral
    diffuse = np.full((size, size, 3), 180, np.uint8) if diffuse is None else diffuse
    project = Project("grid", grid_mesh(cells), [],
                      FaceTextures(diffuse, neutral, wrinkle_maps=dict(maps)))
    project.view["camera"] = front_camera().to_dict()
    return project
