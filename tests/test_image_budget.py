"""The decoded-image budget of one project load, byte by byte.

A project file can point many areas at one huge mask; the loader charges every image's decoded
size (channels × bytes per sample × pixels, read from the PNG header before decoding) and each
area's float32 copy to one total, and refuses past the limit with a message naming the file and
the setting that raises it. The sums below are worked out by hand from the images' sizes.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.files.errors import ProjectError
from studio.core.project.mask_store import ImageBudget

pytestmark = pytest.mark.core

PROJECT = Path("face.wrinkle")


def png(mode: str, size: tuple[int, int]) -> bytes:
    buffer = io.BytesIO()
    image = Image.new(mode, size)
    if mode == "P":
        image.putpalette([0, 0, 0] * 256)
    image.save(buffer, "PNG")
    return buffer.getvalue()


@pytest.mark.parametrize(
    ("mode", "grey", "charged"),
    [
        ("L", True, 10 * 20 * (1 + 4)),  # 8-bit grey, plus the area's float32 copy
        ("L", False, 10 * 20),
        ("RGB", False, 10 * 20 * 3),
        ("RGBA", False, 10 * 20 * 4),
        ("LA", False, 10 * 20 * 2),
        ("P", False, 10 * 20 * 4),  # a palette decodes to RGBA
        ("I;16", True, 10 * 20 * (2 + 4)),  # 16-bit grey: two bytes a sample
    ],
)
def test_an_image_is_charged_its_decoded_size(mode: str, grey: bool, charged: int) -> None:
    budget = ImageBudget(PROJECT)
    budget.claim("masks/a.png", png(mode, (10, 20)), "a mask", grey)
    assert budget.total == charged
    budget.claim("textures/b.png", png("RGB", (2, 3)), "the diffuse texture", False)
    assert budget.total == charged + 18  # charges add up


def test_past_the_total_the_load_is_refused_naming_the_setting(monkeypatch) -> None:
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES", "1500")
    budget = ImageBudget(PROJECT)
    budget.claim("masks/a.png", png("L", (10, 20)), "a mask", True)  # 1 000
    with pytest.raises(ProjectError) as caught:
        budget.claim("textures/d.png", png("RGB", (10, 20)), "the diffuse texture", False)
    assert caught.value.path == PROJECT
    assert caught.value.problem == (
        "the decoded images, with the diffuse texture, is 1,600 bytes, more than the limit of "
        "1,500 bytes (set WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES to change it)"
    )


def test_an_image_over_the_pixel_limit_is_refused_before_anything_is_charged(monkeypatch):
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_IMAGE_PIXELS", "150")
    budget = ImageBudget(PROJECT)
    with pytest.raises(ProjectError) as caught:
        budget.claim("masks/a.png", png("L", (10, 20)), "a mask", True)
    assert caught.value.path == PROJECT
    assert caught.value.problem == (
        "'masks/a.png' (a mask) is 200 pixels, more than the limit of 150 pixels "
        "(set WRINKLE_STUDIO_MAX_IMAGE_PIXELS to change it)"
    )
    assert budget.total == 0


def test_a_shared_mask_is_decoded_once_and_each_area_pays_its_copy() -> None:
    budget = ImageBudget(PROJECT)
    mask = np.zeros((3, 4), np.uint8)
    budget.keep("masks/m.png", mask)
    assert budget.shared("masks/m.png", "area 2", True) is mask
    assert budget.total == 12 * 4
    assert budget.shared("masks/m.png", "a texture", False) is None  # grey is not colour
    assert budget.shared("masks/other.png", "area 3", True) is None
    assert budget.shared(7, "area 4", True) is None  # a name that is not text
    assert budget.total == 12 * 4
    colour = np.zeros((2, 2, 3), np.uint8)
    budget.keep("textures/c.png", colour)
    assert budget.shared("textures/c.png", "the diffuse", False) is colour
    assert budget.total == 12 * 4  # a colour image has no float copy to pay


def test_sharing_a_mask_with_too_many_areas_is_refused(monkeypatch) -> None:
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES", "100")
    budget = ImageBudget(PROJECT)
    budget.keep("masks/m.png", np.zeros((3, 4), np.uint8))
    budget.shared("masks/m.png", "area 1", True)
    budget.shared("masks/m.png", "area 2", True)  # 96 bytes: still within
    with pytest.raises(ProjectError) as caught:
        budget.shared("masks/m.png", "area 3", True)
    assert caught.value.problem.startswith("the decoded images, with area 3, is 144 bytes")


def test_all_masks_are_planned_at_once_from_their_headers(monkeypatch) -> None:
    members = {"a.png": png("L", (10, 20)), "b.png": png("RGB", (4, 5)), "bad.png": b"junk"}
    names = ["a.png", "a.png", None, "b.png", "bad.png"]
    # a once (200) + two float copies (1 600) + b once (60) + its copy (80); the unreadable
    # member and the missing name are left to be reported with their areas
    expected = 200 + 1600 + 60 + 80
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES", str(expected))
    budget = ImageBudget(PROJECT)
    budget.plan_masks(names, lambda name, what: members[name])
    assert budget.total == 0  # planning charges nothing yet
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES", str(expected - 1))
    with pytest.raises(ProjectError) as caught:
        budget.plan_masks(names, lambda name, what: members[name])
    assert caught.value.problem == (
        f"the decoded images, with the 5 influence masks, is {expected:,} bytes, more than the "
        f"limit of {expected - 1:,} bytes (set WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES to change it)"
    )
