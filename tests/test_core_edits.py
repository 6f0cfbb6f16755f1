"""Small core edits and look-ups: renaming and removing wrinkled normal maps, changing view
settings, a link's response curve, the relief maps' fingerprint and the UV layout's coverage."""

from __future__ import annotations

import re

import numpy as np
import pytest

from studio.core.files.errors import ImageError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.project.view_settings import ViewSettings
from studio.core.wrinkles.mask_ops import uv_coverage
from studio.core.wrinkles.relief import maps_digest
from studio.core.wrinkles.response import LINEAR, ResponseCurve, curve_of
from studio.core.wrinkles.textures import FaceTextures

pytestmark = pytest.mark.core


def _image(value: int) -> np.ndarray:
    return np.full((2, 2, 3), value, np.uint8)


def _textures(*names: str) -> FaceTextures:
    """Textures with one wrinkled map per name, map i filled with the value i + 1."""
    return FaceTextures(_image(0), _image(128),
                        wrinkle_maps={n: _image(i + 1) for i, n in enumerate(names)})


def _fills(textures: FaceTextures) -> dict[str, int]:
    return {name: int(image[0, 0, 0]) for name, image in textures.wrinkle_maps.items()}


# --------------------------------------------------------------------------- wrinkled maps

def test_renaming_a_map_keeps_its_image_and_its_place() -> None:
    """A renamed map keeps its image and its position (its shader index) among the maps."""
    textures = _textures("forehead", "smile", "frown")
    textures.rename_wrinkle_map("smile", "  cheeks ")  # spaces around the name are dropped
    assert _fills(textures) == {"forehead": 1, "cheeks": 2, "frown": 3}
    assert textures.wrinkle_map_names == ["forehead", "cheeks", "frown"]


def test_renaming_a_map_to_its_own_name_changes_nothing() -> None:
    """Confirming the current name is allowed and leaves the maps as they were."""
    textures = _textures("forehead", "smile")
    textures.rename_wrinkle_map("smile", "smile")
    assert _fills(textures) == {"forehead": 1, "smile": 2}


@pytest.mark.parametrize("new", ["", "   ", "forehead"])
def test_a_map_cannot_be_renamed_to_nothing_or_to_another_maps_name(new: str) -> None:
    """An empty name or one another map has is refused, and the maps stay as they were."""
    textures = _textures("forehead", "smile")
    message = f"a wrinkled normal map needs a new, unused name (got '{new.strip()}')"
    with pytest.raises(ImageError, match=f"^{re.escape(message)}$"):
        textures.rename_wrinkle_map("smile", new)
    assert _fills(textures) == {"forehead": 1, "smile": 2}


def test_removing_a_map_returns_its_image_and_keeps_the_others() -> None:
    """The removed map's image comes back (for undo); the rest keep their order."""
    textures = _textures("forehead", "smile", "frown")
    removed = textures.remove_wrinkle_map("smile")
    assert int(removed[0, 0, 0]) == 2
    assert _fills(textures) == {"forehead": 1, "frown": 3}
    textures.remove_wrinkle_map("forehead")
    assert _fills(textures) == {"frown": 3}


def test_the_last_map_cannot_be_removed() -> None:
    """A face keeps at least one wrinkled map: removing the only one is refused."""
    textures = _textures("forehead")
    with pytest.raises(ImageError, match=r"^the last wrinkled normal map cannot be removed$"):
        textures.remove_wrinkle_map("forehead")
    assert _fills(textures) == {"forehead": 1}


# --------------------------------------------------------------------------- view settings

def test_view_settings_name_their_fields_in_order() -> None:
    """The field names, in declaration order, are what clients and files go by."""
    assert ViewSettings.field_names() == (
        "technique", "split", "debug_view", "wireframe", "blend", "relief", "relief_depth",
        "light_azimuth", "light_elevation", "tangent_frame", "look", "light_rig")
    assert ViewSettings().field_names() == ViewSettings.field_names()


def test_with_changes_gives_a_copy_with_those_fields_changed() -> None:
    """Only the named fields change, in a new object; the original is untouched."""
    view = ViewSettings()
    changed = view.with_changes(wireframe=True, light_azimuth=-45.0)
    assert changed.wireframe is True and changed.light_azimuth == -45.0
    assert changed == ViewSettings(wireframe=True, light_azimuth=-45.0)
    assert view == ViewSettings()
    assert view.with_changes() == view


def test_with_changes_refuses_an_unknown_field_by_name() -> None:
    """A field that does not exist raises AttributeError naming it."""
    with pytest.raises(AttributeError, match=r"^brightness$"):
        ViewSettings().with_changes(wireframe=True, brightness=2.0)


# --------------------------------------------------------------------------- curve_of

STEP = ResponseCurve("smooth_step", 0.2, 0.6)
TABLE = {"smile": {"cheek": STEP, "mouth": ResponseCurve("ease_in")}, "frown": {}}


@pytest.mark.parametrize(("pose", "area", "expected"), [
    ("smile", "cheek", STEP),
    ("smile", "mouth", ResponseCurve("ease_in")),
    ("smile", "brow", LINEAR),  # the pose has curves, not for this area
    ("frown", "cheek", LINEAR),  # the pose has none
    ("blink", "cheek", LINEAR),  # the pose is not in the table
])
def test_a_links_curve_is_linear_unless_one_is_set(pose: str, area: str,
                                                   expected: ResponseCurve) -> None:
    """The link's own curve where set; linear otherwise."""
    assert curve_of(TABLE, pose, area) == expected


# --------------------------------------------------------------------------- maps_digest

def test_the_maps_digest_is_sixteen_bytes_and_repeatable() -> None:
    """The same maps give the same 16-byte fingerprint, also from non-contiguous views."""
    neutral, wrinkled = _image(128), np.arange(12, dtype=np.uint8).reshape(2, 2, 3)
    digest = maps_digest(neutral, [wrinkled])
    assert isinstance(digest, bytes) and len(digest) == 16
    assert maps_digest(neutral.copy(), [wrinkled.copy()]) == digest
    wide = np.zeros((2, 4, 3), np.uint8)
    wide[:, ::2] = wrinkled
    assert maps_digest(neutral, [wide[:, ::2]]) == digest


def test_the_maps_digest_changes_with_any_map() -> None:
    """A texel changed in any map, or a map added, gives another fingerprint."""
    neutral, wrinkled = _image(128), _image(7)
    digest = maps_digest(neutral, [wrinkled])
    touched = wrinkled.copy()
    touched[1, 1, 2] = 8
    assert maps_digest(neutral, [touched]) != digest
    assert maps_digest(_image(127), [wrinkled]) != digest
    assert maps_digest(neutral, [wrinkled, wrinkled]) != digest


def test_the_maps_digest_tells_apart_the_same_bytes_in_another_shape_or_type() -> None:
    """Equal bytes read as another shape or another sample type are other maps."""
    data = np.arange(24, dtype=np.uint8)
    as_2x4 = data.reshape(2, 4, 3)
    digest = maps_digest(_image(1), [as_2x4])
    assert maps_digest(_image(1), [data.reshape(4, 2, 3)]) != digest
    assert maps_digest(_image(1), [data.view(np.uint16).reshape(2, 2, 3)]) != digest


# --------------------------------------------------------------------------- uv_coverage

def test_uv_coverage_is_where_the_layout_has_triangles() -> None:
    """A triangle in UV covers exactly the texels whose centres it contains (row 0 = v 1)."""
    rest = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0]])
    uvs = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]])
    mesh = FaceMesh(rest, np.array([[0, 1, 2]]), uvs, np.arange(3))
    coverage = uv_coverage(mesh, 4)
    assert coverage.dtype == bool
    assert coverage.astype(int).tolist() == [[0, 0, 0, 0],
                                             [0, 1, 1, 0],
                                             [0, 1, 1, 0],
                                             [1, 1, 1, 1]]


@pytest.mark.parametrize("kind", ["linear", "ease_in", "ease_out", "ease_in_out", "smooth_step"])
def test_curve_responses_are_float64_whatever_the_weights_type(kind: str) -> None:
    """Weights given as float32 still give float64 responses, at full precision."""
    curve = ResponseCurve(kind)
    weights = np.array([0.1, 0.7], np.float32)
    response = curve.evaluate(weights)
    assert response.dtype == np.float64
    np.testing.assert_array_equal(response, curve.evaluate(weights.astype(np.float64)))


def test_a_custom_curve_made_custom_is_itself() -> None:
    """A custom curve keeps all its points when made custom (no resampling to five)."""
    custom = ResponseCurve("custom", points=((0.0, 0.2), (0.3, 0.9), (1.0, 0.4)))
    assert custom.as_custom() is custom
    assert custom.as_custom(samples=9) is custom


@pytest.mark.parametrize(("doc", "message"), [
    ({"kind": "linear", "zeta": 1, "alpha": 2}, "alpha is not a field of a curve"),
    ({"kind": 3}, "kind must be text"),
    ({"kind": "custom", "points": "ab"}, "points must be a list of at most 32 points"),
    ({"kind": "custom", "points": [[i / 40, 0.5] for i in range(33)]},
     "points must be a list of at most 32 points"),
    ({"kind": "custom", "points": [[0.0, 0.0], [1.0, 1.0, 1.0]]},
     "points[1] must be a pair [x, y]"),
    ({"kind": "custom", "points": [[0.0, 0.0], "xy"]}, "points[1] must be a pair [x, y]"),
])
def test_a_damaged_curve_in_a_file_is_refused_saying_what_is_wrong(doc, message: str) -> None:
    """Each kind of damage gets its own message, naming the field (first unknown one by name)."""
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        ResponseCurve.from_dict(doc)


def test_a_curve_of_the_most_points_allowed_is_read() -> None:
    """A custom curve of exactly MAX_POINTS points reads back as written."""
    points = [[i / 31, (i % 2) * 0.5] for i in range(32)]
    curve = ResponseCurve.from_dict({"kind": "custom", "points": points})
    assert [list(p) for p in curve.points] == points
