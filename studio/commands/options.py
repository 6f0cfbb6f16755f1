"""Argument parsers and loaders the commands share (``studio.cli`` wires the commands; they import
what they need from here, so no command depends on the program that lists it)."""

from __future__ import annotations

import argparse
from pathlib import Path

from studio.core.files.errors import StudioError

EXIT_USAGE = 2  # every problem the user can cause: one line on stderr and this exit code


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a size like 1280x720") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"'{text}': width and height must be 1 to 16384")
    from studio.core.files.budgets import RENDER_PIXELS

    try:  # colour and depth, multisampled: 16384x16384 is over 9 GB of framebuffers
        RENDER_PIXELS.check(w * h, f"'{text}'", error=StudioError, hint="choose a smaller size")
    except StudioError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return w, h


def parse_vertices(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 100 <= n <= 200_000:
        raise argparse.ArgumentTypeError(f"{n}: the test face takes 100 to 200000 vertices")
    return n


def load_project_or_sample(path: str | None, vertices: int | None):
    """The project at ``path``; without one the bundled sample (the ICT-FaceKit head), or with
    ``vertices`` the procedural test face at that resolution (the thesis's study)."""
    if path is None:
        if vertices:
            from studio.core.sample.synthetic import make_test_face

            return make_test_face(vertices)
        from studio.core.setup.sample_setup import sample_project

        return sample_project()
    from studio.core.project.reader import load_project

    if vertices:
        raise StudioError("--vertices applies to the bundled sample, not to a project file")
    return load_project(Path(path))


def add_look_options(p: argparse.ArgumentParser) -> None:
    """``--look`` and ``--light-rig``: how ``render`` and the web page shade the face."""
    from studio.core.wrinkles.skin_light import LOOKS, RIG_LABELS, RIG_NAMES

    p.add_argument("--look", choices=LOOKS, default="clay",
                   help="clay: the first shading; skin: a skin shader (scattering diffuse, two "
                        "specular lobes, the head's albedo, each wrinkled map's cavity and "
                        "colour) under the light rig")
    p.add_argument("--light-rig", choices=RIG_NAMES, default="studio",
                   help="the skin look's lights: " + "; ".join(
                       f"{k}: {v}" for k, v in RIG_LABELS.items()))
