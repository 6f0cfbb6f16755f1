"""The project: everything the user authored and imported, free of Qt and GL."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import NEUTRAL, KeyPose, check_pose_topology
from studio.core.animation.timeline import Timeline
from studio.core.files.errors import StudioError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.uv_tiles import UvTiles
from studio.core.wrinkles.furrow_controls import FurrowSettings
from studio.core.wrinkles.influence import InfluenceSetup
from studio.core.wrinkles.response import onset_weight
from studio.core.wrinkles.textures import FaceTextures
from studio.core.wrinkles.wdv import WdvSetup

MANY_POSE_NAMES = 12  # past this, a message names the closest poses instead of all


@dataclass(eq=False)
class Project:
    name: str
    mesh: FaceMesh
    poses: list[KeyPose]  # key poses other than the neutral one (the mesh's rest positions)
    textures: FaceTextures
    influence: InfluenceSetup = field(default_factory=InfluenceSetup)
    wdv: WdvSetup = field(default_factory=WdvSetup)
    timeline: Timeline = field(default_factory=Timeline)
    view: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)  # unknown project.json keys, kept for newer tools
    # (W,) bool per welded vertex: not skin (eyes, teeth, ...), so never wrinkled; None = all skin
    not_face: np.ndarray | None = None
    # UDIM tiles packed into the 0–1 atlas the mesh's UVs are in; None = one tile as imported
    uv_tiles: UvTiles | None = None
    # the furrow controls (depth, spacing, sharpness; the poses' onsets) and their maps' records
    furrows: FurrowSettings = field(default_factory=FurrowSettings)

    def __post_init__(self) -> None:
        for pose in self.poses:
            check_pose_topology(self.mesh.rest, pose, self.mesh.source or None)
        if self.not_face is not None:
            self.not_face = np.asarray(self.not_face, dtype=bool)
            if self.not_face.shape != (self.mesh.n_welded,):
                raise StudioError(f"the not-face flags cover {self.not_face.shape} vertices, "
                                  f"the mesh has {self.mesh.n_welded}")
        if self.uv_tiles is not None and len(self.uv_tiles.vertex_tile) != self.mesh.n_vertices:
            raise StudioError(f"the UV tiles cover {len(self.uv_tiles.vertex_tile)} vertices, "
                              f"the mesh has {self.mesh.n_vertices}")

    def skin_weights(self) -> np.ndarray:
        """(W,) float32: 1 where wrinkles may show, 0 on vertices marked not-face."""
        if self.not_face is None:
            return np.ones(self.mesh.n_welded, np.float32)
        return (~self.not_face).astype(np.float32)

    def skin_triangles(self) -> np.ndarray:
        """(F,) bool, read-only: triangles whose three corners are skin. The same array while
        the mesh and the not-face flags stay, so tools can cache what they build from it."""
        return self._skin()[0]

    def skin_mesh(self) -> FaceMesh:
        """The mesh with only its skin triangles (same vertices), for everything written in UV
        space: masks, strain, furrows, painting through the mesh, baking. Eyes, lashes and
        teeth often share the skin's UV tile, and where UV triangles overlap the one drawn last
        owns the texel — an eye would erase the brow's compression. The whole mesh when
        nothing is marked not-face (or nothing would be left)."""
        return self._skin()[1]

    def _skin(self) -> tuple[np.ndarray, FaceMesh]:
        flags = None if self.not_face is None else self.not_face.tobytes()
        cached = self.__dict__.get("_skin_cache")
        if cached is not None and cached[0] is self.mesh and cached[1] == flags:
            return cached[2], cached[3]
        keep = (self.skin_weights() > 0)[self.mesh.welded_triangles].all(axis=1)
        keep.flags.writeable = False
        mesh = self.mesh
        if not keep.all() and keep.any():
            mesh = FaceMesh(mesh.rest, mesh.triangles[keep], mesh.uvs, mesh.weld, mesh.source)
        self.__dict__["_skin_cache"] = (self.mesh, flags, keep, mesh)
        return keep, mesh

    def skin_tiles(self) -> list[int]:
        """The UDIM tiles that hold skin, in order; none for a face on a single tile."""
        if self.uv_tiles is None:
            return []
        skin = self.skin_weights()[self.mesh.weld] > 0
        return [self.uv_tiles.layout.tiles[i] for i in np.unique(self.uv_tiles.vertex_tile[skin])]

    @property
    def pose_names(self) -> list[str]:
        return [NEUTRAL, *(p.name for p in self.poses)]

    def pose(self, name: str) -> KeyPose:
        if name == NEUTRAL:
            return KeyPose(NEUTRAL, self.mesh.rest)
        for pose in self.poses:
            if pose.name == name:
                return pose
        names = self.pose_names
        if len(names) <= MANY_POSE_NAMES:
            raise StudioError(f"unknown pose '{name}' (poses: {', '.join(names)})")
        close = difflib.get_close_matches(name, names, n=4, cutoff=0.5)
        hint = f"; closest: {', '.join(close)}" if close else ""
        raise StudioError(f"unknown pose '{name}' (the project has {len(names) - 1} key poses "
                          f"and the neutral{hint})")

    def wrinkle_weights(self, weights: Mapping[str, float]) -> dict[str, float]:
        """The pose weights as the wrinkles see them: each through its pose's onset (the furrow
        controls'), the face's shape still following ``weights`` themselves."""
        names = list(weights)
        seen = onset_weight([weights[n] for n in names], self.furrows.onsets(names))
        return dict(zip(names, (float(w) for w in seen), strict=True))

    def has_onsets(self, poses: Iterable[str]) -> bool:
        """Whether any of ``poses`` shows its lines later than its weight (an onset above 0)."""
        return bool((self.furrows.onsets(poses) > 0.0).any())

    def activations(self, weights: Mapping[str, float]) -> np.ndarray:
        """Technique 1's area activations at these pose weights, each pose through its onset."""
        return self.influence.activations(self.wrinkle_weights(weights))

    def activations_over(self, poses: Sequence[str], weights: np.ndarray) -> np.ndarray:
        """(F, N) activations for F frames of ``weights`` (F, len(poses)), through the onsets."""
        seen = onset_weight(np.asarray(weights, dtype=np.float64), self.furrows.onsets(poses))
        return self.influence.activations_over(poses, seen)

    def single_pose_weights(self, name: str, weight: float = 1.0) -> dict[str, float]:
        """Weights that show one key pose (at ``weight``) and nothing else."""
        self.pose(name)
        return {} if name == NEUTRAL else {name: weight}
