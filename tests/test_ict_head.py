"""The real head: ICT-FaceKit's scanned head (MIT), bundled in its compact form
(resources/ict_head, made by scripts/make_ict_head.py), as the sample and as test data.

It is 26 719 vertices in centimetres on seven UDIM tiles, with eye, lash and teeth shells that
share the face's tile: what broke wrinkles on heads made elsewhere. Judged from default
renders: the share of an 800 × 800 render each pose's wrinkles change."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.sample.ict_head import NOT_SKIN_MATERIALS, load_ict_head
from studio.core.setup.auto_setup import auto_start
from studio.core.setup.face_frame import face_frame, face_locator
from studio.core.setup.sample_setup import EXPRESSIONS, WRINKLING, sample_project
from tests.test_skin_uv_writes import check_where_compressed, most_compressed
from tests.visibility import least

POSES = ["browInnerUp_L", "browDown_L", "mouthSmile_L", "eyeSquint_L"]  # judged by render
ISSUE_POSES = [*POSES, "jawOpen"]  # the issue's `new --mesh … --pose … --auto`


@pytest.fixture(scope="module")
def head():
    """The head with the issue's five poses, set up as `new --auto` does, eyes kept."""
    project = load_ict_head(poses=ISSUE_POSES)
    auto_start(project, locate=face_locator(face_frame(project)))
    return project


@pytest.mark.core
def test_the_compact_head_is_the_kit_as_the_studio_imports_it() -> None:
    project = load_ict_head()
    assert project.mesh.n_welded == 26719 and len(project.poses) == 53
    assert {"browDown_L", "mouthSmile_R", "jawOpen", "noseSneer_L"} <= set(project.pose_names)
    assert project.uv_tiles.layout.tiles == (1001, 1002, 1003, 1004, 1005, 1006, 1007)
    assert project.skin_tiles() == [1001, 1002]  # M_Face and M_BackHead
    assert int(project.not_face.sum()) == 12657  # the ten eye, lash, teeth and gum materials
    assert len(NOT_SKIN_MATERIALS) == 10
    # centimetres: a head about 20–30 cm tall; an expression moves the skin by millimetres
    assert 15.0 < np.ptp(project.mesh.rest[:, 1]) < 40.0
    moved = np.linalg.norm(project.pose("browInnerUp_L").positions - project.mesh.rest, axis=1)
    assert 0.3 < moved.max() < 3.0 and (moved == 0.0).mean() > 0.5  # sparse, as stored


@pytest.mark.core
def test_masks_and_furrows_lie_where_each_pose_compresses_with_the_eyes_kept(head) -> None:
    """The eye shells share the face's tile: before the fix the masks and the wrinkled map held
    the neutral value exactly at the vertices each pose compresses most. A brow lowerer
    compresses most above the brow, but its lines lie between the brows, and a squint most
    on the lower lid, but its crow's feet lie beside the outer corner of the eye (issue 38:
    tests/test_furrow_figures.py)."""
    check_where_compressed(head, [pose for pose in POSES
                                  if pose not in ("browDown_L", "eyeSquint_L")])


def check_default_renders(head) -> None:
    """800 × 800, the default camera, each pose at full weight: technique 1 and technique 2
    each change at least ``tests.visibility.least`` of the render (the issue measured 0.000 %
    with the eyes kept),
    and nothing more than 0.45 of the face's height from where the pose compresses (a brow
    raise leaves the mouth and chin alone, a smile the forehead)."""
    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    size = 800
    with OffscreenStudio(head, size, size) as studio:
        background = studio.render(RenderSettings(technique="none"), {})[0, 0].astype(int)
        neutral = studio.render(RenderSettings(technique="none"), {}).astype(int)
        face = np.abs(neutral - background).max(-1) > 8
        rows = np.flatnonzero(face.any(axis=1))
        reach = 0.45 * (rows.max() - rows.min())
        for pose in POSES:
            plain = studio.render(RenderSettings(technique="none"), {pose: 1.0}).astype(int)
            verts = head.mesh.weld[most_compressed(head, pose)]
            pixels, _ = studio.camera.project(head.mesh.rest[verts], size, size)
            cx, cy = pixels.mean(axis=0)
            yy, xx = np.mgrid[0:size, 0:size]
            far = np.hypot(xx - cx, yy - cy) > reach
            for technique in ("t1", "t2"):
                image = studio.render(RenderSettings(technique=technique), {pose: 1.0})
                changed = np.abs(image.astype(int) - plain).max(-1) > 4
                assert changed.mean() >= least(pose), (pose, technique, changed.mean())
                assert not changed[far].any(), (pose, technique, "changed far away")


def test_the_sample_s_default_render_shows_each_pose_s_wrinkles_near_it_only() -> None:
    """The sample as the studio opens on it (18 wrinkling poses, their maps shared). The brow
    lowerer: 1.07 / 1.12 % of the render (t1 / t2) with two lines between the brows, deepest
    low and tapering up to where it stops squeezing the skin (issue 38: the issue's 1 %);
    1.7 / 1.8 % as a comb of three lines up the forehead, 1.0 / 1.2 % when its lines fanned
    out beside the inner brows and technique 2 missed the midline."""
    check_default_renders(sample_project())


def test_the_issue_s_five_pose_new_auto_shows_each_pose_s_wrinkles_near_it_only(head) -> None:
    """The issue's `new --auto` with five poses: each pose's furrows on a map of their own
    or shared with one or two others. The squint compresses a small blob under the eye
    (1.3 % of the skin): it reached 0.5 % here while its smoothed compression stayed under
    the depth's full_at and its mask was a linear ramp. The brow lowerer's lines lie between
    the brows only (issue 38), where it squeezes the skin — most on the side it lowers, and
    on the midline — its mask and vectors holding them whole: two lines, 0.66 / 0.67 % of the
    render (t1 / t2) here, where the face is framed smaller than the sample's (1.05 / 1.07 %
    as a comb of three up the forehead); 0.5 / 0.8 % when its vectors ended short of the
    midline and showed the squint's and the brow raise's lines, 0.000 % with the eyes kept.
    The squint draws crow's feet, a fan of lines from the outer corner of the eye over the
    temple side only, and two lines under the lower lid, where it squeezes the skin (issue 38):
    1.32 / 1.35 % of the render here, seen from the front-left (0.53 / 0.64 % with the crow's
    feet alone, 1.11 / 1.23 % for the crossing lines under the eye before them)."""
    check_default_renders(head)


def test_the_sample_is_the_head_set_up_with_a_timeline_of_expressions() -> None:
    project = sample_project()
    assert project.mesh.n_welded == 26719 and len(project.poses) == 53
    wrinkling = [pose for poses in WRINKLING.values() for pose in poses]
    linked = {pose for pose, gains in project.influence.links.items() if gains}
    assert set(wrinkling) <= linked
    assert {area.pose for area in project.wdv.areas} == set(wrinkling)
    assert len(project.textures.wrinkle_maps) >= 2  # crossing furrows on separate maps
    # the timeline plays each expression in turn: at its peak, its poses at full weight
    step = project.timeline.end / len(EXPRESSIONS)
    for k, (_, poses) in enumerate(EXPRESSIONS):
        weights = project.timeline.weights_at(k * step + step / 2)
        assert all(weights[p] == pytest.approx(1.0) for p in poses)
        assert sum(w > 0 for w in weights.values()) == len(poses)
    assert sample_project() is not project  # a copy each time: callers may change it


@pytest.mark.core
@pytest.mark.parametrize("subset", [True, False])
def test_the_face_box_ends_at_the_chin_and_names_each_pose_after_its_place(subset: bool) -> None:
    """The face is the skin the poses deform; the neck under the chin, pulled by the jaw
    opening alone, is not: the box's bottom is the chin, so F frames the face and the report
    names each pose's place on this real head, with a rig of ten poses or all 53."""
    from studio.core.sample.ict_head import landmark_vertices
    from studio.core.setup.auto_setup import suggest_setup

    named = {"browInnerUp_L": ("forehead", "left brow"), "eyeSquint_L": ("left lower eyelid",),
             "noseSneer_L": ("left side of the nose",),
             "mouthSmile_L": ("left nasolabial fold", "left cheek"),
             "mouthStretch_L": ("left mouth corner",), "jawOpen": ("chin",),
             "eyeBlink_L": ("left upper eyelid", "left lower eyelid"),  # shut on the lower
             "mouthFrown_L": ("left mouth corner",),
             "mouthShrugLower": ("lower lip", "chin")}
    few = [*named, "browDown_L"]  # a rig of ten
    project = load_ict_head(poses=few if subset else None)
    frame = face_frame(project)
    marks = frame.to_face(project.mesh.rest[landmark_vertices()].astype(np.float64))
    assert -0.95 < marks[8, 1] < -0.75  # the chin, at the bottom of the face box
    assert 0.35 < marks[24, 1] < 0.8  # the brows in its upper part
    report = suggest_setup(project, locate=face_locator(frame), poses=list(named))
    for pose, places in named.items():
        assert report.regions[pose] in places, (pose, report.regions[pose])


@pytest.mark.core
def test_an_unknown_pose_of_a_big_rig_is_answered_with_the_closest_names() -> None:
    """53 poses make a line too long to read: the message counts them and names the closest."""
    project = load_ict_head(poses=None)
    with pytest.raises(StudioError) as refused:
        project.pose("browInnerUpL")
    assert str(refused.value) == ("unknown pose 'browInnerUpL' (the project has 53 key poses "
                                  "and the neutral; closest: browInnerUp_L, browInnerUp_R, "
                                  "browOuterUp_L, browOuterUp_R)")
    with pytest.raises(StudioError, match=r"53 key poses and the neutral\)$"):
        project.pose("zzz")
