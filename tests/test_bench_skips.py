"""The benchmark never loses what it timed: a configuration the driver cannot draw is skipped
with the reason, and results.csv is written as each face's configurations finish."""

from __future__ import annotations

import csv

import pytest

from studio.bench.configs import Config
from studio.bench.poses import bench_animation, bench_project
from studio.bench.runner import time_configurations
from studio.cli import main
from studio.core.files.errors import StudioError
from studio.render.renderer import FaceRenderer


@pytest.fixture
def no_tessellation(monkeypatch):
    """A driver of OpenGL 3.3, as NVIDIA's answer to a 3.3 request was: no relief displace."""
    monkeypatch.setattr(FaceRenderer, "can_displace", property(lambda self: False))


def test_a_configuration_the_driver_cannot_draw_is_skipped_with_why(gl_context,
                                                                      no_tessellation):
    configs = [Config("t2", 0, 561), Config("t2", 0, 561, relief="displace"),
               Config("none", 0, 561)]
    skipped: list[tuple[Config, str]] = []
    results = time_configurations(gl_context, [bench_project(c) for c in configs], configs,
                                  frames=2, size=(64, 48),
                                  skipped=lambda c, why: skipped.append((c, why)))
    assert [r.config for r in results] == [configs[0], configs[2]]
    assert [c for c, _ in skipped] == [configs[1]]
    assert "needs OpenGL 4.0" in skipped[0][1]
    assert all(len(r.frame_ms) == 2 and len(r.cpu_ms) == 2 for r in results)


def test_bench_prints_the_skipped_and_writes_the_rest(tmp_path, capsys, no_tessellation,
                                                      monkeypatch):
    import studio.bench.configs

    small = [Config("t2", 0, 561), Config("t2", 0, 561, relief="displace")]
    monkeypatch.setattr(studio.bench.configs, "configurations", lambda quick, poses: small)
    out = tmp_path / "bench"
    assert main(["bench", "--frames", "2", "--size", "64x48", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "skipped t2+displace, 561 vertices: relief 'displace' needs OpenGL 4.0" in printed
    with (out / "results.csv").open() as f:
        assert [(r["technique"], r["relief"]) for r in csv.DictReader(f)] == [("t2", "off")]


def test_results_of_finished_faces_survive_a_later_failure(tmp_path, capsys, monkeypatch):
    import studio.bench.configs
    import studio.bench.poses

    small = [Config("none", 0, 561), Config("none", 0, 1071)]
    monkeypatch.setattr(studio.bench.configs, "configurations", lambda quick, poses: small)

    def project(config: Config):
        if config.vertices == 1071:
            raise StudioError("the second face cannot be built")
        return bench_project(config)

    monkeypatch.setattr(studio.bench.poses, "bench_project", project)
    out = tmp_path / "bench"
    assert main(["bench", "--frames", "2", "--size", "64x48", "--out", str(out)]) == 2
    assert "the second face cannot be built" in capsys.readouterr().err
    with (out / "results.csv").open() as f:
        assert [r["vertices"] for r in csv.DictReader(f)] == ["561"]


def test_a_still_face_has_no_weights_to_blend():
    config = Config("none", 0, 561, still=True)
    timeline = bench_animation(bench_project(config), config)
    assert all(timeline.weights_at(f) == {} for f in range(timeline.end))
    assert config.label == "none, still, 561 vertices"
