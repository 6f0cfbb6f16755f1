"""View settings read back from a project file: a damaged or newer file cannot break the
viewport."""

from __future__ import annotations

import pytest

from studio.core.project.view_settings import ViewSettings

pytestmark = pytest.mark.core


def test_unknown_choices_and_wrong_types_fall_back_to_defaults():
    view = ViewSettings.from_dict({"relief": "bogus", "blend": "normal", "relief_depth": 1,
                                "wireframe": "yes", "technique": "t1",
                                "light_azimuth": float("nan"), "future_setting": 3})
    default = ViewSettings()
    assert (view.relief, view.wireframe, view.light_azimuth) == (
        default.relief, default.wireframe, default.light_azimuth)
    assert (view.blend, view.technique, view.relief_depth) == ("normal", "t1", 1.0)


def test_saved_settings_round_trip():
    view = ViewSettings(technique="strain", relief="parallax", relief_depth=0.02, split=True)
    assert ViewSettings.from_dict(view.to_dict()) == view
