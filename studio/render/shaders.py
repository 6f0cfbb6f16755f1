"""The one place GLSL is loaded: files in ``shaders/``, ``#include`` and ``#define`` handling.

Techniques are compiled as separate programs (a ``#define`` each) instead of branching on a
uniform, so every program does only its own work per pixel.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from functools import cache
from pathlib import Path

import moderngl

from studio.paths import shader_dir

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)
# a folder of shaders to load instead of shaders/: scripts/glsl_mutation.py runs the tests on
# mutated copies this way, never touching the tree's own files
SHADER_DIR_ENV = "WRINKLE_SHADER_DIR"


def shader_folder() -> Path:
    """Where the GLSL is read from: ``$WRINKLE_SHADER_DIR`` when set, else ``shaders/``."""
    override = os.environ.get(SHADER_DIR_ENV)
    return Path(override) if override else shader_dir()


@cache
def load_source(name: str) -> str:
    """Shader text with ``#include "file"`` lines replaced by that file's text."""
    path = shader_folder() / name
    text = path.read_text(encoding="utf-8")
    return _INCLUDE.sub(lambda m: load_source(m.group(1)), text)


def with_defines(source: str, defines: Iterable[str]) -> str:
    """Insert ``#define`` lines right after the ``#version`` line."""
    lines = source.split("\n", 1)
    extra = "".join(f"#define {d}\n" for d in defines)
    return f"{lines[0]}\n{extra}{lines[1] if len(lines) > 1 else ''}"


def build_program(ctx: moderngl.Context, vertex: str, fragment: str | None,
                  defines: Iterable[str] = (), tess_control: str | None = None,
                  tess_evaluation: str | None = None,
                  varyings: Iterable[str] = ()) -> moderngl.Program:
    """A program from shader files, every stage with the same defines; the tessellation stages
    (OpenGL 4.0) are optional and come as a pair. With ``varyings`` (and no fragment shader)
    the vertex stage's outputs are captured by transform feedback: how the tests read back
    what the real shader computed per vertex."""
    if (tess_control is None) != (tess_evaluation is None):
        raise ValueError("give both tessellation stages or neither")
    defines = tuple(defines)

    def stage(name: str | None) -> str | None:
        return None if name is None else with_defines(load_source(name), defines)

    return ctx.program(
        vertex_shader=stage(vertex),
        fragment_shader=stage(fragment),
        tess_control_shader=stage(tess_control),
        tess_evaluation_shader=stage(tess_evaluation),
        varyings=tuple(varyings),
    )
