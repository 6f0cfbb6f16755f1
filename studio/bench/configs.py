"""Which configurations the benchmark times (thesis Tables 5.2–5.4, extended)."""

from __future__ import annotations

from dataclasses import dataclass

THESIS_VERTICES = tuple(range(561, 5152, 510))  # 561, 1071, …, 5151 (Tables 5.3/5.4)
THESIS_AREAS = (1, 2, 4, 8, 12, 16)  # Table 5.2, on the 2172-vertex model
EXTRA_AREAS = (32, 64, 128, 256)
EXTRA_VERTICES = (30000,)
POSES_VERTICES = 30000  # the face of the many-poses case (a production head's size)
AREA_MODEL = 2172
COMPARISON_AREAS = 8  # technique 1 in the vertex comparison
# wrinkles in depth: each relief with both authored techniques, on the area model
RELIEF_CONFIGS = tuple((t, r) for t in ("t2", "t1") for r in ("parallax", "displace"))
# every triangle through the wrinkle program, as if wrinkles could show anywhere on the face: the
# worst case of the split draw, and technique 1's per-pixel cost against the number of areas

# mean frame time (ms) the thesis reports, for the plots
THESIS_T1_BY_AREAS = {1: 17.4, 2: 17.9, 4: 19.8, 8: 22.9, 12: 26.3, 16: 29.9}
THESIS_BY_VERTICES = {561: (16.6, 16.1), 1071: (16.6, 16.8), 2091: (17.8, 18.8),
                      3111: (21.4, 22.9), 4131: (25.6, 32.3), 5151: (30.0, 40.0)}


@dataclass(frozen=True)
class Config:
    technique: str  # flat | none | t1 | t2 | strain
    areas: int  # technique-1 areas (0 for the others)
    vertices: int
    relief: str = "off"  # off | displace | parallax (RenderSettings.relief)
    draw: str = "split"  # split: plain shading where no wrinkle can show | whole: no split
    poses: int = 0  # 0: the sample's poses in turn | N: N ARKit poses all moving every frame

    @property
    def label(self) -> str:
        extra = f", {self.areas} areas" if self.technique == "t1" else ""
        relief = f"+{self.relief}" if self.relief != "off" else ""
        whole = " whole" if self.draw == "whole" else ""
        moving = f", {self.poses} poses moving" if self.poses else ""
        return f"{self.technique}{relief}{whole}{extra}{moving}, {self.vertices} vertices"


def configurations(quick: bool = False, poses: int = 0) -> list[Config]:
    """Every configuration, grouped by mesh so each mesh is built once; with ``poses``, also a
    capture take's case (that many poses, all changing every frame) on the large face, beside
    the plain shading of the same face."""
    if quick:
        by_areas, by_vertices = (1, 16, 64), (561, 2172)
    else:
        by_areas = THESIS_AREAS + EXTRA_AREAS
        by_vertices = tuple(sorted({*THESIS_VERTICES, AREA_MODEL, *EXTRA_VERTICES}))
    configs = []
    for v in by_vertices:
        configs += [Config("flat", 0, v), Config("none", 0, v), Config("t2", 0, v),
                    Config("t1", COMPARISON_AREAS, v), Config("strain", 0, v)]
        if v == AREA_MODEL:
            configs += [Config("t1", a, v) for a in by_areas if a != COMPARISON_AREAS]
            configs += [Config(t, COMPARISON_AREAS if t == "t1" else 0, v, relief)
                        for t, relief in RELIEF_CONFIGS]
            configs += [Config("t2", 0, v, draw="whole")]
            configs += [Config("t1", a, v, draw="whole") for a in by_areas]
    if poses:
        if POSES_VERTICES not in by_vertices:
            configs.append(Config("none", 0, POSES_VERTICES))
        configs.append(Config("none", 0, POSES_VERTICES, poses=poses))
    return configs
