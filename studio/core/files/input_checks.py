"""Small checks of values a user or a file hands the studio: camera blocks, numbers, patterns.

Why here: these values reach code that trusts them (``float()`` of a list, ``math.radians`` of
infinity, ``%`` with a 10⁹-character field width) far from where they were read; checking them
where they enter turns each into a one-line message that names the file or the option.
"""

from __future__ import annotations

import math
import re
from typing import Any

from studio.core.files.budgets import PATTERN_WIDTH
from studio.core.files.errors import ProjectError, StudioError

# Frame rates a timeline may have: 1e-300 fps made a frame last longer than any clock counts.
MIN_FPS, MAX_FPS = 0.01, 1000.0
CAMERA_NUMBERS = ("distance", "yaw", "pitch", "fov_y", "radius")
_CONVERSION = re.compile(r"%(?P<flags>[#0 +-]*)(?P<width>\*|\d+)?(?:\.(?P<precision>\*|\d+))?"
                         r"(?P<kind>[%a-zA-Z]?)")


def finite(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def check_camera(view: Any, path: object = None) -> None:
    """Raise ProjectError when the view's ``camera`` block cannot place a camera.

    The block is optional; present, it must be an object whose ``target`` is three finite
    numbers and whose ``distance``, ``yaw``, ``pitch``, ``fov_y`` and ``radius`` (each optional)
    are finite, with a positive distance, radius and a field of view between 0 and 180 degrees.
    """
    if not isinstance(view, dict) or "camera" not in view:
        return
    camera = view["camera"]

    def fail(problem: str) -> None:
        raise ProjectError(f"project.json: view.camera {problem}", path)

    if not isinstance(camera, dict):
        fail("must be a JSON object")
    if "target" in camera:
        target = camera["target"]
        if not (isinstance(target, list) and len(target) == 3 and all(map(finite, target))):
            fail("target must be three finite numbers")
    for key in CAMERA_NUMBERS:
        if key in camera and not finite(camera[key]):
            fail(f"{key} must be a finite number")
    for key in ("distance", "radius"):
        if key in camera and camera[key] <= 0:
            fail(f"{key} must be positive")
    if "fov_y" in camera and not 0 < camera["fov_y"] < 180:
        fail("fov_y must be between 0 and 180 degrees")


def finite_float(text: str) -> float:
    """An argparse type: a finite number (``inf`` and ``nan`` refused)."""
    import argparse

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
    return value


def check_frame_pattern(pattern: str) -> None:
    """Refuse a frame-file pattern whose ``%d`` field is wider than PATTERN_WIDTH (a
    ``%999999999d`` would build a gigabyte-long name for every frame) or takes a ``*`` width."""
    for match in _CONVERSION.finditer(pattern):
        for part in ("width", "precision"):
            text = match.group(part)
            if text == "*":
                raise StudioError(f"-o {pattern}: a '*' width needs an argument the pattern "
                                  "cannot have; write the width, e.g. %04d")
            if text is not None:
                PATTERN_WIDTH.check(int(text), f"-o {pattern}: the field width",
                                    error=StudioError, hint="write a smaller width like %04d")
