"""``auto_setup.narrow_cones`` leaves out, before any angle is taken, the vertices and pose
pairs whose motion cannot reach far enough along an area's vectors to cross its cones (issue
51: 20 s of the 30 000-vertex, 52-pose head's set-up). The cones must come out exactly as
when every other pose and every pair of them is tried at every vertex (the reference below, as
the set-up did it before), on a hand-made head in millimetres, Z up and far from the origin,
whose poses each move much of the face in other directions (crossings everywhere), with cones
of 20°, 45° (anatomy's lines) and a painted 120° (wider than the bound holds for)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.setup import auto_setup as auto
from studio.core.wrinkles.wdv import WdvArea

pytestmark = pytest.mark.core

POSES = 14


def _reference(area: WdvArea, motions: dict, squeezed: dict, lines: dict | None) -> np.ndarray:
    """The area's cones, every other pose and every pair of them tried at every vertex."""
    index = np.flatnonzero(area.authored)
    direction = area.directions[index].astype(np.float64)
    length = area.lengths[index].astype(np.float64)
    full = area.vertex_cones_deg()[index].astype(np.float64)
    own = None if lines is None else lines.get(area.pose)
    singles = []
    for pose, motion in motions.items():
        if pose == area.pose or pose not in squeezed:
            continue
        delta = motion[index].astype(np.float64)
        weight = np.asarray(squeezed[pose])[index]
        if own is not None:
            theirs = lines.get(pose)
            weight = np.where(own[index] if theirs is None else own[index] & ~theirs[index],
                              0.0, weight)
        singles.append((delta, weight, np.linalg.norm(delta, axis=1) / length))
    tried = [(delta, weight, auto.CROSS_SHOWN, np.ones(len(index), bool))
             for delta, weight, _ in singles]
    moving = [s for s in singles if s[2].max() > 0.5 * auto.CROSS_SHOWN]
    for i, (delta, weight, reach) in enumerate(moving):
        for other, other_weight, other_reach in moving[i + 1:]:
            both = np.maximum(weight, other_weight)
            tried.append((delta + other, both, auto.PAIR_SHOWN,
                          (reach + other_reach > auto.PAIR_SHOWN) & (both < auto.CROSS_SQUEEZED)))
    cone = full.copy()
    for delta, weight, least, considered in tried:
        size = np.linalg.norm(delta, axis=1)
        cos = np.einsum("ij,ij->i", delta, direction) / np.maximum(size, 1e-300)
        alpha = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        shown = size / length * (1.0 - alpha / full)
        crosses = (considered & (size > 0.0) & (alpha < full) & (shown > least)
                   & (weight < auto.CROSS_SQUEEZED))
        cone[crosses] = np.minimum(cone[crosses],
                                   np.maximum(auto.CONE_SHRINK * alpha[crosses], auto.LEAST_CONE))
    painted = (np.zeros(len(area.lengths), np.float32) if area.cone_angles_deg is None
               else area.cone_angles_deg.copy())
    painted[index] = np.where(cone < full, cone, painted[index])
    return np.where(painted > 0, painted, np.float32(area.cone_angle_deg)).astype(np.float32)


def _head(rng: np.random.Generator) -> tuple[np.ndarray, dict, dict, dict]:
    """A domed face of 4000 vertices (millimetres, Z up, far from the origin) and ``POSES``
    poses, each a few smooth bumps of motion in random directions over much of the face;
    squeeze weights smooth too, some under ``CROSS_SQUEEZED``; placed lines for three poses."""
    u, v = rng.uniform(-1.0, 1.0, (2, 4000))
    rest = np.c_[80.0 * u, -60.0 * (1.0 - 0.5 * (u * u + v * v)), 100.0 * v] + [250, -40, 1600]
    motions, squeezed, lines = {}, {}, {}
    for p in range(POSES):
        name = f"pose{p:02d}"
        motion = np.zeros((len(u), 3))
        for _ in range(3):
            centre = rng.uniform(-1.0, 1.0, 2)
            bump = np.exp(-((u - centre[0]) ** 2 + (v - centre[1]) ** 2) / 0.5)
            motion += bump[:, None] * rng.normal(0.0, 4.0, 3)
        motions[name] = motion.astype(np.float32)
        centre = rng.uniform(-1.0, 1.0, 2)
        squeezed[name] = 0.3 * np.exp(-((u - centre[0]) ** 2 + (v - centre[1]) ** 2) / 0.2)
        if p % 5 == 0:
            lines[name] = np.hypot(u - centre[0], v - centre[1]) < 0.3
    return rest.astype(np.float32), motions, squeezed, lines


@pytest.mark.parametrize("with_lines", [False, True])
def test_the_cones_narrow_exactly_as_when_every_pose_and_pair_is_tried(with_lines):
    rng = np.random.default_rng(51)
    rest, motions, squeezed, lines = _head(rng)
    areas = []
    for p, (name, motion) in enumerate(motions.items()):
        moved = np.linalg.norm(motion, axis=1)
        area = auto.wdv_area_from_selection(name, name, rest, rest + motion,
                                            moved > 0.2 * moved.max(),
                                            cone_angle_deg=(20.0, 45.0)[p % 2])
        if p % 3 == 0:  # a painted cone wider than a right angle on part of it
            area.cone_angles_deg = np.where(rest[:, 0] > 250.0, 120.0, 0.0).astype(np.float32)
        areas.append(area)
    placed = lines if with_lines else None
    expected = [_reference(area, motions, squeezed, placed) for area in areas]
    auto.narrow_cones(areas, motions, squeezed, placed)
    narrowed = 0
    for area, cones in zip(areas, expected, strict=True):
        np.testing.assert_array_equal(area.vertex_cones_deg(), cones, err_msg=area.name)
        narrowed += int((cones[area.authored] < area.cone_angle_deg).sum())
    assert narrowed > 1000  # crossings enough to tell a bound that leaves some out
