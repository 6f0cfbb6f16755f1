"""An OBJ head's own maps: the skin material's ``map_Kd`` (base colour) and normal map from the
``.mtl`` files its ``mtllib`` lines name.

The skin's material is the one on most of the face's skin triangles (parts marked not face
left out). Its normal map is what Blender's OBJ exporter writes and importer reads as one:
``map_Bump`` (or ``bump``), or ``norm``. Options before a file name (``-bm 1.0``, ``-o u v w``,
``-clamp on``) are skipped; a name may hold spaces. Texture paths are relative to the ``.mtl``
(Blender also looks beside it by the file's name, for a folder moved without its textures).
A library or texture that is missing is said in the report (core/formats/head_maps.py), never
refused: the head opens in plain skin.
"""

from __future__ import annotations

from pathlib import Path, PureWindowsPath

import numpy as np

from studio.core.files.budgets import FILE_BYTES
from studio.core.files.errors import StudioError
from studio.core.files.naming import shown, shown_list
from studio.core.files.safe_io import read_regular
from studio.core.formats.head_maps import HeadMaps, MapSource, read_head_maps
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.meshio import obj_materials

Array = np.ndarray
# the statement that names each map, as the .mtl writes it (lower case)
MAP_KEYS = {"map_kd": "diffuse", "map_bump": "normal", "bump": "normal", "norm": "normal"}
# options of a map statement and how many values each takes (at most: -o, -s and -t take 1–3)
OPTION_VALUES = {"-blendu": 1, "-blendv": 1, "-bm": 1, "-boost": 1, "-cc": 1, "-clamp": 1,
                 "-imfchan": 1, "-mm": 2, "-o": 3, "-s": 3, "-t": 3, "-texres": 1,
                 "-type": 1}


def obj_head_maps(path: str | Path, mesh: FaceMesh, not_face: Array | None) -> HeadMaps:
    """The skin material's maps of an OBJ read by ``load_mesh`` (before its UVs are packed),
    and the report's lines; nothing when the OBJ names no material library."""
    path = Path(path)
    found = obj_materials(mesh)
    if found is None or not found[0]:
        return HeadMaps()
    libraries, names, triangle_material = found
    material = names[_skin_material(mesh, triangle_material, not_face, len(names))]
    lines: list[str] = []
    maps: dict[str, MapSource] | None = None
    for written in libraries:
        library = _library(path.parent, written)
        if library is None:
            lines.append(f"material library {shown(written)} not found beside "
                         f"{shown(path.name)}")
            continue
        try:
            text = read_regular(library, FILE_BYTES.value, StudioError, "material library",
                                FILE_BYTES.setting).decode("utf-8", errors="replace")
        except StudioError as exc:
            lines.append(f"material library {shown(written)} cannot be read ({exc.problem})")
            continue
        maps = _material_maps(text, material, library.parent)
        if maps is not None:
            break
    if maps is None:
        if libraries and not lines:
            lines.append(f"material {shown(material)} is in none of the material libraries "
                         f"({shown_list(libraries)}): plain skin colour")
        return HeadMaps(lines=lines)
    head = read_head_maps(maps, material, path)
    head.lines[:0] = lines
    return head


def _skin_material(mesh: FaceMesh, triangle_material: Array, not_face: Array | None,
                   count: int) -> int:
    """The material on most skin triangles (on most triangles when none is skin)."""
    skin = np.ones(len(triangle_material), bool)
    if not_face is not None:
        skin = ~not_face[mesh.welded_triangles].all(axis=1)
        if not skin.any():
            skin[:] = True
    return int(np.argmax(np.bincount(triangle_material[skin], minlength=count)))


def _library(folder: Path, written: str) -> Path | None:
    """The ``.mtl`` an ``mtllib`` line names: the whole line as one name (names with spaces),
    else its first word (a line naming several libraries), else the name beside the OBJ."""
    candidates = [written, *written.split()[:1], PureWindowsPath(written).name]
    return next((folder / c.replace("\\", "/") for c in candidates
                 if c and (folder / c.replace("\\", "/")).is_file()), None)


def _material_maps(text: str, material: str, folder: Path) -> dict[str, MapSource] | None:
    """The maps ``material``'s statements name in one library's text; None when the library
    does not define the material."""
    maps: dict[str, MapSource] | None = None
    current = None
    for line in text.splitlines():
        parts = line.split(None, 1)
        if not parts:
            continue
        key = parts[0].lower()
        if key == "newmtl":
            current = parts[1].strip() if len(parts) > 1 else ""
            if current == material:
                maps = {}
        elif current == material and key in MAP_KEYS and len(parts) > 1:
            assert maps is not None
            name = _file_name(parts[1])
            if name and MAP_KEYS[key] not in maps:
                relative = name.replace("\\", "/")
                maps[MAP_KEYS[key]] = MapSource(
                    name, None, [folder / relative, folder / PureWindowsPath(name).name])
    return maps


def _file_name(rest: str) -> str:
    """The file name of a map statement, its options skipped."""
    words = rest.split()
    i = 0
    while i < len(words) and words[i].lower() in OPTION_VALUES:
        most = OPTION_VALUES[words[i].lower()]
        i += 1
        taken = 0
        while taken < most and i < len(words) - 1 and _value(words[i]):
            i += 1
            taken += 1
    return " ".join(words[i:])


def _value(word: str) -> bool:
    if word.lower() in ("on", "off", "r", "g", "b", "m", "l", "z", "sphere", "cube_top",
                        "cube_bottom", "cube_front", "cube_back", "cube_left", "cube_right"):
        return True
    try:
        float(word)
    except ValueError:
        return False
    return True
