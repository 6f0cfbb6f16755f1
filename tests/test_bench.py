"""The benchmark command's output, and the optimised shading paths against the thesis's forms."""

from __future__ import annotations

import csv
import itertools
import re

import numpy as np
import pytest

from studio.cli import main
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

COLUMNS = ["technique", "areas", "vertices", "width", "height", "frames", "mean_ms", "fps_mean",
           "fps_min", "fps_max", "fps_std", "relief", "draw", "poses", "frame", "cpu_ms", "look"]


def test_quick_bench_writes_a_well_formed_csv_and_plots(tmp_path, capsys):
    out = tmp_path / "bench"
    assert main(["bench", "--quick", "--frames", "2", "--size", "160x120",
                 "--out", str(out)]) == 0
    with (out / "results.csv").open() as f:
        reader = csv.DictReader(f)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    techniques = {r["technique"] for r in rows}
    assert techniques == {"flat", "none", "t1", "t2", "strain"}
    for row in rows:
        assert int(row["frames"]) == 2 and (row["width"], row["height"]) == ("160", "120")
        assert float(row["mean_ms"]) > 0 and float(row["fps_min"]) <= float(row["fps_max"])
        assert float(row["cpu_ms"]) > 0
    # every configuration in the user's default frame; the thesis's own ones in its frame too
    default = [r for r in rows if r["frame"] == "mikktspace"]
    thesis = {(r["technique"], r["areas"], r["vertices"]) for r in rows if r["frame"] == "thesis"}
    assert len(default) + len(thesis) == len(rows)
    assert thesis == {("t2", "0", "561"), ("t1", "8", "561"), ("t1", "8", "2172"),
                      ("t1", "1", "2172"), ("t1", "16", "2172")}
    reliefs = {(r["technique"], r["relief"]) for r in rows if r["relief"] != "off"}
    assert reliefs == {(t, r) for t in ("t1", "t2") for r in ("displace", "parallax")}
    whole = {(r["technique"], int(r["areas"])) for r in rows if r["draw"] == "whole"}
    assert whole == {("t2", 0), ("t1", 1), ("t1", 16), ("t1", 64)}
    areas = sorted(int(r["areas"]) for r in rows if r["technique"] == "t1")
    assert areas[-1] >= 16
    # the skin look's cost (issue 46): each technique and none, in the skin look, on the area model
    skin = {(r["technique"], r["vertices"]) for r in rows if r["look"] == "skin"}
    assert skin == {(t, "2172") for t in ("none", "t1", "t2")}
    for plot in ("fps_by_areas.png", "fps_by_vertices.png"):
        assert (out / plot).stat().st_size > 1000
    printed = capsys.readouterr().out
    assert re.match(r"OpenGL [34]\.\d core, ", printed) and "configuration" in printed


def test_quick_bench_times_52_poses_moving_beside_the_still_face(tmp_path, capsys):
    """``--poses 52``: a capture take's case on the 30000-vertex face, every weight changing
    every frame, shaded plainly and by the strain mode, reported beside the same face held
    still; the plots leave them out."""
    out = tmp_path / "bench"
    assert main(["bench", "--quick", "--poses", "52", "--frames", "2", "--size", "160x120",
                 "--out", str(out)]) == 0
    with (out / "results.csv").open() as f:
        rows = [r for r in csv.DictReader(f) if r["vertices"] == "30000"]
    assert [(r["technique"], r["poses"], r["frame"]) for r in rows] == [
        ("none", "0", "mikktspace"), ("none", "52", "mikktspace"), ("strain", "52", "mikktspace")]
    printed = capsys.readouterr().out
    table = printed[printed.rindex("configuration"):]
    assert "none, still, 30000 vertices" in table
    assert "none, 52 poses moving, 30000 vertices" in table
    assert "strain, 52 poses moving, 30000 vertices" in table
    assert "none, 561 vertices" in table  # --quick keeps its own configurations


def test_capture_animation_moves_every_pose_every_frame():
    from studio.bench.configs import Config
    from studio.bench.poses import bench_animation, bench_project

    config = Config("none", 0, 561, poses=52)
    project = bench_project(config)
    assert len(project.poses) == 52
    timeline = bench_animation(project, config)
    frames = [timeline.weights_at(f) for f in range(timeline.end + 1)]
    assert all(len(w) == 52 for w in frames)
    for a, b in itertools.pairwise(frames):
        assert all(a[p] != b[p] for p in a)
    deltas = [p.positions - project.mesh.rest for p in project.poses]
    assert all(np.abs(d).max() > 0 for d in deltas)
    assert not any(np.array_equal(deltas[0], d) for d in deltas[1:])


def test_bench_rejects_zero_frames(tmp_path, capsys):
    assert main(["bench", "--frames", "0", "--out", str(tmp_path)]) == 2
    assert "--frames" in capsys.readouterr().err


@pytest.fixture
def studio(sample, gl_context):
    s = OffscreenStudio(sample, 400, 300, ctx=gl_context)
    yield s
    s.release()


def test_composed_technique_1_matches_the_per_layer_loop(studio):
    """Within 2/255 per channel: the composed weight is stored at half precision."""
    weights = {"surprise": 1.0, "squeeze": 0.6}
    direct = studio.render(RenderSettings(technique="t1", t1_mode="direct"), weights)
    composed = studio.render(RenderSettings(technique="t1"), weights)
    none = studio.render(RenderSettings(technique="none"), weights)
    assert np.abs(direct.astype(int) - none.astype(int)).max() > 20  # wrinkles are showing
    assert np.abs(direct.astype(int) - composed.astype(int)).max() <= 2


@pytest.mark.parametrize("technique", ["t1", "t2"])
def test_normal_blending_shows_the_same_wrinkles_and_nothing_elsewhere(studio, technique):
    weights = {"surprise": 1.0}
    none = studio.render(RenderSettings(technique="none"), weights)
    colour = studio.render(RenderSettings(technique=technique), weights)
    normal = studio.render(RenderSettings(technique=technique, blend="normal"), weights)
    changed_colour = np.abs(colour.astype(int) - none.astype(int)).max(axis=2) > 3
    changed_normal = np.abs(normal.astype(int) - none.astype(int)).max(axis=2) > 3
    assert changed_colour.sum() > 200
    overlap = (changed_colour & changed_normal).sum() / changed_colour.sum()
    assert overlap > 0.8  # the same wrinkles appear, shaded slightly differently
    neutral = studio.render(RenderSettings(technique="none"), {})
    at_rest = studio.render(RenderSettings(technique=technique, blend="normal"), {})
    assert np.abs(at_rest.astype(int) - neutral).max() <= 1  # float rounding, on a pixel or two


def test_a_held_pose_is_not_deformed_again_and_a_reloaded_mesh_is(studio):
    """The per-frame work skips what did not change: the same weights again deform and upload
    nothing — but a new mesh (which starts at rest) is posed again with the same weights."""
    scene, settings = studio.scene, RenderSettings(technique="t2")
    rest = studio.render(settings, {})
    assert scene.set_pose_weights({"surprise": 1.0})
    posed = studio.render(settings)
    assert np.abs(posed.astype(int) - rest.astype(int)).max() > 20
    assert not scene.set_pose_weights({"surprise": 1.0})
    assert np.array_equal(studio.render(settings), posed)
    scene.reload_mesh()
    assert np.array_equal(studio.render(settings), posed)
    assert scene.set_pose_weights({"surprise": 0.5})
    assert not np.array_equal(studio.render(settings), posed)


def test_deformation_is_timed_every_frame(sample):
    from studio.bench.runner import deformation_cpu_ms
    from studio.core.animation.timeline import sequence_all_poses

    timeline = sequence_all_poses([p.name for p in sample.poses], fps=24.0)
    times = deformation_cpu_ms(sample, timeline, 12, "mikktspace")
    assert times.shape == (12,) and np.isfinite(times).all() and (times >= 0).all()


def test_cpu_breakdown_names_every_part(capsys):
    from studio.bench.cpu import main

    assert main(["--vertices", "561", "--repeat", "1", "--areas", "2", "12"]) == 0
    lines = capsys.readouterr().out.splitlines()
    parts = {line.rsplit(None, 2)[0]: float(line.split()[-2]) for line in lines}
    assert set(parts) == {"timeline weights", "blend", "normals + tangents, the face moving",
                          "normals + tangents, every vertex moving",
                          "normals + MikkTSpace tangents, the face moving",
                          "normals + MikkTSpace tangents, every vertex moving",
                          "activations, 2 areas", "activations, 12 areas"}
    assert all(np.isfinite(ms) and ms >= 0 for ms in parts.values())
