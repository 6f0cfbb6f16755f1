"""Wrinkles where the face is drawn: masks and synthesised furrows come from skin triangles only.

Eyes, lashes and teeth often share the skin's UV tile (the ICT-FaceKit head's eye parts lie on
its face tile). Where UV triangles overlap, the triangle drawn last owns the texel, so before
the fix the eyes erased the brow's compression and the furrows: the map and the masks held the
neutral value exactly where the pose compresses the face. Each case here samples every mask
and the wrinkled map its pose reveals at the atlas coordinates of the vertices that pose
compresses most."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import pack_mesh
from studio.core.project.model import Project
from studio.core.setup.auto_setup import auto_start, uv_overlap_share
from studio.core.wrinkles.skin_strain import SkinStrain
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map
from tests.test_auto_setup import grid_mesh, squeezed

pytestmark = pytest.mark.core


def most_compressed(project: Project, pose: str, count: int = 40) -> np.ndarray:
    """Render vertices of the ``count`` skin vertices the pose compresses most."""
    strain = SkinStrain(project.mesh, project.skin_weights())
    per_triangle = strain.of(project.pose(pose).positions).compression  # of welded triangles
    compression = np.full(project.mesh.n_welded, -1.0)
    corners = project.mesh.welded_triangles
    np.maximum.at(compression, corners, np.repeat(per_triangle[:, None], 3, axis=1))
    compression[project.skin_weights() == 0] = -1.0
    welded = np.argsort(compression)[-count:]
    return np.flatnonzero(np.isin(project.mesh.weld, welded))


def texels(image: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    rows = np.clip(((1.0 - uvs[:, 1]) * h).astype(int), 0, h - 1)
    cols = np.clip((uvs[:, 0] * w).astype(int), 0, w - 1)
    return image[rows, cols]


def window_changed(image: np.ndarray, neutral: np.ndarray, uvs: np.ndarray, radius: int) -> float:
    """Share of the texel windows around these UVs where the map differs from the neutral."""
    h, w = image.shape[:2]
    changed = np.any(image != neutral, axis=-1)
    rows = np.clip(((1.0 - uvs[:, 1]) * h).astype(int), 0, h - 1)
    cols = np.clip((uvs[:, 0] * w).astype(int), 0, w - 1)
    hits = [changed[max(r - radius, 0):r + radius + 1, max(c - radius, 0):c + radius + 1].any()
            for r, c in zip(rows, cols, strict=True)]  # a few dozen windows
    return float(np.mean(hits))


def check_where_compressed(project: Project, poses: list[str]) -> None:
    """Each pose's mask is strong and its wrinkled map holds furrows where it compresses most."""
    neutral = project.textures.normal_neutral[0, 0]
    for pose in poses:
        verts = most_compressed(project, pose)
        uvs = project.mesh.uvs[verts]
        (mask_name,) = project.influence.links[pose]
        area = next(a for a in project.influence.areas if a.name == mask_name)
        assert np.median(texels(area.mask, uvs)) > 0.3, pose
        wrinkled = project.textures.wrinkle_maps[area.wrinkle_map]
        radius = max(wrinkled.shape[0] // 64, 2)  # furrows lie a spacing or so apart
        assert window_changed(wrinkled, neutral, uvs, radius) > 0.6, pose


# --- small faces whose eyes lie over the skin in UV, on 1, 2 and 7 tiles ---------------------

def face_with_eye_over_the_skin(tiles: int) -> Project:
    """A grid of skin on tile 1001 squeezed on its left half, an eye shell drawn after it over
    the same UVs (the squeezed half's), and ``tiles − 1`` small parts on the next tiles."""
    skin = grid_mesh(21)
    rest, tris, uvs = [skin.rest], [skin.triangles], [skin.uvs]
    offset = len(skin.rest)

    def add(points: np.ndarray, uv: np.ndarray) -> None:
        nonlocal offset
        quad = np.array([[0, 1, 2], [0, 2, 3]]) + offset
        rest.append(points.astype(np.float32))
        uvs.append(uv.astype(np.float32))
        tris.append(quad)
        offset += 4

    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    add(np.c_[square * 0.8 - [0.9, 0.4], np.full(4, 0.3)], square * [0.45, 0.9] + [0.02, 0.05])
    for k in range(1, tiles):
        add(np.c_[square * 0.1 + [2.0 + k, 0.0], np.zeros(4)], square * 0.5 + [k + 0.25, 0.25])
    rest_all = np.concatenate(rest)
    mesh = FaceMesh(rest_all, np.concatenate(tris), np.concatenate(uvs), np.arange(len(rest_all)))
    not_face = np.arange(len(rest_all)) >= len(skin.rest)
    mesh, layout = pack_mesh(mesh, ~not_face)
    posed = rest_all.copy()
    posed[: len(skin.rest)] = squeezed(skin.rest)
    textures = FaceTextures(flat_normal_map(8), flat_normal_map(8), flat_normal_map(8))
    return Project("eye over skin", mesh, [KeyPose("squeeze", posed)], textures,
                   not_face=not_face, uv_tiles=layout)


@pytest.mark.parametrize("tiles", [1, 2, 7])
def test_an_eye_over_the_skin_in_uv_takes_nothing_from_its_masks_and_furrows(tiles: int) -> None:
    project = face_with_eye_over_the_skin(tiles)
    assert (project.uv_tiles is None) == (tiles == 1)
    lines = auto_start(project)
    check_where_compressed(project, ["squeeze"])
    # the eye covers about 0.45 × 0.9 of the skin's square: the set-up says so
    (said,) = [line for line in lines if "overlap" in line]
    share = int(said.split("overlap ")[1].split("%")[0])
    assert 35 <= share <= 45 and "skin's triangles only" in said


def test_a_face_whose_parts_keep_apart_in_uv_hears_nothing_of_overlaps() -> None:
    project = face_with_eye_over_the_skin(2)
    project.mesh.uvs[project.mesh.weld >= 441] += np.float32(0.6)  # the eye off the skin
    assert uv_overlap_share(project) == 0.0


def test_the_skin_mesh_leaves_out_every_triangle_with_a_not_face_corner() -> None:
    project = face_with_eye_over_the_skin(1)
    skin = project.skin_mesh()
    assert skin.n_triangles == project.mesh.n_triangles - 2
    assert skin is project.skin_mesh()  # one object while the mesh and flags stay
    project.not_face = None
    assert project.skin_mesh() is project.mesh
