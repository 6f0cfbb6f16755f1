"""The shading techniques, one entry each: what the menus, panels, command line, renderer and
benchmark know about a technique comes from here, so a new technique is its shader code, its
entry below, and nothing else to keep in step."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Technique:
    key: str  # the name in project files, on the command line and in the benchmark's CSV
    label: str  # for menus and panels
    short: str  # for tight places (the split view's labels, the export dialog)
    wrinkles: bool  # reveals wrinkled maps: has wrinkles to raise in relief, shows in split
    authored: bool  # driven by what the user authored (areas, vectors), not automatic


TECHNIQUE_LIST = (
    Technique("t2", "Technique 2 (wrinkle vectors)", "Technique 2 · wrinkle direction vectors",
              wrinkles=True, authored=True),
    Technique("t1", "Technique 1 (influence areas)", "Technique 1 · influence areas",
              wrinkles=True, authored=True),
    Technique("strain", "Automatic (skin compression)", "Automatic · skin compression",
              wrinkles=True, authored=False),
    Technique("none", "No wrinkles", "No wrinkles", wrinkles=False, authored=False),
    Technique("flat", "Flat (no normal maps)", "Flat shading", wrinkles=False, authored=False),
)
TECHNIQUES = {t.key: t for t in TECHNIQUE_LIST}
# the split view's columns, left to right: t1 | t2 | automatic, as the thesis compares them
SPLIT = ("t1", "t2", "strain")
WRINKLE_TECHNIQUES = tuple(t.key for t in TECHNIQUE_LIST if t.wrinkles)


def technique(key: str) -> Technique:
    try:
        return TECHNIQUES[key]
    except KeyError:
        raise ValueError(f"unknown technique '{key}' (choose from "
                         f"{', '.join(TECHNIQUES)})") from None


def shader_define(key: str) -> str:
    """The preprocessor symbol that selects a technique's code in shaders/face.*."""
    return f"TECHNIQUE_{technique(key).key.upper()}"
