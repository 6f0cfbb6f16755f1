"""The heads ``wrinkle-studio bench --setup`` sets up, written as the files a user would bring:
the bundled sample as the studio builds it at first start, and heads in other conventions than
the sample's (millimetres, Z up, far from the origin, OBJ files or a glTF with ARKit-named
morph targets), up to a head of 250 000 vertices.

Built here, not taken from the tests' heads: the benchmark is part of the studio and may not
import the tests; each head is made from the studio's own faces (the ICT-FaceKit head, the
procedural test face), moved into its conventions and written by the studio's own writers."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.bench.poses import with_arkit_poses
from studio.core.animation.poses import KeyPose
from studio.core.formats.gltf.codec import save_gltf
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import save_obj
from studio.core.project.model import Project
from studio.core.sample.ict_head import load_ict_head
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.textures import flat_normal_map

Array = np.ndarray
Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # y up → z up, −y front
FAR = np.array([250.0, -40.0, 1600.0])  # a head placed in a scene, not at the origin


@dataclass(frozen=True)
class BenchHead:
    """A head to set up: its label, and how to write its files into a folder (the mesh, and
    {pose: file} for separate key-pose meshes); ``sample``: the bundled sample instead."""

    label: str
    write: Callable[[Path], tuple[Path, dict[str, Path]]] | None = None
    sample: bool = False


def in_conventions(project: Project, scale: float) -> Project:
    """The project's rest and poses ``scale`` times larger, Z up and far from the origin; its
    wrinkle set-up dropped and its wrinkled map a flat placeholder, as a head made elsewhere."""
    def moved(points: Array) -> Array:
        return (np.asarray(points, np.float64) @ Z_UP.T * scale + FAR).astype(np.float32)

    mesh = project.mesh
    project.mesh = FaceMesh(moved(mesh.rest), mesh.triangles, mesh.uvs, mesh.weld)
    project.poses = [KeyPose(p.name, moved(p.positions)) for p in project.poses]
    project.influence.areas, project.influence.links = [], {}
    project.wdv.areas = []
    project.textures.wrinkle_maps = {name: flat_normal_map()
                                     for name in project.textures.wrinkle_maps}
    return project


def _ict_objs(folder: Path) -> tuple[Path, dict[str, Path]]:
    """The ICT head with all its expressions, in millimetres (it is in centimetres), Z up, as
    a neutral OBJ and an OBJ per expression."""
    project = in_conventions(load_ict_head(), 10.0)
    mesh = project.mesh
    neutral = folder / "neutral.obj"
    save_obj(neutral, mesh)
    poses = {}
    for pose in project.poses:
        poses[pose.name] = folder / f"{pose.name}.obj"
        save_obj(poses[pose.name], mesh, pose)
    return neutral, poses


def _test_face_gltf(vertices: int, arkit: int = 0) -> Callable[[Path], tuple[Path, dict]]:
    """The procedural test face of ``vertices`` (its own poses, or ``arkit`` ARKit ones), in
    millimetres, Z up, as one glTF with morph targets."""
    def write(folder: Path) -> tuple[Path, dict[str, Path]]:
        project = make_test_face(vertices)
        if arkit:
            project = with_arkit_poses(project, arkit)
        path = folder / "head.glb"
        save_gltf(in_conventions(project, 1000.0), path)
        return path, {}
    return write


def bench_heads(quick: bool = False) -> list[BenchHead]:
    """The heads, smallest first; ``quick``: the sample and the small test face only."""
    heads = [BenchHead("sample (ICT head, 19 of 53 expressions)", sample=True),
             BenchHead("test face, 2172 vertices, 5 poses, glTF mm Z up",
                       _test_face_gltf(2172))]
    if quick:
        return heads
    return [
        *heads,
        BenchHead("ICT head, 53 expressions, OBJs mm Z up", _ict_objs),
        BenchHead("test face, 30000 vertices, 52 ARKit poses, glTF", _test_face_gltf(30000, 52)),
        BenchHead("test face, 250000 vertices, 5 poses, glTF", _test_face_gltf(250000)),
    ]
