"""Mirror an influence area to the other side of the face with the Areas panel's button: the
mask through the mesh, the name and the pose links to their pairs, one undo step."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QPushButton

from studio.core.sample.synthetic import landmark_uvs
from studio.core.wrinkles.surface_mirror import SurfaceMirror, mirror_mask
from tests.test_face_frame import head_project


def mask_at(mask: np.ndarray, name: str) -> float:
    h, w = mask.shape
    u, v = landmark_uvs()[name]
    return float(mask[int((1.0 - v) * h), int(u * w)])


def test_mirror_makes_the_other_sides_area_linked_to_the_paired_pose(window, qtbot):
    doc, panel = window.doc, window.mask_tools.panel
    influence = doc.project.influence
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    names = [a.name for a in influence.areas]
    # start without the right forehead's area: the mirror must make it
    panel.select(names.index("forehead right"))
    qtbot.mouseClick(next(b for b in panel.findChildren(QPushButton) if b.text() == "Delete"),
                     Qt.MouseButton.LeftButton)
    assert "forehead right" not in [a.name for a in influence.areas]
    left = [a.name for a in influence.areas].index("forehead left")
    rect = panel.list.visualItemRect(panel.list.item(left))
    qtbot.mouseClick(panel.list.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    assert panel.state.active == left
    steps = doc.undo_stack.count()
    mirror = next(b for b in panel.findChildren(QPushButton) if b.text() == "Mirror")
    qtbot.mouseClick(mirror, Qt.MouseButton.LeftButton)
    assert doc.undo_stack.count() == steps + 1  # one step
    made = influence.areas[left + 1]
    assert made.name == "forehead right" and panel.state.active == left + 1
    source = influence.areas[left].mask
    assert mask_at(source, "forehead left") > 0.5 and mask_at(source, "forehead right") == 0
    assert mask_at(made.mask, "forehead right") > 0.5  # on the other side …
    assert mask_at(made.mask, "forehead left") == 0.0  # … and only there
    assert abs(made.mask.sum() - source.sum()) < 0.1 * source.sum()  # the same amount
    assert influence.links["brow_raise_right"] == {"forehead right": 1.0}  # the paired pose
    assert influence.links["surprise"]["forehead right"] == 1.0  # a pose without a pair
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert "forehead right" not in [a.name for a in influence.areas]
    assert "forehead right" not in influence.links.get("brow_raise_right", {})


def test_a_mask_mirrors_across_a_head_placed_anywhere():
    """A Z-up head in millimetres, 35 cm off the origin: through its own symmetry plane, a
    blob on the left eye corner lands on the right one."""
    from studio.core.setup.face_frame import face_frame

    head, project = head_project("mm")
    frame = face_frame(project)
    mesh = project.mesh
    face = head.to_sample(mesh.rest)
    size = 256
    uv = mesh.uvs
    welded = face[mesh.weld]
    near = np.hypot(welded[:, 0] - 0.45, welded[:, 1] - 0.075) < 0.06
    mask = np.zeros((size, size), np.float32)
    mask[((1 - uv[near, 1]) * size).astype(int), (uv[near, 0] * size).astype(int)] = 1.0
    mirrored = mirror_mask(mask, SurfaceMirror(mesh, frame.mirror_axis, frame.mirror_plane))
    rows, cols = np.nonzero(mirrored > 0.5)
    texel_uv = np.c_[(cols + 0.5) / size, 1 - (rows + 0.5) / size]
    # where those texels are on the face: the nearest render vertex in UV
    nearest = np.argmin(((uv[None] - texel_uv[:, None]) ** 2).sum(-1), axis=1)
    spots = welded[nearest]
    assert len(spots) > 0.5 * near.sum()
    assert np.all(spots[:, 0] < -0.3) and np.all(np.abs(spots[:, 1] - 0.075) < 0.15)


def test_a_52_pose_rig_keeps_its_names_and_the_filter_finds_a_pose(open_window, qtbot):
    from studio.core.animation.pose_names import ARKIT_NAMES
    from studio.core.animation.poses import KeyPose
    from studio.core.sample.synthetic import make_test_face

    project = make_test_face(561)
    rest = project.mesh.rest
    rng = np.random.default_rng(0)
    project.poses = [KeyPose(name, rest + rng.normal(0, 1e-3, rest.shape).astype(np.float32))
                     for name in ARKIT_NAMES]
    project.influence.links = {}
    project.wdv.areas = []
    project.timeline.tracks = []
    window = open_window(project)
    panel = window.pose_panel
    assert list(panel.pose_rows) == list(ARKIT_NAMES)
    assert panel.pose_rows["eyeBlinkLeft"].label.text() == "eyeBlinkLeft"  # as the rig spells it
    window.docks["Poses"].show()
    window.docks["Poses"].raise_()
    panel.filter.setFocus()
    qtbot.keyClicks(panel.filter, "smile")
    shown = [name for name, row in panel.pose_rows.items() if row.isVisibleTo(panel)]
    assert shown == ["mouthSmileLeft", "mouthSmileRight"]
    panel.filter.clear()
    assert all(row.isVisibleTo(panel) for row in panel.pose_rows.values())
