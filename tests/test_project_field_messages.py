"""Every damaged field of a project file is named where it is, in the words a user reads.

A project edited by hand or by a script gets one field wrong: the message must point at that
field by its full path in project.json (``wdv.areas[0].cone_angle_deg``), or at the archive
member and what it holds, so the user can find and fix it. One small project (an influence
area, a link, a WDV area) is damaged one field at a time.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.files.errors import ProjectError
from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.wdv import WdvArea
from tests.bad_inputs import rewrite_project
from tests.test_auto_setup import grid_mesh, grid_project, squeezed

pytestmark = pytest.mark.core

DELETE = object()


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    mesh = grid_mesh()
    project = grid_project(squeeze=squeezed(mesh.rest))
    project.influence.areas.append(InfluenceArea("brow", np.full((16, 16), 0.5, np.float32)))
    project.influence.links = {"squeeze": {"brow": 1.0}}
    n = len(mesh.rest)
    directions = np.tile(np.float32([1, 0, 0]), (n, 1))
    project.wdv.areas.append(WdvArea("frown", "squeeze", directions, np.full(n, 0.1, np.float32)))
    path = tmp_path_factory.mktemp("saved") / "face.wrinkle"
    save_project(project, path)
    return path


def setting(*path: object, to: object) -> Callable[[dict], None]:
    def change(doc: dict) -> None:
        for key in path[:-1]:
            doc = doc[key]
        if to is DELETE:
            del doc[path[-1]]
        else:
            doc[path[-1]] = to

    return change


def png(pixels: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    Image.fromarray(pixels).save(buffer, "PNG")
    return buffer.getvalue()


def npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


AREA = ("influence", "areas", 0)
WDV = ("wdv", "areas", 0)
FIELDS = {
    "area-not-object": (setting(*AREA, to=5), "influence.areas[0] must be a JSON object"),
    "area-name": (setting(*AREA, "name", to=DELETE), None),
    "area-mask": (setting(*AREA, "mask", to=3), "influence.areas[0].mask must be text"),
    "area-colour": (
        setting(*AREA, "colour", to="red"),
        "influence.areas[0].colour must be three whole numbers from 0 to 255",
    ),
    "area-activation": (
        setting(*AREA, "activation", to="x"),
        "influence.areas[0].activation must be a number",
    ),
    "area-visible": (
        setting(*AREA, "visible", to=1),
        "influence.areas[0].visible must be true or false",
    ),
    "area-map": (
        setting(*AREA, "wrinkle_map", to=2),
        "influence.areas[0].wrinkle_map must be text",
    ),
    "areas": (setting("influence", "areas", to={}), "influence.areas must be a JSON list"),
    "links": (setting("influence", "links", to=[]), "influence.links must be a JSON object"),
    "links-pose": (
        setting("influence", "links", "squeeze", to=1),
        "influence.links.squeeze must be a JSON object",
    ),
    "links-gain": (
        setting("influence", "links", "squeeze", "brow", to="a"),
        "influence.links.squeeze.brow must be a number",
    ),
    "wdv-not-object": (setting(*WDV, to=[]), "wdv.areas[0] must be a JSON object"),
    "wdv-name": (setting(*WDV, "name", to=7), "wdv.areas[0].name must be a non-empty name"),
    "wdv-directions": (setting(*WDV, "directions", to=1), "wdv.areas[0].directions must be text"),
    "wdv-colour": (
        setting(*WDV, "colour", to=[1, 2]),
        "wdv.areas[0].colour must be three whole numbers from 0 to 255",
    ),
    "wdv-cone": (
        setting(*WDV, "cone_angle_deg", to="20"),
        "wdv.areas[0].cone_angle_deg must be a number",
    ),
    "wdv-enabled": (
        setting(*WDV, "enabled", to="yes"),
        "wdv.areas[0].enabled must be true or false",
    ),
    "wdv-map": (setting(*WDV, "wrinkle_map", to=1), "wdv.areas[0].wrinkle_map must be text"),
    "wdv-areas": (setting("wdv", "areas", to=1), "wdv.areas must be a JSON list"),
    "wdv-factor": (
        setting("wdv", "expression_factor", to="1"),
        "wdv.expression_factor must be a number",
    ),
    "maps": (setting("wrinkle_maps", to={}), "wrinkle_maps must be a JSON list"),
    "maps-entry": (setting("wrinkle_maps", to=[5]), "wrinkle_maps[0] must be a non-empty name"),
    "maps-none": (
        setting("wrinkle_maps", to=[]),
        "wrinkle_maps must name 1 to 4 different wrinkled maps",
    ),
    "maps-twice": (
        setting("wrinkle_maps", to=["a", "a"]),
        "wrinkle_maps must name 1 to 4 different wrinkled maps",
    ),
}
MISSING = {
    "area-name": "project.json lacks influence.areas[0].name",
    "wdv-pose": "project.json lacks wdv.areas[0].pose",
    "wdv-lengths": "project.json lacks wdv.areas[0].lengths",
}


@pytest.mark.parametrize("case", sorted(FIELDS))
def test_a_wrong_field_is_named_by_its_path(saved: Path, tmp_path: Path, case: str) -> None:
    change, problem = FIELDS[case]
    damaged = tmp_path / "damaged.wrinkle"
    rewrite_project(saved, damaged, change)
    with pytest.raises(ProjectError) as caught:
        load_project(damaged)
    assert caught.value.path == damaged
    assert caught.value.problem == (
        MISSING[case] if problem is None else f"project.json: {problem}"
    )


@pytest.mark.parametrize("case", ["wdv-pose", "wdv-lengths"])
def test_a_missing_field_is_named_by_its_path(saved: Path, tmp_path: Path, case: str) -> None:
    key = case.removeprefix("wdv-")
    damaged = tmp_path / "damaged.wrinkle"
    rewrite_project(saved, damaged, setting(*WDV, key, to=DELETE))
    with pytest.raises(ProjectError) as caught:
        load_project(damaged)
    assert caught.value.problem == MISSING[case]


@pytest.mark.parametrize(
    ("member", "data", "problem"),
    [
        (
            "masks/00_brow.png",
            png(np.zeros((16, 16, 3), np.uint8)),
            "'masks/00_brow.png' (the mask of influence area 'brow') must be a greyscale image, "
            "it has 3 channels",
        ),
        (
            "textures/diffuse.png",
            png(np.zeros((8, 8), np.uint8)),
            "'textures/diffuse.png' (the diffuse texture) must be an RGB image, it has 1 channel",
        ),
        (
            "wdv/00_lengths.npy",
            npy(np.zeros(3, np.float32)),
            "'wdv/00_lengths.npy' (the lengths of WDV area 'frown') has shape (3,), "
            "expected (441,)",
        ),
    ],
)
def test_a_wrong_member_is_named_with_what_it_holds(saved, tmp_path, member, data, problem):
    damaged = tmp_path / "damaged.wrinkle"
    rewrite_project(saved, damaged, members={member: data})
    with pytest.raises(ProjectError) as caught:
        load_project(damaged)
    assert caught.value.problem == problem
