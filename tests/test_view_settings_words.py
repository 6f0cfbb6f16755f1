"""View settings as a user or a damaged file sets them: each refusal's exact words, the light's
direction by hand, and a saved view read back with its bad values replaced by defaults (a
newer or damaged project must still open, in the view it can show).
"""

from __future__ import annotations

import math

import pytest

from studio.core.project.view_settings import ViewSettings, saved_view

pytestmark = pytest.mark.core


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"debug_view": "xray"},
            "unknown debug view 'xray' (choose from shaded, heat, normals, uv, heat-shows)",
        ),
        ({"blend": "add"}, "unknown blend 'add' (choose from colour, normal)"),
        ({"relief": "bump"}, "unknown relief 'bump' (choose from off, displace, parallax)"),
        ({"relief_depth": -0.5}, "the relief depth must be 0 or more, got -0.5"),
        ({"relief_depth": math.inf}, "the relief depth must be 0 or more, got inf"),
        ({"light_azimuth": math.nan}, "the light azimuth must be a finite number"),
        ({"light_elevation": -math.inf}, "the light elevation must be a finite number"),
    ],
)
def test_a_bad_setting_is_refused_in_words(change: dict, message: str) -> None:
    with pytest.raises(ValueError) as caught:
        ViewSettings(**change)
    assert str(caught.value) == message


def test_a_relief_depth_of_zero_is_allowed() -> None:
    assert ViewSettings(relief_depth=0.0).relief_depth == 0.0


@pytest.mark.parametrize(
    ("azimuth", "elevation", "direction"),
    [
        (0.0, 0.0, (0.0, 0.0, 1.0)),  # from the viewer
        (90.0, 0.0, (1.0, 0.0, 0.0)),  # from the right
        (0.0, 90.0, (0.0, 1.0, 0.0)),  # from above
        (30.0, 60.0, (0.5 * 0.5, math.sqrt(3) / 2, math.sqrt(3) / 2 * 0.5)),
    ],
)
def test_the_light_direction_by_hand(azimuth: float, elevation: float, direction) -> None:
    found = ViewSettings(light_azimuth=azimuth, light_elevation=elevation).light_dir()
    assert found == pytest.approx(direction, abs=1e-12)


def test_a_saved_view_keeps_its_good_values_and_drops_its_bad_ones() -> None:
    view = saved_view(
        {
            "view": {
                "technique": "t1",
                "wireframe": True,
                "light_azimuth": 45,  # a whole number where a float is expected: fine
                "light_elevation": True,  # a bool is not a number here
                "relief_depth": -1.0,
                "blend": "add",
                "debug_view": 3,
                "relief": "parallax",
                "unknown": 1,
            }
        }
    )
    defaults = ViewSettings()
    assert (view.technique, view.wireframe, view.relief) == ("t1", True, "parallax")
    assert view.light_azimuth == 45.0 and isinstance(view.light_azimuth, float)
    assert view.light_elevation == defaults.light_elevation
    assert view.relief_depth == defaults.relief_depth
    assert (view.blend, view.debug_view) == (defaults.blend, defaults.debug_view)


def test_a_saved_relief_depth_of_zero_and_a_view_that_is_not_an_object() -> None:
    assert saved_view({"view": {"relief_depth": 0}}).relief_depth == 0.0
    assert saved_view({"view": {"light_azimuth": math.inf}}).light_azimuth == 30.0
    assert saved_view({"view": ["t1"]}) == ViewSettings()
    assert saved_view({}) == ViewSettings()
