"""The kinds of mesh file the studio reads, and the words for those it does not.

One table, so that the message for an unknown file, the file dialogs' filters and the command
line's help say the same: a user with a ``.blend`` or a Maya scene is told what the studio reads
and which export of their tool gives it, in one line, instead of a list of library formats.
"""

from __future__ import annotations

from pathlib import Path

# (what a user calls it, its suffixes), in the order they are listed
READ: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("OBJ", (".obj",)), ("PLY", (".ply",)), ("STL", (".stl",)), ("OFF", (".off",)),
    ("glTF/GLB", (".gltf", ".glb")), ("VRM", (".vrm",)), ("FBX", (".fbx",)),
    ("USD", (".usd", ".usda", ".usdc", ".usdz")))
# read as a whole head, its blend shapes the key poses: never one key pose, nor a bare mesh
HEADS = frozenset({".vrm", ".fbx", ".usd", ".usda", ".usdc", ".usdz"})
# a key pose, or a mesh read on its own (a sculpt to bake from)
MESHES = (".obj", ".ply", ".stl", ".off", ".gltf", ".glb")
# the files of tools the studio does not read, and the export that gives one it reads
EXPORT = {
    ".blend": "from Blender use File > Export > glTF 2.0 or USD",
    ".abc": "an Alembic cache holds no blend shapes: export the head from the tool that made "
            "it as glTF, FBX or USD (Blender: File > Export > glTF 2.0 or USD)",
    ".dae": "open it in Blender (File > Import > Collada) and use File > Export > glTF 2.0",
    ".ma": "from Maya use File > Export All as FBX or USD",
    ".mb": "from Maya use File > Export All as FBX or USD",
    ".max": "from 3ds Max use File > Export > FBX",
}


def suffixes(kinds: tuple[str, ...] | None = None) -> list[str]:
    """The suffixes of the kinds named (every kind the studio reads by default)."""
    return [s for name, found in READ if kinds is None or name in kinds for s in found]


def kinds_read() -> str:
    """"OBJ, PLY, …, FBX and USD": what the studio reads, in words."""
    names = [name for name, _ in READ]
    return f"{', '.join(names[:-1])} and {names[-1]}"


def file_filter(label: str = "Meshes", pick: tuple[str, ...] | None = None) -> str:
    """A file dialog's filter of the kinds named (all by default), then all files."""
    return f"{label} ({' '.join('*' + s for s in (pick or suffixes()))});;All files (*)"


def unknown_kind(path: str | Path) -> str:
    """The one line for a file of a kind the studio does not read: what it reads, and for a
    tool's own file, which export to use."""
    suffix = Path(path).suffix.lower()
    shown = f"'{Path(path).suffix}'" if suffix else "without a suffix"
    line = f"unknown mesh format {shown}: the studio reads {kinds_read()}"
    advice = EXPORT.get(suffix)
    return f"{line}; {advice}" if advice else line


def head_only(path: str | Path) -> str:
    """The one line for a head file (VRM, FBX, USD) given where one mesh is wanted."""
    return (f"a {Path(path).suffix} file is read as a whole head, its blend shapes the key "
            f"poses (as the neutral mesh of a new project); here use "
            f"{', '.join(s.lstrip('.').upper() for s in MESHES)}")
