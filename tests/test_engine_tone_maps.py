"""The engine layouts carry each wrinkle map's cavity and colour (issue 46, point 4):
MetaHuman-style animated colour maps (the albedo as the wrinkle shows it) and cavity maps,
Character-Creator-style AO and redness maps, beside the normal maps they go with, each texel
from the same project map as the normals; a face without them writes none."""

from __future__ import annotations

import json

import numpy as np
import pytest

from studio.core.engines.export import SHEET, export_layout
from studio.core.wrinkles.skin_tone import TINT_ONE
from tests.test_engine_layouts import arkit_face, pil_pixels

pytestmark = pytest.mark.core

FLUSHED = (128, 96, 92)  # a colour map's tint where a wrinkle flushes the skin
DEEP = 100  # a cavity map's value in a crease


def toned_face():
    """The ARKit sample with each wrinkled map flushed and creased in its own left column
    band (the tone of map m in columns [m·w/4, (m+1)·w/4)), unchanged elsewhere."""
    project = arkit_face()
    textures = project.textures
    for m, (name, normal) in enumerate(textures.wrinkle_maps.items()):
        h, w = normal.shape[:2]
        band = np.zeros((h, w), bool)
        band[:, m * w // 4:(m + 1) * w // 4] = True
        colour = np.full((h, w, 3), TINT_ONE, np.uint8)
        colour[band] = FLUSHED
        cavity = np.full((h, w), 255, np.uint8)
        cavity[band] = DEEP
        textures.set_tone(name, cavity, colour)
    return project


def slot_of(folder, name: str) -> dict:
    sheet = json.loads((folder / SHEET).read_text())
    return next(m for m in sheet["wrinkle_maps"] if m["name"] == name)


def test_metahuman_gets_an_animated_colour_and_a_cavity_map_per_wrinkle_map(tmp_path):
    project = toned_face()
    export_layout(project, tmp_path, "metahuman")
    slot = slot_of(tmp_path, "head_wm1_normal")
    source = slot["project_map"] or project.textures.wrinkle_map_names[0]
    colour = pil_pixels(tmp_path / "maps" / "head_wm1_color.png")[:, :, :3].astype(int)
    cavity = pil_pixels(tmp_path / "maps" / "head_wm1_cavity.png")
    diffuse = project.textures.diffuse.astype(int)
    assert colour.shape == diffuse.shape
    deep = cavity.reshape(cavity.shape[0], cavity.shape[1], -1)[..., 0] == DEEP
    assert deep.any() and (~deep).any()
    flushed = np.kron(deep, np.ones((colour.shape[0] // deep.shape[0],) * 2, bool))
    # where the slot's map flushes: redder than the albedo (green drops); elsewhere the albedo
    ratio = (colour[flushed][:, 1] + 1) / (diffuse[flushed][:, 1] + 1)
    assert (ratio < 0.93).mean() > 0.9
    assert np.abs(colour[~flushed] - diffuse[~flushed]).max() <= 1
    assert source in project.textures.colour_maps


def test_character_creator_gets_ao_and_redness_maps(tmp_path):
    export_layout(toned_face(), tmp_path, "cc")
    redness = pil_pixels(tmp_path / "maps" / "_WrinkleNormalBlend1_Redness.png")
    ao = pil_pixels(tmp_path / "maps" / "_WrinkleNormalBlend1_AO.png")
    redness = redness.reshape(redness.shape[0], redness.shape[1], -1)[..., 0]
    ao = ao.reshape(ao.shape[0], ao.shape[1], -1)[..., 0]
    assert set(np.unique(ao)) <= {DEEP, 255} and (ao == DEEP).any()
    assert (redness[ao == DEEP] > 150).all() and (redness[ao == 255] == 0).all()


@pytest.mark.parametrize("key", ["metahuman", "cc", "studio"])
def test_a_face_without_them_writes_none(key, tmp_path):
    export_layout(arkit_face(), tmp_path, key)
    names = [p.name for p in (tmp_path / "maps").iterdir()]
    assert not [n for n in names if any(w in n for w in ("color", "cavity", "AO", "Redness",
                                                          "colour_"))], names
