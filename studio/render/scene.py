"""Keeps a renderer in step with a project: the one path from document data to GPU state.

Both the viewport and the command line use it, so what the studio shows is what it renders.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from studio.core.animation.poses import PoseBlender
from studio.core.project.model import Project
from studio.render.renderer import FaceRenderer


class ProjectScene:
    def __init__(self, renderer: FaceRenderer, project: Project) -> None:
        self.renderer = renderer
        self.project = project
        self.weights: dict[str, float] = {}
        self.preview_area: int | None = None  # technique 1's area shown alone at full strength
        renderer.set_textures(project.textures)  # (the old mesh may still be loaded here)
        self.reload_masks()
        self.reload_mesh()

    def reload_mesh(self) -> None:
        """After the mesh or the set of key poses changed (the WDVs are per vertex, so too)."""
        project = self.project
        self.blender = PoseBlender(project.mesh.rest, project.poses)
        self.renderer.set_mesh(project.mesh, project.poses)
        self.renderer.set_skin(project.skin_weights())
        self.reload_wdv()
        self._posed: dict[str, float] | None = None  # the weights the renderer's pose shows
        self.set_pose_weights(self.weights)

    def reload_textures(self) -> None:
        """New maps; areas name their wrinkled map, so their map indices may have moved too."""
        self.renderer.set_textures(self.project.textures)
        self.reload_area_maps()
        self.reload_wdv()

    def reload_masks(self) -> None:
        self.renderer.set_masks(self.project.influence.mask_stack())
        self.reload_area_maps()
        self.reload_activations()

    def reload_area_maps(self) -> None:
        """After areas were added, removed, reordered or pointed at another wrinkled map."""
        index = self.project.textures.map_index
        self.renderer.set_area_maps([index(a.wrinkle_map) for a in self.project.influence.areas])

    def reload_activations(self) -> None:
        activations = self.project.activations(self.weights)
        if self.preview_area is not None:  # painting: the area being painted, alone, at 1
            activations = (np.arange(len(activations)) == self.preview_area).astype(
                activations.dtype)
        self.renderer.set_activations(activations)

    def reload_wdv(self) -> None:
        wdv = self.project.wdv
        slots = wdv.pack_slots(self.project.mesh.n_welded, self.project.textures.map_index)
        self.renderer.set_wdv(slots, wdv.expression_factor, wdv.scale_free)

    def reload_wdv_settings(self) -> None:
        """The expression factor or scale-free mode changed: uniforms only, no slot repacked."""
        self.renderer.expression_factor = float(self.project.wdv.expression_factor)
        self.renderer.scale_free = bool(self.project.wdv.scale_free)

    def set_pose_weights(self, weights: Mapping[str, float]) -> bool:
        """Deform the face to these key-pose weights; linked technique-1 areas follow. The same
        weights again (a held pose) deform and upload nothing; returns whether the pose changed."""
        self.weights = {k: float(v) for k, v in weights.items() if k in self.blender.names}
        changed = self.weights != self._posed
        if changed:
            if self.renderer.deforms_on_gpu:  # a weight per pose crosses the bus, no more
                self.renderer.set_pose_weights(self.blender.weights_vector(self.weights))
            else:
                self.renderer.set_positions(self.blender.blend(self.weights))
            self._posed = self.weights
            self.reload_drive()
        self.reload_activations()
        return changed

    def reload_onsets(self) -> None:
        """The poses' onsets changed: what every technique's wrinkles see of the pose."""
        self.reload_drive()
        self.reload_activations()

    def reload_drive(self) -> None:
        """What technique 2 and the automatic mode measure: with an onset on a posed pose,
        the face blended with its weights through the onsets; else the face itself."""
        weights = self.weights
        if not self.project.has_onsets(weights):
            self.renderer.set_wrinkle_drive(None, None)
            return
        positions = self.blender.blend(weights).copy()
        self.renderer.set_wrinkle_drive(positions,
                                        self.blender.blend(self.project.wrinkle_weights(weights)))
