"""Which configurations the benchmark times (thesis Tables 5.2–5.4, extended)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from studio.core.mesh.tangent_frames import DEFAULT_TANGENT_FRAME

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
    frame: str = DEFAULT_TANGENT_FRAME  # the tangent frame recomputed as the face moves
    still: bool = False  # the neutral face held: no deformation at all (the floor of a frame)
    look: str = "clay"  # clay | skin (RenderSettings.look, under the studio light rig)

    @property
    def label(self) -> str:
        extra = f", {self.areas} areas" if self.technique == "t1" else ""
        relief = f"+{self.relief}" if self.relief != "off" else ""
        whole = " whole" if self.draw == "whole" else ""
        moving = f", {self.poses} poses moving" if self.poses else ", still" if self.still else ""
        frame = f", {self.frame} frame" if self.frame != DEFAULT_TANGENT_FRAME else ""
        look = f", {self.look}" if self.look != "clay" else ""
        return (f"{self.technique}{relief}{whole}{extra}{moving}{frame}{look}, "
                f"{self.vertices} vertices")


def reproduces_thesis(config: Config) -> bool:
    """Whether ``config`` is one of the thesis's own measurements (Tables 5.2–5.4): those are
    timed in the thesis's tangent frame too, beside the studio's default."""
    if (config.relief != "off" or config.draw != "split" or config.poses or config.still
            or config.look != "clay"):
        return False
    if config.technique == "t1" and config.vertices == AREA_MODEL:
        return config.areas in THESIS_AREAS
    return (config.technique in ("t1", "t2") and config.vertices in THESIS_VERTICES
            and (config.technique == "t2" or config.areas == COMPARISON_AREAS))


def configurations(quick: bool = False, poses: int = 0) -> list[Config]:
    """Every configuration in the studio's default tangent frame, those of the thesis also in
    its own frame, grouped by mesh so each mesh is built once; with ``poses``, also a capture
    take's case (that many poses, all changing every frame) on the large face, shaded plainly
    and by the strain mode, beside the same face held still."""
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
            # the skin look's cost: each technique against none, all in the skin look (issue
            # 46: within 1.1×), and the skin look against clay's same configurations
            configs += [Config(t, COMPARISON_AREAS if t == "t1" else 0, v, look="skin")
                        for t in ("none", "t1", "t2")]
            configs += [Config("t1", a, v, draw="whole") for a in by_areas]
    configs = [c for config in configs
               for c in (config, replace(config, frame="thesis"))[:1 + reproduces_thesis(config)]]
    if poses:
        configs += [Config("none", 0, POSES_VERTICES, still=True),
                    Config("none", 0, POSES_VERTICES, poses=poses),
                    Config("strain", 0, POSES_VERTICES, poses=poses)]
    return configs
