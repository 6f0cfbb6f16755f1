"""What a player of the wrinkles computes from, in one format for both players: the exported web
page (core/formats/web_export.py) and the three.js module ``wrinkles.js`` shipped beside every
glTF export (core/formats/gltf/player.py puts the same data in the glTF). Both players run the
same JavaScript on it (``resources/web/activations.js``), so the two cannot drift apart.

* technique 1: each pose → area link as (pose, area, gain) with its response curve sampled on
  [0, 1] by the studio's own ``ResponseCurve.evaluate`` (linear in between: exact for linear
  links, which therefore need two samples only), the areas' own values, whether each is shown,
  and the wrinkled map each reveals;
* technique 2: the renderer's per-vertex slots (``WdvSetup.pack_slots``: up to four areas per
  vertex, the longest motions kept) and where wrinkles may show at all (not-face is 0), per
  render vertex.
"""

from __future__ import annotations

import numpy as np

from studio.core.project.model import Project
from studio.core.wrinkles.response import curve_of

#: points at which each pose → area link's curved response is sampled for the players
CURVE_SAMPLES = 257


def t1_links(project: Project) -> list[dict]:
    """Each pose → area link as (pose index, area index, gain, curve samples on [0, 1], its
    pose's onset: the weight goes through ``response.onset_weight`` before the curve, carried
    per link rather than baked into the samples, whose spacing would round its corner)."""
    influence = project.influence
    areas = [a.name for a in influence.areas]
    poses = [p.name for p in project.poses]
    links = []
    for pose, targets in influence.links.items():
        if pose not in poses:
            continue
        for area, gain in targets.items():
            if area not in areas:
                continue
            curve = curve_of(influence.curves, pose, area)
            xs = np.linspace(0.0, 1.0, 2 if curve.kind == "linear" else CURVE_SAMPLES)
            links.append({"pose": poses.index(pose), "area": areas.index(area),
                          "gain": float(gain),
                          "curve": [round(float(v), 6) for v in curve.evaluate(xs)],
                          "onset": float(project.furrows.of(pose).onset)})
    return links


def t1_arrays(project: Project) -> dict[str, np.ndarray]:
    """Per area: its own value (0 for hidden areas, which the studio never shows), whether it is
    shown, and the index of the wrinkled map it reveals."""
    influence, textures = project.influence, project.textures
    return {"t1.base": np.asarray(influence.activations({}), np.float32),
            "t1.shown": np.array([a.visible for a in influence.areas], np.float32),
            "t1.maps": np.array([textures.map_index(a.wrinkle_map) for a in influence.areas],
                                np.float32)}


def vertex_arrays(project: Project) -> dict[str, np.ndarray]:
    """Per render vertex: where wrinkles may show (``skin``) and technique 2's slots."""
    mesh = project.mesh
    slots = project.wdv.pack_slots(mesh.n_welded, project.textures.map_index)
    return {"skin": np.asarray(project.skin_weights(), np.float32)[mesh.weld],
            "wdv.dirs": slots.dirs.reshape(len(slots.dirs), -1)[mesh.weld].astype(np.float32),
            "wdv.cones": slots.cones[mesh.weld].astype(np.float32),
            "wdv.maps": slots.maps[mesh.weld].astype(np.float32)}
