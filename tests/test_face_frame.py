"""The face's own frame on heads in any convention: up, front and left found from the poses and
the surface, the face box, and the camera and renders that follow from them."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from studio.cli import main
from studio.core.animation.poses import KeyPose
from studio.core.files.errors import StudioError
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.model import Project
from studio.core.setup.face_frame import aim, detect_face_frame, face_frame, parse_axis
from studio.core.wrinkles.textures import FaceTextures, flat_normal_map, plain_diffuse
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings
from tests.production_head import POSES, ProductionHead, build_head

EXPECTED = {"z": {"up": (0, 0, 1), "front": (0, -1, 0), "left": (1, 0, 0)},
            "y": {"up": (0, 1, 0), "front": (0, 0, 1), "left": (1, 0, 0)}}


def head_project(unit: str = "mm", up: str = "z", poses=POSES) -> tuple[ProductionHead, Project]:
    """The production head as one project (all parts welded in, eyes and teeth not face)."""
    head = build_head(unit, up=up)
    rest, tris, uvs, weld, not_face = [], [], [], [], []
    pose_positions = {p: [] for p in poses}
    n_pos = n_uv = 0
    for part in head.parts:
        part_weld = part.weld if part.weld is not None else np.arange(len(part.uvs))
        rest.append(head.to_world(part.rest))
        uvs.append(part.uvs)
        tris.append(part.triangles + n_uv)
        weld.append(part_weld + n_pos)
        not_face.append(np.full(len(part.rest), part.name != "head"))
        for p in poses:
            pose_positions[p].append(head.to_world(part.poses[p]))
        n_pos += len(part.rest)
        n_uv += len(part.uvs)
    mesh = FaceMesh(np.vstack(rest), np.vstack(tris), np.vstack(uvs), np.concatenate(weld))
    project = Project("head", mesh, [KeyPose(p, np.vstack(v)) for p, v in
                                     pose_positions.items()],
                      FaceTextures(plain_diffuse(8), flat_normal_map(), flat_normal_map()),
                      not_face=np.concatenate(not_face))
    return head, project


@pytest.mark.core
@pytest.mark.parametrize("up", ["z", "y"])
@pytest.mark.parametrize("unit", ["mm", "cm", "m"])
def test_up_front_and_left_are_found_in_any_units_and_axes(unit, up):
    head, project = head_project(unit, up)
    frame = face_frame(project)
    for axis, expected in EXPECTED[up].items():
        np.testing.assert_allclose(getattr(frame, axis), expected, atol=1e-9)
    assert f"up {'+Z' if up == 'z' else '+Y'} (from the motion of" in frame.how
    # the face box, in sample units, is the same whatever the units and axes
    box = head.to_sample(frame.corners())
    lo, hi = box.min(axis=0), box.max(axis=0)
    assert -0.8 < lo[1] < -0.45 and 0.45 < hi[1] < 0.95  # chin … forehead, not the neck
    assert 0.3 < hi[0] < 0.9 and -0.9 < lo[0] < -0.3


@pytest.mark.core
def test_the_box_is_the_same_at_every_scale():
    boxes = []
    for unit in ("mm", "cm", "m"):
        head, project = head_project(unit)
        boxes.append(head.to_sample(face_frame(project).corners()))
    np.testing.assert_allclose(boxes[0], boxes[1], atol=1e-4)
    np.testing.assert_allclose(boxes[0], boxes[2], atol=1e-4)


@pytest.mark.core
def test_a_given_up_axis_wins_and_a_bad_one_is_refused():
    _, project = head_project()
    project.view["up"] = "y"
    frame = face_frame(project)
    assert frame.up == (0.0, 1.0, 0.0) and "up +Y (as given)" in frame.how
    with pytest.raises(StudioError, match="not an axis"):
        parse_axis("diagonal")


@pytest.mark.core
def test_without_poses_the_axis_convention_is_used_and_said():
    _, project = head_project(poses=())
    frame = face_frame(project)
    assert frame.up == (0.0, 0.0, 1.0)  # the Z extent is the longer one
    assert "the longer of the Y and Z extents; give --up to choose" in frame.how
    assert "no key pose deforms the skin" in frame.how
    assert frame.front == (0.0, -1.0, 0.0)  # Blender's convention for Z up
    assert "the usual convention with that up axis" in frame.how


@pytest.mark.core
def test_inward_normals_are_caught():
    _, project = head_project()
    mesh = project.mesh
    flipped = detect_face_frame(mesh.rest, mesh.welded_triangles[:, ::-1],
                                [p.positions for p in project.poses],
                                [p.name for p in project.poses], project.skin_weights())
    assert flipped.front == (0.0, -1.0, 0.0) and "inward" in flipped.how


def test_the_default_render_looks_at_the_face_from_the_front():
    head, project = head_project()
    size = 400
    with OffscreenStudio(project, size, size) as studio:
        image = studio.render(RenderSettings(technique="none"), {})
        camera = studio.camera
    face = np.abs(image.astype(int) - image[0, 0]).max(-1) > 8
    assert face.mean() > 0.4  # the face fills the picture
    points = head.to_world(np.array([[0.0, 0.55, 0.45], [0.0, -0.6, 0.4], [0.3, 0.1, 0.4]]))
    pixels, _ = camera.project(points, size, size)
    forehead, chin, left_cheek = pixels
    assert forehead[1] < chin[1]  # forehead above the chin on screen
    assert left_cheek[0] > forehead[0]  # the character's left is on the right, seen from front
    all_camera = OrbitCamera()
    aim(all_camera, project, "all")
    assert all_camera.distance > 1.3 * camera.distance  # the whole mesh needs to back off


def test_render_frames_the_face_or_everything(tmp_path, capsys):
    head = build_head("cm")
    files = head.write_set(tmp_path / "cm", POSES[:3])
    out = tmp_path / "head.wrinkle"
    args = ["new", "--mesh", str(files["neutral"]), "--not-face", "eye_L", "eye_R", "teeth",
            "-o", str(out)]
    for pose in POSES[:3]:
        args += ["--pose", f"{pose}={files[pose]}"]
    assert main(args) == 0
    assert "assumed: up +Z (from the motion of browInnerUp" in capsys.readouterr().out
    from PIL import Image

    shares = {}
    for frame in ("face", "all"):
        png = tmp_path / f"{frame}.png"
        assert main(["render", str(out), "--frame", frame, "--size", "200x200", "-o",
                     str(png)]) == 0
        image = np.asarray(Image.open(png).convert("RGB")).astype(int)
        shares[frame] = (np.abs(image - image[0, 0]).max(-1) > 8).mean()
    assert shares["face"] > 1.5 * shares["all"]
    with pytest.raises(SystemExit) as stop:
        main(["render", str(out), "--up", "sideways", "-o", str(tmp_path / "x.png")])
    assert stop.value.code == 2
    assert "sideways" in capsys.readouterr().err


def test_home_frames_the_face_and_the_numpad_views_follow_its_axes(open_window, qtbot):
    _, project = head_project()
    window = open_window(project)
    camera = window.doc.camera
    frame = window.doc.face_frame()
    vp = window.viewport
    vp.setFocus()
    qtbot.keyClick(vp, Qt.Key.Key_Home, Qt.KeyboardModifier.ShiftModifier)
    everything = camera.distance
    qtbot.keyClick(vp, Qt.Key.Key_Home)
    assert camera.distance < 0.8 * everything
    np.testing.assert_allclose(camera.target, np.mean(frame.corners(), axis=0), atol=1e-6)
    qtbot.keyClick(vp, Qt.Key.Key_3, Qt.KeyboardModifier.KeypadModifier)  # right side view
    np.testing.assert_allclose(camera.direction(), frame.left, atol=1e-9)
    qtbot.keyClick(vp, Qt.Key.Key_7, Qt.KeyboardModifier.KeypadModifier)  # from above
    assert np.dot(camera.direction(), frame.up) > 0.99
    qtbot.keyClick(vp, Qt.Key.Key_1, Qt.KeyboardModifier.KeypadModifier)  # front
    np.testing.assert_allclose(camera.direction(), frame.front, atol=1e-9)


@pytest.mark.core
def test_the_mirror_plane_is_the_heads_own_not_x_zero():
    """The head stands 35 cm to the side of the origin: mirroring across x = 0 would land
    nowhere near the face; across the face's own plane, the left eye corner maps to the
    right one."""
    from studio.core.mesh import selection as sel

    head, project = head_project("mm")
    frame = face_frame(project)
    assert frame.mirror_axis == 0
    assert frame.mirror_plane == pytest.approx(head.to_world(np.zeros((1, 3)))[0, 0], abs=0.5)
    face = head.to_sample(project.mesh.rest)
    skin = ~project.not_face
    corner = {}
    for side in (1, -1):
        d = np.hypot(face[:, 0] - side * 0.45, face[:, 1] - 0.075) + 10 * (face[:, 2] < 0.2)
        corner[side] = int(np.argmin(np.where(skin, d, np.inf)))
    mirrored = sel.mirror_map(project.mesh.rest, frame.mirror_axis, frame.mirror_plane)
    mapped = face[mirrored[corner[1]]]
    assert np.hypot(mapped[0] + 0.45, mapped[1] - 0.075) < 0.05
