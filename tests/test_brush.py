"""Brush dabs and strokes: footprint, falloff, spacing, erase, and the touched rectangle."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.brush import Brush, Stroke, TileBackup, falloff, stamp, tile_changes

pytestmark = pytest.mark.core


def test_hard_dab_covers_exactly_the_pixels_within_the_radius():
    mask = np.zeros((64, 64), np.float32)
    rect = stamp(mask, 32.0, 32.0, Brush(radius=5.0, hardness=1.0, flow=1.0, opacity=1.0))
    yy, xx = np.mgrid[0:64, 0:64] + 0.5
    inside = np.hypot(xx - 32.0, yy - 32.0) < 5.0
    assert np.array_equal(mask == 1.0, inside)
    assert mask[~inside].max() == 0.0
    x, y, w, h = rect
    assert (x, y, w, h) == (26, 26, 12, 12)  # floor(32-5.5) .. ceil(32+5.5)


def test_soft_falloff_is_full_inside_the_hardness_and_zero_at_the_radius():
    d = np.array([0.0, 2.0, 5.0, 7.5, 10.0, 12.0], np.float32)
    f = falloff(d, 10.0, 0.5)
    assert f[:3].tolist() == [1.0, 1.0, 1.0]
    assert f[3] == pytest.approx(0.5)  # halfway through the fade: smoothstep(0.5) = 0.5
    assert f[4] == 0.0 and f[5] == 0.0


def test_flow_and_opacity_build_up_but_never_past_opacity():
    mask = np.zeros((16, 16), np.float32)
    brush = Brush(radius=4, hardness=1.0, flow=0.5, opacity=0.8)
    stamp(mask, 8, 8, brush)
    assert mask[8, 8] == pytest.approx(0.4)
    stamp(mask, 8, 8, brush)
    assert mask[8, 8] == pytest.approx(0.6)
    for _ in range(30):
        stamp(mask, 8, 8, brush)
    assert mask[8, 8] == pytest.approx(0.8, abs=1e-4)
    stamp(mask, 8, 8, brush, pressure=0.5)
    assert mask.max() <= 0.8 + 1e-6


def test_erase_lowers_toward_zero():
    mask = np.ones((16, 16), np.float32)
    stamp(mask, 8, 8, Brush(radius=3, hardness=1.0, flow=0.5, opacity=1.0, erase=True))
    assert mask[8, 8] == pytest.approx(0.5)
    assert mask[0, 0] == 1.0


def test_dab_off_the_mask_touches_nothing_and_edge_dab_is_clipped():
    mask = np.zeros((16, 16), np.float32)
    assert stamp(mask, -50, -50, Brush(radius=4)) is None
    rect = stamp(mask, 0, 0, Brush(radius=4))
    assert rect[0] == 0 and rect[1] == 0 and rect[2] <= 5 and rect[3] <= 5


def test_stroke_spacing_places_dabs_along_the_drag():
    mask = np.zeros((64, 256), np.float32)
    stroke = Stroke(mask, Brush(radius=10, spacing=0.5))  # a dab every 5 px
    stroke.jump(20, 32)
    stroke.to(70, 32)  # 50 px: 10 more dabs
    assert stroke.dabs == 11
    stroke.to(72, 32)  # 2 px: not yet
    assert stroke.dabs == 11
    stroke.to(75, 32)  # 5 px since the last dab
    assert stroke.dabs == 12
    assert mask[32, 20:76].min() > 0 and mask[32, 100:].max() == 0
    assert mask[0:10].max() == 0  # rows beyond the radius untouched


def test_mirrored_stroke_paints_both_sides():
    mask = np.zeros((32, 100), np.float32)
    Stroke(mask, Brush(radius=3, hardness=1.0, flow=1.0), mirror=True).jump(20, 16)
    assert mask[16, 20] == 1.0 and mask[16, 79] == 1.0
    assert np.array_equal(mask, mask[:, ::-1])


def test_tile_backup_keeps_only_touched_tiles():
    mask = np.zeros((512, 512), np.float32)
    stroke = Stroke(mask, Brush(radius=5))
    stroke.jump(100, 100)
    changes = stroke.backup.changes()
    assert len(changes) == 1
    x, y, before, after = changes[0]
    assert (x, y) == (64, 64) and before.max() == 0 and after.max() > 0
    backup = TileBackup(mask)
    backup.touch((0, 0, 1, 1))
    assert backup.changes() == []  # touched but unchanged: nothing stored


def test_tile_changes_finds_the_differing_tiles():
    a = np.zeros((130, 130), np.float32)
    b = a.copy()
    b[129, 129] = 1.0
    changes = tile_changes(a, b)
    assert [(x, y) for x, y, _, _ in changes] == [(128, 128)]
    assert changes[0][3].shape == (2, 2)


def test_dab_on_4096_mask_touches_only_its_rectangle():
    """Only the dab's rectangle is touched (speed is the benchmark's to measure)."""
    mask = np.zeros((4096, 4096), np.float32)
    brush = Brush(radius=40, hardness=0.5, flow=0.5)
    for i in range(200):
        rect = stamp(mask, 1000 + i, 2000, brush)
    _, _, w, h = rect
    assert w <= 82 and h <= 82
    assert mask[:1900].max() == 0 and mask[2100:].max() == 0
    assert mask[:, :950].max() == 0 and mask[:, 1250:].max() == 0
