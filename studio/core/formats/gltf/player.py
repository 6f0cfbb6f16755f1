"""``extras.wrinklePlayer``: what the three.js module ``wrinkles.js`` plays the wrinkles from,
in the web page's own format (core/formats/player_data.py) — the links with their sampled
curves, and arrays named as the page names them, each in a buffer view of the file (``type``,
``shape``, ``bufferView``, where the page's blob gives an ``offset``; an empty array is left
out). The glTF validator lists these views as unused objects (an information): no accessor
reads them, wrinkles.js does.

Why beside ``extras.wrinkleStudio`` rather than read from it: the studio's extras hold the
set-up as authored (curves by kind, technique-2 areas as per-area vertex attributes), and a
player would have to redo the studio's sampling and its packing of four areas per vertex; here
it reads what the studio's renderer reads. The studio's reader ignores this key.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from studio.core.formats.player_data import t1_arrays, t1_links, vertex_arrays
from studio.core.project.model import Project

PLAYER_KEY = "wrinklePlayer"


def player_extras(project: Project, view: Callable[[bytes], int], map_images: list[str],
                  mask_images: list[str]) -> dict:
    """The player's extras; ``view`` stores bytes in a buffer view of the file and returns its
    index. ``map_images`` and ``mask_images`` are the names the export gives the wrinkled maps'
    images (in map order) and the masks' (in area order)."""
    arrays = {}
    for name, array in {**vertex_arrays(project), **t1_arrays(project)}.items():
        data = np.ascontiguousarray(array, np.float32)
        if not data.size:
            continue  # a face without areas: glTF has no empty buffer views
        arrays[name] = {"type": "f4", "shape": list(data.shape),
                        "bufferView": view(data.tobytes())}
    return {"poses": [p.name for p in project.poses],
            "onsets": [float(v) for v in project.furrows.onsets(p.name for p in project.poses)],
            "areas": [a.name for a in project.influence.areas],
            "links": t1_links(project),
            "wrinkle_maps": map_images,
            "masks": mask_images,
            "wdv": {"expression_factor": float(project.wdv.expression_factor),
                    "scale_free": bool(project.wdv.scale_free)},
            "arrays": arrays}
