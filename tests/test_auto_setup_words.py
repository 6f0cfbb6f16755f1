"""What the automatic setup tells the user, word for word, and the small rules behind it.

The summary goes to the status bar, a message box and the command line; the per-pose lines
are what a user reads first on a face made elsewhere ("why did blink get no mask?"); strain
areas are named after their poses, strongest first. These are quick checks on hand-made
reports and the flat test face, so each wording and rule is held on its own.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from studio.core.files.errors import StudioError
from studio.core.setup import auto_setup as auto
from studio.core.wrinkles.skin_strain import PoseStrain
from tests.test_auto_setup import grid_mesh, grid_project, squeezed

pytestmark = pytest.mark.core


def strain(
    compressed: float, peak: float = 0.0, stretch: float = 0.0, moved: float = 0.1
) -> PoseStrain:
    return PoseStrain(peak, stretch, compressed, None, moved)


def test_nothing_to_start_from() -> None:
    assert auto.AutoSetupReport().summary() == "No key poses to start from."


def test_the_summary_counts_what_was_added_and_names_the_poses_that_gave_nothing() -> None:
    report = auto.AutoSetupReport(
        influence_areas=["m"],
        wdv_areas=["a", "b"],
        still_poses=["blink", "sneer"],
        flat_poses=["jawOpen"],
    )
    assert report.summary() == (
        "Added 2 wrinkle-vector area(s) and 1 mask(s); no vectors for blink, sneer (moves no "
        "skin); no mask for jawOpen (compresses no skin)."
    )


@pytest.mark.parametrize(
    ("still", "flat", "expected"),
    [
        (
            ["blink"],
            [],
            "Added 0 wrinkle-vector area(s) and 0 mask(s); no vectors for blink (moves no skin).",
        ),
        (
            [],
            ["smile"],
            "Added 0 wrinkle-vector area(s) and 0 mask(s); no mask for smile (compresses no skin).",
        ),
    ],
)
def test_a_setup_that_added_nothing_still_says_why(still, flat, expected) -> None:
    report = auto.AutoSetupReport(still_poses=still, flat_poses=flat)
    assert report.empty and report.summary() == expected


def test_only_areas_added_is_one_sentence() -> None:
    report = auto.AutoSetupReport(influence_areas=["m"])
    assert report.summary() == "Added 0 wrinkle-vector area(s) and 1 mask(s)."


def test_a_line_per_pose_says_how_much_where_and_why_not() -> None:
    report = auto.AutoSetupReport(
        strains={
            "browDown": strain(0.1234, peak=0.256),
            "cheekPuff": strain(0.05, peak=0.31),
            "jawLeft": strain(0.0, peak=0.004, moved=0.2),
            "still": strain(0.0, moved=0.0),
        },
        regions={"browDown": "between the brows"},
    )
    assert report.pose_lines() == [
        "browDown: compresses 12.3 % of the skin (between the brows), peak 26 %",
        "cheekPuff: compresses 5.0 % of the skin, peak 31 %",
        "jawLeft: no mask, it moves the skin without deforming it (a rotation or translation;"
        " compression at most 0.4 %)",
        "still: no mask, it moves no skin",
    ]


def test_new_areas_get_distinct_colours() -> None:
    colours = [auto.area_colour(i) for i in range(8)]
    assert len(set(colours)) == 8
    assert all(0 <= c <= 255 for colour in colours for c in colour)


def fake_project(rest: np.ndarray, skin: np.ndarray) -> SimpleNamespace:
    return SimpleNamespace(mesh=SimpleNamespace(rest=rest), skin_weights=lambda: skin)


def test_the_face_size_is_the_skins_diagonal() -> None:
    rest = np.array([[0, 0, 0], [3, 4, 0], [100, 100, 100]], np.float32)
    assert auto.face_size(fake_project(rest, np.array([1.0, 0.5, 0.0]))) == 5.0
    # no skin marked: the whole mesh; a single point: 1, so nothing divides by zero
    assert auto.face_size(fake_project(rest, np.zeros(3))) == pytest.approx(np.sqrt(3) * 100)
    assert auto.face_size(fake_project(rest[:1], np.ones(1))) == 1.0


@pytest.fixture(scope="module")
def face():
    mesh = grid_mesh()
    return grid_project(
        squeeze=squeezed(mesh.rest),
        shift=mesh.rest + np.float32([0.3, -0.2, 0.1]),
        frown=squeezed(mesh.rest, 0.95),
        blink=squeezed(mesh.rest, 0.97),
    )


def test_active_poses_are_the_known_positive_ones_strongest_first(face) -> None:
    weights = {"shift": 0.2, "nope": 0.9, "squeeze": 0.7, "frown": 0.0, "blink": -0.5}
    active = auto.active_poses(face, weights)
    assert list(active.items()) == [("squeeze", 0.7), ("shift", 0.2)]


@pytest.mark.parametrize(
    ("weights", "name"),
    [
        ({"squeeze": 1.0}, "squeeze strain"),
        ({"shift": 0.1, "squeeze": 0.5, "frown": 0.3}, "squeeze + frown + shift strain"),
        (
            {"shift": 0.1, "squeeze": 0.5, "frown": 0.3, "blink": 0.2},
            "squeeze + frown + blink … strain",
        ),
    ],
)
def test_strain_areas_are_named_after_their_strongest_poses(face, weights, name) -> None:
    assert auto.strain_area_name(face, weights) == name


def test_the_neutral_pose_is_refused_in_words(face) -> None:
    message = (
        "the face is in its neutral pose, where the automatic mode shows no wrinkles: "
        "move a pose slider first"
    )
    for call in (auto.strain_mask, auto.strain_wdv_area):
        with pytest.raises(StudioError) as caught:
            call(face, {"squeeze": 0.0})
        assert str(caught.value) == message


def test_a_pose_that_compresses_nothing_is_refused_in_words(face) -> None:
    with pytest.raises(StudioError) as caught:
        auto.strain_mask(face, {"shift": 1.0}, mask_size=16)
    assert str(caught.value) == (
        "the automatic mode shows no wrinkles at these pose weights (no skin is compressed)"
    )
    with pytest.raises(StudioError) as caught:
        auto.strain_wdv_area(face, {"shift": 1.0})
    assert str(caught.value) == (
        "no vertex has an automatic wrinkle weight above 0.25 at these pose weights"
    )


def test_a_strain_area_takes_the_next_colour_of_the_run(face) -> None:
    area, links = auto.strain_mask(face, {"squeeze": 0.25, "frown": 0.25}, mask_size=16)
    assert area.colour == auto.area_colour(len(face.influence.areas))
    assert links == {"squeeze": {area.name: 2.0}, "frown": {area.name: 2.0}}
    vectors = auto.strain_wdv_area(face, {"squeeze": 1.0})
    assert vectors.colour == auto.area_colour(len(face.wdv.areas))
