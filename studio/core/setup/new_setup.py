"""A new project set up from the user's files: the one path ``wrinkle-studio new`` and
File ▸ New from Files both take once the user has chosen, so that a head comes out the same
whichever way it was brought in (the VRM toggles left out, the user's axes over the file's, a
whole body's vertices beyond the head marked not face, the automatic set-up).

It lives in ``setup``, not ``project``: it frames the face and runs the automatic set-up, and
``project`` may not import ``setup`` (the core packages' layering)."""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping
from pathlib import Path
from typing import NamedTuple

from studio.core.files.errors import StudioError
from studio.core.formats.assemble import project_from_files
from studio.core.formats.vrm import leave_out_toggles
from studio.core.project.model import Project
from studio.core.setup.auto_setup import auto_start
from studio.core.setup.face_frame import (
    FaceFrame,
    beyond_the_head,
    face_frame,
    face_locator,
    parse_axis,
)
from studio.core.setup.stage_clock import stage
from studio.core.wrinkles.normalmap import flip_green

Progress = Callable[[int, int], bool]


class NewSetup(NamedTuple):
    """What ``new_project`` made and what it has to say about it."""

    project: Project
    found: list[str]  # what was found or chosen in the files, a line each
    assumed: str  # how the face's up and front were found (``FaceFrame.how``)
    done: list[str] | None  # what the automatic set-up did; None when it was cancelled


def new_project(mesh: str | Path, poses: Mapping[str, str | Path] | None = None,
                diffuse: str | Path | None = None, normal: str | Path | None = None,
                wrinkled: str | Path | None = None, *, flip: bool = False,
                keep: Collection[str] | None = None, not_face: Collection[str] | None = None,
                part_kind: str | None = None, up: str | None = None, front: str | None = None,
                auto: bool = False, progress: Progress | None = None,
                furrows: Mapping[str | None, Mapping[str, float]] | None = None) -> NewSetup:
    """A project from a neutral mesh (OBJ, PLY, glTF, VRM, FBX, …), key-pose files and maps,
    set up as the command line does it. ``keep``, ``not_face`` and ``part_kind`` as
    ``project_from_files``'s; ``flip``: the normal maps are DirectX's (green down); ``up``
    and ``front``: the user's axes (``parse_axis`` spellings), over the file's own; ``auto``:
    toggles left out and the automatic set-up run, reporting to ``progress`` (done, total),
    which cancels it by returning False (``done`` is None then); ``furrows``: the furrow
    controls, {pose (None: all poses): {control: value}}, set before the set-up synthesises
    the maps with them. StudioError for a bad file, axis or control, naming it."""
    for axis in (up, front):
        if axis is not None:
            parse_axis(axis)  # a bad axis fails before any file is read
    found: list[str] = []
    with stage("reading"):
        project = project_from_files(mesh, dict(poses or {}), diffuse, normal, wrinkled,
                                     keep=keep, not_face=not_face, part_kind=part_kind,
                                     report=found)
        if flip:
            _flip_normal_maps(project)
    _choose_axes(project, up, front)
    if furrows:
        _set_furrows(project, furrows)
    with stage("face finding"):
        toggles = leave_out_toggles(project, found) if auto else set()
        frame = _mark_body(project, found)
    done: list[str] | None = []
    if auto:
        carried = set_up_poses(project)
        wanted = [p.name for p in project.poses if p.name not in toggles | carried]
        if carried:  # a file the studio exported: its set-up is kept, not made twice
            found.append(f"already set up in the file, kept: {', '.join(sorted(carried))}")
        if wanted:
            done = auto_start(project, locate=face_locator(frame), progress=progress,
                              poses=wanted if toggles or carried else None, frame=frame)
    return NewSetup(project, found, frame.how, done)


def _set_furrows(project: Project, values: Mapping[str | None, Mapping[str, float]]) -> None:
    """The furrow controls given, on poses the face has (StudioError naming one it lacks)."""
    names = [p.name for p in project.poses]
    for pose in values:
        if pose is not None and pose not in names:
            raise StudioError(f"the furrow controls name a pose the face does not have: "
                              f"'{pose}' (key poses: {', '.join(names) or 'none'})")
    try:
        project.furrows = project.furrows.with_values(values)
    except ValueError as exc:
        raise StudioError(f"furrow controls: {exc}") from None


def set_up_poses(project: Project) -> set[str]:
    """The key poses the project already drives wrinkles with (a file the studio exported,
    read back: its areas and vector areas travel in it): an area linked to it, or a vector
    area made from it."""
    linked = {pose for pose, gains in project.influence.links.items() if gains}
    return (linked | {area.pose for area in project.wdv.areas}) & set(project.pose_names)


def _flip_normal_maps(project: Project) -> None:
    """DirectX normal maps (green down) turned to the studio's OpenGL convention."""
    textures = project.textures
    textures.normal_neutral = flip_green(textures.normal_neutral)
    textures.normal_wrinkled = flip_green(textures.normal_wrinkled)


def _choose_axes(project: Project, up: str | None, front: str | None) -> None:
    """The user's word over the file's (a VRM says its own front): kept in the project's view,
    where the face frame reads it."""
    for key, axis in (("up", up), ("front", front)):
        if axis is not None:
            project.view[key] = axis


def _mark_body(project: Project, found: list[str]) -> FaceFrame:
    """The face frame, after marking a whole body's skin beyond the head as not face (said in
    ``found``): the face is then measured against the head, not a body ten times its size,
    and framed again."""
    frame = face_frame(project)
    body = beyond_the_head(frame, project.mesh.rest, project.skin_weights())
    if body is None:
        return frame
    project.not_face = body if project.not_face is None else project.not_face | body
    found.append(f"a whole body: {int(body.sum())} vertices beyond the head marked not face")
    return face_frame(project)
