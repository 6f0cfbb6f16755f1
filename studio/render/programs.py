"""The compiled GLSL programs, built on first use and kept by key, and the texture units the
passes bind their textures to (one table, so no two passes ever share a unit by accident)."""

from __future__ import annotations

import moderngl

from studio.render.shaders import build_program

UNITS = {"diffuse": 0, "normals": 1, "masks": 2, "activations": 3, "t1_weight": 4,
         "t1_index": 5, "t1_slot_weight": 6, "more_maps": 7, "relief": 8, "tone": 9,
         "deform": 10}  # the GPU deformation's data textures: 10 and on (gpu_deform.DATA_UNITS)

# the helper passes' programs; any other key is the face program with those #defines
_HELPERS = {("wire",): ("wire.vert", "wire.frag"),
            ("compose",): ("t1_compose.vert", "t1_compose.frag")}


class Programs:
    """Programs by key: ``("wire",)`` and ``("compose",)`` for the helper passes, else a tuple
    of the face program's ``#define``s (tessellation stages added for RELIEF_DISPLACE)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._programs: dict[tuple[str, ...], moderngl.Program] = {}

    def get(self, key: tuple[str, ...]) -> moderngl.Program:
        if key not in self._programs:
            vert, frag = _HELPERS.get(key, ("face.vert", "face.frag"))
            defines = () if key in _HELPERS else key
            tess = ("face.tesc", "face.tese") if "RELIEF_DISPLACE" in key else (None, None)
            self._programs[key] = build_program(self.ctx, vert, frag, defines, *tess)
        return self._programs[key]

    def feedback(self, vertex: str, varyings: tuple[str, ...],
                 defines: tuple[str, ...] = ()) -> moderngl.Program:
        """A vertex-only program whose ``varyings`` transform feedback captures (the GPU
        deformation's passes), built once per shader and defines."""
        key = ("feedback", vertex, *defines)
        if key not in self._programs:
            self._programs[key] = build_program(self.ctx, vertex, None, defines,
                                                varyings=varyings)
        return self._programs[key]

    def release(self) -> None:
        for prog in self._programs.values():
            prog.release()
        self._programs.clear()


def write_matrix(prog: moderngl.Program, name: str, matrix) -> None:
    """A 4×4 numpy matrix (row-major) into a GLSL mat4 uniform (column-major)."""
    prog[name].write(matrix.T.astype("f4").tobytes())


def set_uniforms(prog: moderngl.Program, values: dict[str, object]) -> None:
    """Set the uniforms this program has; the others were optimised away by its #defines."""
    for name, value in values.items():
        if name in prog:
            prog[name].value = value
