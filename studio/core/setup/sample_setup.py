"""The bundled sample as the studio opens on it: the ICT-FaceKit head
(studio.core.sample.ict_head) set up for wrinkles the way a user would set up their own head —
the automatic set-up of its wrinkling expressions — with a timeline that plays a few whole
expressions. Built at start in a few seconds, from the 3.6 MB resource alone."""

from __future__ import annotations

import copy
from collections.abc import Callable
from functools import lru_cache

from studio.core.animation.timeline import Key, Timeline
from studio.core.project.model import Project
from studio.core.sample.ict_head import load_ict_head
from studio.core.setup.auto_setup import auto_start
from studio.core.setup.face_frame import face_frame, face_locator
from studio.core.setup.stage_clock import stage

# The expressions that wrinkle, by region: each gets an influence area and wrinkle vectors.
WRINKLING = {
    "forehead": ("browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R"),
    "glabella": ("browDown_L", "browDown_R"),
    "crow's feet": ("eyeSquint_L", "eyeSquint_R", "cheekSquint_L", "cheekSquint_R"),
    "nose": ("noseSneer_L", "noseSneer_R"),
    "nasolabial folds": ("mouthSmile_L", "mouthSmile_R"),
    "chin": ("mouthShrugLower", "mouthFrown_L", "mouthFrown_R"),
    "lips": ("mouthPucker",),
}
# A few expressions, each rising, held and falling back: what the timeline plays.
EXPRESSIONS = (
    ("surprise", ("browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R")),
    ("frown", ("browDown_L", "browDown_R", "mouthFrown_L", "mouthFrown_R")),
    ("smile", ("mouthSmile_L", "mouthSmile_R", "cheekSquint_L", "cheekSquint_R")),
    ("squint", ("eyeSquint_L", "eyeSquint_R", "noseSneer_L", "noseSneer_R")),
    ("doubt", ("mouthShrugLower", "browInnerUp_L", "browDown_R")),
    ("kiss", ("mouthPucker",)),
)


def wrinkling_poses() -> list[str]:
    return [pose for poses in WRINKLING.values() for pose in poses]


def expression_timeline(fps: float = 24.0, rise: float = 0.5, hold: float = 0.75,
                        fall: float = 0.5) -> Timeline:
    """neutral → expression → neutral for each of ``EXPRESSIONS`` in turn: several poses keyed
    together, so the face plays whole expressions, not one ARKit shape at a time."""
    timeline = Timeline(fps=fps)
    up, held, down = (round(s * fps) for s in (rise, hold, fall))
    frame = 0.0
    for _, poses in EXPRESSIONS:
        for pose in poses:
            timeline.track(pose).keys += [Key(frame, 0.0, "cosine"), Key(frame + up, 1.0, "cosine"),
                                          Key(frame + up + held, 1.0, "cosine"),
                                          Key(frame + up + held + down, 0.0, "cosine")]
        frame += up + held + down
    for track in timeline.tracks:
        track.sort()
    timeline.end = int(frame)
    return timeline


def ready_sample(progress: Callable[[int, int], bool] | None = None) -> Project | None:
    """The bundled sample as the studio opens on it: the head with all 53 expressions, the
    automatic set-up of the wrinkling ones (an area and wrinkle vectors each, wrinkled maps
    synthesised from them) and a timeline of a few expressions. None if ``progress`` stopped."""
    with stage("reading"):
        project = load_ict_head()
    frame = face_frame(project)
    if auto_start(project, locate=face_locator(frame), progress=progress,
                  poses=wrinkling_poses(), frame=frame) is None:
        return None
    project.name = "ICT-FaceKit head (sample)"
    project.timeline = expression_timeline()
    # it opens on the first expression at its height, wrinkles showing, not on a neutral face
    first = project.timeline.tracks[0].keys
    frame = (first[1].frame + first[2].frame) / 2
    project.view["frame"] = frame
    project.view["pose_weights"] = project.timeline.weights_at(frame)
    return project


@lru_cache(maxsize=1)
def _cached_sample() -> Project:
    project = ready_sample()
    assert project is not None  # no progress callback: it always finishes
    return project


def sample_project() -> Project:
    """The ready sample, built once per process (a few seconds); each call returns a deep
    copy, so callers may change what they get."""
    return copy.deepcopy(_cached_sample())
