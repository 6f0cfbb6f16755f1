"""The open project on the Qt side: the single source of truth the views watch.

Views never own data: they read from the document, listen to its signals and change it only by
pushing undo commands (through the methods below). A signal per kind of change lets each view
redo only what that change affects — the viewport re-uploads only the touched GPU data.
"""

from __future__ import annotations

from collections.abc import Hashable
from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from studio.core.animation.poses import PoseBlender
from studio.core.mesh.camera import OrbitCamera
from studio.core.project.model import Project
from studio.core.project.view_settings import ViewSettings
from studio.core.setup.face_frame import FaceFrame, aim, face_frame
from studio.core.wrinkles.relief import suggested_relief_depth
from studio.core.wrinkles.wdv import WdvArea
from studio.widgets.commands import ValueCommand


class Document(QObject):
    projectReplaced = Signal()  # a different project: everything changed
    posesChanged = Signal()  # the set of key poses (or the mesh) changed
    texturesChanged = Signal()
    poseWeightsChanged = Signal()
    activationsChanged = Signal()  # technique-1 activation sliders (pose links follow weights)
    areasChanged = Signal()  # technique-1 areas: added, removed, renamed, reordered, links
    curvesChanged = Signal()  # technique-1 links' response curves (activationsChanged follows)
    masksChanged = Signal()  # technique-1 mask stack replaced (size or count changed)
    maskRegionChanged = Signal(int, int, int, int, int)  # layer, x, y, w, h (image pixels)
    wdvChanged = Signal()  # technique-2 areas, vectors, cone angles
    furrowsChanged = Signal()  # the synthesised furrows' controls (the maps follow them)
    wdvSettingsChanged = Signal()  # technique 2's expression factor (a uniform, not the slots)
    selectionChanged = Signal()  # selected vertices (welded indices)
    timelineChanged = Signal()  # keys, interpolation, range, frame rate
    playheadChanged = Signal()  # the current time
    viewChanged = Signal()  # ViewState (technique, debug view, light)
    currentWdvAreaChanged = Signal()  # the technique-2 area that Create, Suggest, … act on
    cameraChanged = Signal()
    pathChanged = Signal()
    modifiedChanged = Signal(bool)

    def __init__(self, project: Project, path: Path | None = None,
                 parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        # bound methods, not lambdas: Qt drops the connections when the document goes
        self.undo_stack.cleanChanged.connect(self._clean_changed)
        self.posesChanged.connect(self._forget_face)
        self._load(project, path)

    def _clean_changed(self, clean: bool) -> None:
        self.modifiedChanged.emit(not clean)

    def _forget_face(self) -> None:
        """New poses: a new face frame and new posed positions (made again when asked for)."""
        self._face = None
        self._blender: PoseBlender | None = None
        self._posed: tuple[tuple, np.ndarray] | None = None

    def posed_positions(self) -> np.ndarray:
        """Welded positions at the current pose weights (what the viewport draws), read-only:
        blended once per change of the weights and shared by every tool that picks, paints or
        draws on the posed face."""
        if self._blender is None:
            self._blender = PoseBlender(self.project.mesh.rest, self.project.poses)
        names = set(self._blender.names)
        weights = {k: v for k, v in self.pose_weights.items() if k in names}
        key = tuple(sorted(weights.items()))
        if self._posed is None or self._posed[0] != key:
            positions = self._blender.blend(weights).copy()
            positions.flags.writeable = False
            self._posed = (key, positions)
        return self._posed[1]

    # --- the whole project ---------------------------------------------------------------------
    def _load(self, project: Project, path: Path | None) -> None:
        self._current_wdv: WdvArea | None = None
        self.project = project
        self.path = path
        self.pose_weights: dict[str, float] = {
            k: float(v) for k, v in project.view.get("pose_weights", {}).items()
            if k in project.pose_names}
        self.view = ViewSettings.from_dict(project.view.get("view", {}))
        if "relief_depth" not in project.view.get("view", {}):  # scaled to this face's units
            self.view = self.view.with_changes(
                relief_depth=suggested_relief_depth(*project.mesh.bounds()))
        # selected vertices (welded indices) for technique-2 authoring; changed by commands in
        # studio/widgets/wdv/edits.py, announced by selectionChanged
        self.selection = np.zeros(project.mesh.n_welded, dtype=bool)
        self.frame = float(project.view.get("frame", project.timeline.start))  # the playhead
        self._forget_face()  # the face frame and posed positions: found when first asked for
        self.camera = OrbitCamera.from_dict(project.view.get("camera", {}))
        if "camera" not in project.view:
            self.frame_face()

    def replace_project(self, project: Project, path: Path | None) -> None:
        """Open another project: a fresh undo history, every view refreshed."""
        self.undo_stack.clear()
        self._load(project, path)
        self.undo_stack.setClean()
        self.projectReplaced.emit()
        self.pathChanged.emit()
        self.modifiedChanged.emit(False)

    @property
    def modified(self) -> bool:
        return not self.undo_stack.isClean()

    @property
    def display_name(self) -> str:
        return self.path.stem if self.path else self.project.name

    def store_view_state(self) -> None:
        """Copy view state into the project so that it is saved with it."""
        self.project.view["view"] = self.view.to_dict()
        self.project.view["camera"] = self.camera.to_dict()
        self.project.view["pose_weights"] = dict(self.pose_weights)
        self.project.view["frame"] = self.frame

    def mark_saved(self, path: Path) -> None:
        self.path = path
        self.undo_stack.setClean()
        self.pathChanged.emit()

    # --- edits (undoable) ----------------------------------------------------------------------
    def _push(self, text: str, read, apply, value, merge_key: Hashable | None) -> None:
        if read() == value:
            return
        self.undo_stack.push(ValueCommand(text, read, apply, value, merge_key))

    def set_pose_weight(self, name: str, weight: float, gesture: int | None = None) -> None:
        """Show the face at a pose weight: view state like the playhead and the camera (saved
        with the project, but neither an undo step nor an unsaved change), because moving a
        pose slider to look at an expression edits nothing; keying it on the timeline (K) is
        the edit. ``gesture`` is kept for the callers' symmetry with the edits."""
        del gesture
        weight = float(weight)
        if self.pose_weights.get(name, 0.0) == weight:
            return
        self.pose_weights[name] = weight
        self.poseWeightsChanged.emit()

    def set_area_activation(self, index: int, value: float, gesture: int | None = None) -> None:
        area = self.project.influence.areas[index]

        def apply(v: float) -> None:
            area.activation = v
            self.activationsChanged.emit()

        key = None if gesture is None else ("activation", id(area), gesture)
        self._push(f"Activation {area.name}", lambda: area.activation, apply, float(value), key)

    def set_expression_factor(self, value: float, gesture: int | None = None) -> None:
        wdv = self.project.wdv

        def apply(v: float) -> None:
            wdv.expression_factor = v
            self.wdvSettingsChanged.emit()

        key = None if gesture is None else ("expression", gesture)
        self._push("Expression factor", lambda: wdv.expression_factor, apply, float(value), key)

    def set_cone_angle(self, degrees: float, gesture: int | None = None) -> None:
        """Cone half-angle θ_max of the current technique-2 area (the others keep theirs)."""
        area = self.current_wdv_area
        if area is None:
            return

        def apply(value: float) -> None:
            area.cone_angle_deg = value
            self.wdvChanged.emit()

        key = None if gesture is None else ("cone", id(area), gesture)
        self._push(f"Cone angle {area.name}", lambda: area.cone_angle_deg, apply,
                   float(degrees), key)

    # --- the current technique-2 area: what its panel, Create and the cone slider act on ---------
    @property
    def current_wdv_area(self) -> WdvArea | None:
        """The chosen area; the first one when none is chosen or the chosen one left the list
        (deleted, or its addition undone)."""
        areas = self.project.wdv.areas
        if not any(a is self._current_wdv for a in areas):
            self._current_wdv = areas[0] if areas else None
        return self._current_wdv

    def set_current_wdv_area(self, area: WdvArea | None) -> None:
        """Choose the area (view state, not an edit; the area-list commands restore it)."""
        if area is not self._current_wdv:
            self._current_wdv = area
            self.currentWdvAreaChanged.emit()

    # --- derived values ------------------------------------------------------------------------
    def activations(self) -> np.ndarray:
        """Technique-1 activation vector: sliders plus the links from the current pose weights."""
        return self.project.activations(self.pose_weights)

    # --- playback (not undoable, like scrubbing in any animation tool) ------------------------
    def show_frame(self, frame: float) -> None:
        """Move the playhead; an animated project's pose follows the timeline."""
        self.frame = float(frame)
        timeline = self.project.timeline
        if timeline.has_keys:
            self.pose_weights = {**self.pose_weights, **timeline.weights_at(self.frame)}
            self.poseWeightsChanged.emit()
        self.playheadChanged.emit()

    # --- view state (saved, not undoable) ------------------------------------------------------
    def set_view(self, **changes) -> None:
        """Change view settings (the view model is immutable: a new one replaces it)."""
        self.view = self.view.with_changes(**changes)
        self.viewChanged.emit()

    def face_frame(self) -> FaceFrame:
        """Where the face is and which way is up and front (found once per set of poses)."""
        if self._face is None:
            self._face = face_frame(self.project)
        return self._face

    def mirror_plane(self) -> tuple[int, float]:
        """(model axis, position) of the face's left–right symmetry plane, for mirroring."""
        face = self.face_frame()
        return face.mirror_axis, face.mirror_plane

    def frame_face(self) -> None:
        """View ▸ Frame Face: the face from its front-facing side, filling the view."""
        aim(self.camera, self.project, "face", self.face_frame())
        self.cameraChanged.emit()

    def frame_all(self) -> None:
        """View ▸ Frame All: the whole mesh (neck, shoulders, eyes…), turned to the face's axes."""
        aim(self.camera, self.project, "all", self.face_frame())
        self.cameraChanged.emit()
