"""The Areas panel's model without Qt: which poses drive the selected area, what Add pose…
offers, Solo, Up/Down, the selection kept after a change, the flat-map warning and the brush
kept between sessions (studio/widgets/paint/areas_model.py)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from studio.core.wrinkles.influence import InfluenceArea
from studio.widgets.layer_list_model import can_move, kept_selection, solo
from studio.widgets.paint.areas_model import (
    addable_poses,
    brush_setting,
    flat_tooltip,
    linked_poses,
    links_shown,
    map_chosen_text,
    scaled_radius,
)

pytestmark = pytest.mark.core


def _project(links: dict[str, dict[str, float]]) -> SimpleNamespace:
    """What the model reads of a project: its poses (neutral first, the rig's own names), the
    pose → area gains and the wrinkled maps."""
    return SimpleNamespace(
        pose_names=["Basis", "browDown_L", "Frown-R", "mouthSmile_L"],
        influence=SimpleNamespace(links=links),
        textures=SimpleNamespace(wrinkle_map_names=["forehead", "frown lines"]))


def _area(name: str) -> InfluenceArea:
    return InfluenceArea(name, np.zeros((8, 8), np.float32))


def test_only_poses_with_a_gain_drive_an_area_in_the_rigs_order():
    project = _project({"mouthSmile_L": {"glabella": 0.5}, "browDown_L": {"glabella": 1.0},
                        "Frown-R": {"glabella": 0.0, "crows": 1.0}})
    linked = linked_poses(project, _area("glabella"))
    assert linked == ["browDown_L", "mouthSmile_L"]
    assert linked_poses(project, None) == []
    assert addable_poses(project, linked) == ["Frown-R"]  # never the neutral


def test_the_links_form_is_kept_while_it_shows_the_same_thing():
    project = _project({"browDown_L": {"glabella": 1.0}})
    area = _area("glabella")
    shown = links_shown(project, 0, area)
    assert links_shown(project, 0, area) == shown
    project.influence.links["Frown-R"] = {"glabella": 0.3}  # another pose linked
    assert links_shown(project, 0, area) != shown
    assert links_shown(project, 1, area) != links_shown(project, 0, area)  # another row
    project.textures.wrinkle_map_names.append("smile")  # a map added
    assert links_shown(project, 0, area)[-1] == ("forehead", "frown lines", "smile")
    assert links_shown(project, 0, None) is None


def test_solo_shows_one_area_and_pressed_again_shows_all():
    visible, text = solo((True, True, False), 1, "glabella")
    assert visible == (False, True, False) and text == "Solo glabella"
    visible, text = solo(visible, 1, "glabella")
    assert visible == (True, True, True) and text == "Show all areas"


def test_up_and_down_stay_inside_the_list():
    assert can_move(0, 1, 3) and can_move(2, -1, 3)
    assert not can_move(0, -1, 3) and not can_move(2, 1, 3) and not can_move(-1, 1, 3)


def test_a_rebuilt_list_keeps_the_row_or_the_last_one():
    assert kept_selection(1, 3) == 1
    assert kept_selection(5, 3) == 2  # the selected area was deleted: the last one
    assert kept_selection(-1, 3) == 0
    assert kept_selection(0, 0) == -1


def test_the_flat_warning_and_the_map_a_link_chose_are_said_in_words():
    assert flat_tooltip("glabella", "") == ""
    assert flat_tooltip("glabella", "reveals a flat map").startswith(
        "glabella reveals a flat map: its heat of the weight is hot")
    assert map_chosen_text("glabella", None, "browDown_L") == ""
    assert map_chosen_text("glabella", "frown lines", "browDown_L") == (
        "“glabella” reveals “frown lines”, the map of browDown_L (choose another under "
        "Wrinkled map).")


@pytest.mark.parametrize(("key", "stored", "expected"), [
    ("radius", "24.5", 24.5), ("radius", 0.2, 1.0), ("radius", 5000, 1000.0),
    ("hardness", 1.7, 1.0), ("opacity", "-2", 0.0), ("flow", "soft", 0.25),
    ("flow", None, 0.25), ("flow", "nan", 0.25)])
def test_a_remembered_brush_value_is_kept_in_range_or_dropped(key, stored, expected):
    assert brush_setting(key, stored, 0.25) == pytest.approx(expected)


def test_brackets_scale_the_radius_within_range():
    assert scaled_radius(20.0, 1.25) == pytest.approx(25.0)
    assert scaled_radius(1.0, 0.5) == 1.0 and scaled_radius(900.0, 2.0) == 1000.0
