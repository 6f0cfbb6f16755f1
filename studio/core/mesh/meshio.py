"""Loading face meshes and key poses, and writing meshes back out as OBJ.

OBJ — what artists exchange face models and blend shapes in — is read by our own parser, so the
file's ``v`` order survives exactly: welded position ``i`` is the file's ``v`` number ``i + 1``,
which is what lets a key pose exported from the same scene line up vertex for vertex. Render
vertices are split wherever one ``v`` is used with different ``vt`` (UV seams).

An OBJ's ``o`` objects, ``g`` groups and ``usemtl`` materials are read per face, so a file holding
the face with its eyes and teeth can be loaded whole or in part (``keep``, see ``obj_groups``);
the choice made for the neutral mesh is applied to every key pose loaded against it. When only
part of a file is kept, its unused ``v`` are dropped: welded positions are then the used ``v`` in
file order.

PLY, STL, OFF and glTF/GLB go through trimesh; any other suffix is refused in one line that
names what the studio reads and, for a tool's own file (``.blend``, ``.ma``), the export to use
(core/mesh/file_kinds.py); a head file (VRM, FBX, USD) is read whole by the project assembly.
Their render vertices are the file's vertices and positions that coincide exactly are
welded. A file without UVs (STL and OFF never have any, PLY often not) is welded by position
and unwrapped by xatlas (core/mesh/unwrap.py): its render vertices are then xatlas's, so what a
key pose of the same file topology needs (the file's vertex count, its triangles, which welded
position each file vertex is) is kept beside the mesh.

Every problem a user can cause raises ``MeshError`` naming the file and, where it helps, the line,
face or vertex (numbered from 1, as in the file) — never a bare traceback.
"""

from __future__ import annotations

import re
import warnings
import weakref
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.file_kinds import HEADS, MESHES, head_only, unknown_kind
from studio.core.mesh.obj_records import KINDS, UNNAMED, sort_records
from studio.core.mesh.unwrap import unwrap

Array = np.ndarray

_MISSING = np.iinfo(np.int64).min  # a face corner without a texture index


@dataclass(frozen=True)
class ObjGroup:
    """A named part of an OBJ: an object, group or material, and how many faces carry it.

    Each kind splits the faces: every face has one object, one group and one material name.
    """

    kind: str  # "object", "group" or "material"
    name: str
    faces: int


@dataclass
class _ObjData:
    """What the OBJ parser read: positions, UVs and polygons with 0-based, resolved indices."""

    positions: Array  # (N, 3) float64, file order
    uvs: Array  # (M, 2) float64
    sizes: Array  # (P,) corners per polygon
    corner_v: Array  # (C,) intp
    corner_vt: Array  # (C,) intp, _MISSING where a corner has no vt
    face_lines: Array  # (P,) line of each polygon, for messages
    # kind -> (names, (P,) index into names per polygon); kinds the file never names are absent
    labels: dict[str, tuple[list[str], Array]] = field(default_factory=dict)
    face_number: Array | None = None  # (P,) the file's polygon number, once filtered
    libraries: list[str] = field(default_factory=list)  # ``mtllib`` lines, as written
    v_number: Array | None = None  # (N,) the file's v number of each position, once filtered

    def __post_init__(self) -> None:
        if self.face_number is None:
            self.face_number = np.arange(len(self.sizes))
        if self.v_number is None:
            self.v_number = np.arange(len(self.positions))

    def names(self, kind: str | None = None) -> set[str]:
        """The part names of one kind, or of every kind."""
        return {name for k, (names, _) in self.labels.items() if kind in (None, k)
                for name in names}


@dataclass
class _ObjInfo:
    """What a mesh read from OBJ remembers of its file: the polygons (so a key pose is checked
    face by face and errors use the file's numbers), the part names of each kept polygon, and
    which parts were kept (so each key pose is cut the same way)."""

    data: _ObjData  # the kept polygons, indices over the mesh's welded vertices
    keep: frozenset[str] | None
    kind: str | None  # the kind of part the kept names are, None for any
    file_mask: Array  # (P_file,) bool: which of the file's polygons were kept


# Kept beside FaceMesh rather than in it, and dropped with the mesh.
_OBJ_INFO: weakref.WeakKeyDictionary[FaceMesh, _ObjInfo] = weakref.WeakKeyDictionary()
# A mesh whose UVs the studio made (core/mesh/unwrap.py) -> the line that says so.
_MADE_UVS: weakref.WeakKeyDictionary[FaceMesh, str] = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class _FileTopology:
    """A PLY/STL/OFF mesh unwrapped by the studio, as its file had it: a key pose exported from
    the same scene has the file's vertices and triangles, not the render vertices xatlas made,
    so it is checked against these and read through ``weld``."""

    weld: Array  # (N_file,) the file's vertex -> welded position
    triangles: Array  # (F, 3) the file's triangles over its own vertices


# A mesh from a non-OBJ file without UVs -> its file's topology (see _FileTopology).
_FILE_TOPOLOGY: weakref.WeakKeyDictionary[FaceMesh, _FileTopology] = weakref.WeakKeyDictionary()


# --------------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------------


def obj_groups(path: str | Path) -> list[ObjGroup]:
    """The objects, groups and materials an OBJ names, kind by kind, each kind's names in the
    order the file first uses them, with their face counts. Faces before any ``o``/``g``/
    ``usemtl`` are "(no object)", "default" (OBJ's own name) and "(no material)"; kinds the
    file never names are left out."""
    path = Path(path)
    _check_readable(path)
    if path.suffix.lower() != ".obj":
        return []
    data = _parse_obj(path, _read_obj(path))
    return [ObjGroup(kind, name, int(count))
            for kind, (names, ids) in data.labels.items()
            for name, count in zip(names, np.bincount(ids, minlength=len(names)), strict=True)]


def load_mesh(path: str | Path, keep: Collection[str] | None = None,
              kind: str | None = None) -> FaceMesh:
    """Read a face mesh: OBJ with our parser, other formats through trimesh.

    ``keep`` (OBJ only) names the parts to keep: a face stays when its object, group or material
    (only its ``kind`` of name, if given) is one of them; None keeps the whole file. Key poses
    loaded against the mesh are cut the same way.
    """
    path = Path(path)
    _check_readable(path)
    if path.suffix.lower() == ".obj":
        data = _parse_obj(path, _read_obj(path))
        file_mask = np.ones(len(data.sizes), bool)
        chosen = None if keep is None else frozenset(keep)
        if chosen is not None:
            file_mask = _named_faces(path, data, chosen, kind)
            if not file_mask.any():
                raise MeshError("no parts are kept: keep at least one", path)
            data = _compact(data, file_mask)
        mesh = _mesh_from_obj(path, data)
        _OBJ_INFO[mesh] = _ObjInfo(data, chosen, kind, file_mask)
        return mesh
    if keep is not None:
        raise MeshError("only OBJ files have groups or materials to choose from", path)
    positions, faces, uvs = _load_with_trimesh(path, need_uvs=True)
    if uvs is None:  # none at all (STL, OFF, a bare PLY): made, and said (``made_uvs``)
        return _unwrapped_file(path, positions, faces)
    return mesh_from_render_vertices(path, positions, faces, uvs)


def load_pose(path: str | Path, mesh: FaceMesh, name: str | None = None) -> KeyPose:
    """Read a key pose: a mesh with the neutral mesh's topology (name defaults to the file stem).

    OBJ poses must have the same ``v`` count and faces over the same ``v`` indices as the neutral
    OBJ — strictly, the same triangles once polygons are fanned, so a pose re-saved as triangles
    still fits; UVs are ignored. When only some parts of the neutral OBJ were kept, the pose is
    cut to the same parts (by name, or by face number if it names none of them) and compared
    after the cut, so a pose exported without the eyes still fits a neutral mesh without them.
    Poses in other formats must have the same vertices and faces, and vertices welded in the
    neutral mesh must coincide; when the studio made the neutral mesh's UVs, "the same" is the
    neutral file's vertices and triangles (an STL repeats every corner), not the render
    vertices xatlas made. The first mismatch is reported (face and vertex numbers from 1,
    as in the file) so a user can find it in their modelling tool.
    """
    path = Path(path)
    name = path.stem if name is None else name
    _check_readable(path)
    if path.suffix.lower() == ".obj":
        data = _parse_obj(path, _read_obj(path))
        info = _OBJ_INFO.get(mesh)
        if info is not None and info.keep is not None:
            data = _compact(data, _pose_keep_mask(path, data, info))
        _check_obj_pose(path, data, mesh, info)
        return KeyPose(name=name, positions=data.positions)
    positions, faces, _ = _load_with_trimesh(path, need_uvs=False)
    topology = _FILE_TOPOLOGY.get(mesh) or _topology_by_faces(positions, faces, mesh)
    if topology is not None:  # the file's own vertices, not xatlas's render vertices
        weld, triangles = topology.weld, topology.triangles
    else:
        weld, triangles = mesh.weld, mesh.triangles
    if len(positions) != len(weld):
        raise MeshError(
            f"has {len(positions)} vertices, the neutral mesh has {len(weld)}", path
        )
    _check_same_triangles(path, faces, triangles)
    # Welded positions from each welded vertex's first file copy; the other copies must agree.
    _, first = np.unique(weld, return_index=True)
    welded = mesh.rest.astype(np.float64)
    welded[weld[first]] = positions[first]
    apart = np.abs(welded[weld] - positions).max(axis=1)
    extent = max(float(np.ptp(positions, axis=0).max()), 1e-30)
    torn = apart > 1e-6 * extent
    if torn.any():
        i = int(np.argmax(torn))
        j = int(np.argmax(weld == weld[i]))
        raise MeshError(
            f"vertices {j + 1} and {i + 1} are one point in the neutral mesh but apart in "
            "this pose",
            path,
        )
    return KeyPose(name=name, positions=welded)


def made_uvs(mesh: FaceMesh) -> str | None:
    """"no UVs in FILE: made them with xatlas, N charts" for a mesh read without UVs, else
    None: the user is told that the layout their maps must follow is the studio's."""
    return _MADE_UVS.get(mesh)


def not_face_vertices(mesh: FaceMesh, names: Collection[str], kind: str | None = None) -> Array:
    """(W,) bool: the welded vertices whose every face is in one of the named parts (eyes,
    teeth...), so the seam between skin and eyelid stays skin. The mesh must come from an OBJ
    (``load_mesh``); the names are objects, groups or materials of that file (of ``kind``)."""
    info = _OBJ_INFO.get(mesh)
    where = mesh.source or None
    if info is None:
        raise MeshError("only OBJ files have groups or materials to mark as not-face", where)
    data = info.data
    marked = _named_faces(where, data, frozenset(names), kind)
    per_triangle = np.repeat(marked, data.sizes - 2)
    tris = mesh.welded_triangles
    every = np.bincount(tris.ravel(), minlength=mesh.n_welded)
    flagged = np.bincount(tris[per_triangle].ravel(), minlength=mesh.n_welded)
    return (every > 0) & (flagged == every)


def obj_materials(mesh: FaceMesh) -> tuple[list[str], list[str], Array] | None:
    """An OBJ mesh's ``mtllib`` lines as written, its material names and the material of each
    triangle (index into the names; the mesh's own triangles, in order): what finds the skin's
    textures (core/formats/obj_maps.py). None for a mesh not read from an OBJ, or one that
    names no material."""
    info = _OBJ_INFO.get(mesh)
    if info is None or "material" not in info.data.labels:
        return None
    names, ids = info.data.labels["material"]
    return info.data.libraries, list(names), np.repeat(ids, info.data.sizes - 2)


def save_obj(path: str | Path, mesh: FaceMesh, positions: Array | KeyPose | None = None) -> None:
    """Write the mesh (or a pose's welded positions on its topology) as OBJ with ``v/vt`` faces.

    Welded positions become the ``v`` lines in order, so ``load_mesh``/``load_pose`` read the
    file back with the same welded numbering.
    """
    path = Path(path)
    if positions is None:
        pos = mesh.rest
    elif isinstance(positions, KeyPose):
        pos = positions.positions
    else:
        pos = np.asarray(positions)
    if pos.shape != mesh.rest.shape:
        raise MeshError(
            f"cannot save positions of shape {pos.shape} on a mesh of {mesh.n_welded} vertices",
            path,
        )
    corners = np.stack([mesh.weld[mesh.triangles] + 1, mesh.triangles + 1], axis=2)
    try:
        with path.open("w", encoding="utf-8", newline="\n") as fh:
            fh.write("# Wrinkle Studio mesh\n")
            np.savetxt(fh, pos, fmt="v %.9g %.9g %.9g")
            np.savetxt(fh, mesh.uvs, fmt="vt %.9g %.9g")
            np.savetxt(fh, corners.reshape(len(corners), 6), fmt="f %d/%d %d/%d %d/%d")
    except OSError as exc:
        raise MeshError(f"cannot write the file ({exc.strerror or exc})", path) from exc


# --------------------------------------------------------------------------------------------
# Reading files
# --------------------------------------------------------------------------------------------


def _check_readable(path: Path) -> None:
    from studio.core.files.budgets import FILE_BYTES
    from studio.core.files.safe_io import require_regular

    if not path.exists():
        raise MeshError("file not found", path)
    require_regular(path, MeshError, "mesh file")  # a FIFO or device would hang the reader
    FILE_BYTES.check(path.stat().st_size, "the mesh file", path, MeshError)


def _read_obj(path: Path) -> bytes:
    from studio.core.files.budgets import FILE_BYTES
    from studio.core.files.safe_io import read_regular

    raw = read_regular(path, FILE_BYTES.value, MeshError, "mesh file", FILE_BYTES.setting)
    if not raw.strip():
        raise MeshError("the file is empty", path)
    if b"\x00" in raw[:4096]:
        raise MeshError("not an OBJ mesh (the file is binary)", path)
    return raw


def _parse_obj(path: Path, raw: bytes) -> _ObjData:
    """Parse ``v``, ``vt``, ``f``, the part names ``o``, ``g``, ``usemtl`` and the material
    libraries ``mtllib`` names; everything else (vn, s, ...) is ignored.

    The lines are sorted in bulk (core/mesh/obj_records.py); numbers are converted in bulk by
    numpy, and only when that fails are the tokens walked again to say which line is wrong.
    Part names are recorded where they change (face count, name) and spread over the faces
    afterwards.
    """
    rec = sort_records(path, raw)
    if not len(rec.v_line):
        raise MeshError("not an OBJ mesh: no vertices ('v' lines) found", path)
    if not len(rec.sizes):
        raise MeshError("the mesh has no faces ('f' lines)", path)

    positions = _floats(path, rec.v, rec.v_line, 3, "vertex coordinates")
    _require_finite(path, positions, rec.v_line,
                    "vertex {} (line {}) has a non-finite coordinate")
    _require_float32(path, positions, "vertex {}", rec.v_line)
    uvs = _floats(path, rec.vt, rec.vt_line, 2, "texture coordinates")
    _require_finite(path, uvs, rec.vt_line, "texture coordinate {} (line {}) is not finite")
    _require_float32(path, uvs, "texture coordinate {}", rec.vt_line)

    sizes, lines = rec.sizes, rec.f_line
    raw_v, raw_vt = _face_indices(path, rec.corners, sizes, lines)
    corner_v = _resolve(path, raw_v, rec.f_nv, len(positions), sizes, lines, "vertex")
    corner_vt = _resolve(path, raw_vt, rec.f_nvt, len(uvs), sizes, lines, "texture coordinate")
    labels = {kind: _spread_names(kind, rec.changes[kind], len(sizes)) for kind in KINDS
              if rec.changes[kind]}
    return _ObjData(positions, uvs, sizes, corner_v, corner_vt, lines, labels,
                    libraries=rec.libraries)


def _spread_names(kind: str, changes: list[tuple[int, str]], n_faces: int
                  ) -> tuple[list[str], Array]:
    """Per-face name index from the (face count, name) points where a name was set; only names
    that some face carries are kept, in the order faces first carry them."""
    at = np.array([0] + [start for start, _ in changes], dtype=np.intp)
    names = [UNNAMED[kind]] + [name for _, name in changes]
    index: dict[str, int] = {}
    code = np.array([index.setdefault(n, len(index)) for n in names], dtype=np.intp)
    unique = list(index)
    ids = code[np.searchsorted(at, np.arange(n_faces), side="right") - 1]
    used, ids = np.unique(ids, return_inverse=True)
    _, first = np.unique(ids, return_index=True)
    order = np.argsort(first)  # renumber by first face, not alphabetically
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return [unique[i] for i in used[order]], rank[ids.reshape(-1)]


def _require_finite(path: Path, values: Array, lines: Array, message: str) -> None:
    """Name the first row holding NaN or infinity (``message`` takes its number and line)."""
    bad = ~np.isfinite(values).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise MeshError(message.format(i + 1, lines[i]) + " (NaN or infinity)", path)


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _require_float32(path: Path, values: Array, what: str, lines: Array | list[int] | None = None
                     ) -> None:
    """Name the first row (``what`` takes its number) holding a value beyond the range of
    32-bit floats: the studio keeps positions and UVs as float32, where such a value would
    become infinity (with a numpy warning) far from the file that held it."""
    bad = (np.abs(values) > _FLOAT32_MAX).any(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        where = "" if lines is None else f" (line {lines[i]})"
        raise MeshError(f"{what.format(i + 1)}{where} is outside the range of 32-bit floats",
                        path)


def _floats(path: Path, tokens: str, lines: Array, width: int, what: str) -> Array:
    """(len(lines), width) floats from ``width`` space-separated tokens per line."""
    parts = tokens.split()
    try:
        return np.array(parts, dtype=np.float64).reshape(len(lines), width)
    except ValueError:
        for i, lineno in enumerate(lines):
            tok = parts[i * width:(i + 1) * width]
            try:
                [float(x) for x in tok]
            except ValueError:
                raise MeshError(
                    f"line {lineno}: cannot read the {what} '{' '.join(tok)}'", path
                ) from None
        raise MeshError(f"cannot read the {what}", path) from None


def _face_indices(path: Path, joined: str, sizes: Array, lines: Array) -> tuple[Array, Array]:
    """Raw (1-based or negative) ``v`` and ``vt`` indices of every face corner.

    Fast path: every corner written alike (``v``, ``v/vt`` or ``v/vt/vn``) is one numpy
    conversion. Anything else (``v//vn``, mixed forms, junk) takes the per-corner path, which
    also finds the line of a bad token.
    """
    n = int(sizes.sum())
    slashes = joined.count("/")
    width = slashes // max(n, 1) + 1
    # the total alone would take "1/1 2/2/1 3" for three v/vt corners: no corner may have
    # more slashes than the form's, so that every corner has exactly as many
    one_too_many = "/[^ /]*" * width
    if "//" not in joined and slashes in (0, n, 2 * n) and not re.search(one_too_many, joined):
        numbers = _plain_integers(joined)
        if numbers is None:
            try:
                numbers = np.array(joined.replace("/", " ").split(), dtype=np.int64)
            except (ValueError, OverflowError):
                numbers = None
        if numbers is not None and numbers.size == n * width:
            numbers = numbers.reshape(n, width)
            if width == 1:
                return numbers[:, 0], np.full(n, _MISSING, dtype=np.int64)
            return numbers[:, 0], numbers[:, 1]

    raw_v = np.empty(n, dtype=np.int64)
    raw_vt = np.full(n, _MISSING, dtype=np.int64)
    line_of = np.repeat(lines, sizes)
    for i, tok in enumerate(joined.split()):
        fields = tok.split("/")
        try:
            raw_v[i] = int(fields[0])
            if len(fields) > 1 and fields[1]:
                raw_vt[i] = int(fields[1])
        except (ValueError, OverflowError):
            raise MeshError(
                f"line {int(line_of[i])}: cannot read the face corner '{tok}'", path
            ) from None
    return raw_v, raw_vt


def _plain_integers(joined: str) -> Array | None:
    """The numbers of corners all written as ``-?digits`` (at most 18) between single spaces
    or slashes, read by numpy in one pass: six times quicker than a Python string per number,
    and exact for that writing, the only one it is given. None for any other (``+7``, ``1_0``,
    an empty field), which the per-token conversion reads as before."""
    if not joined.isascii():
        return None
    b = np.frombuffer(joined.encode("ascii"), np.uint8)
    gap = (b == 32) | (b == 47)
    digit = (b >= 48) & (b <= 57)
    minus = np.flatnonzero(b == 45)
    if (gap | digit).sum() + len(minus) != len(b):
        return None
    if len(minus) and (minus[-1] + 1 == len(b) or not digit[minus + 1].all()
                       or not ((minus == 0) | gap[minus - 1]).all()):
        return None
    ends = np.flatnonzero(gap)
    length = np.diff(ends, prepend=-1, append=len(b)) - 1
    if not ((length >= 1) & (length <= 19)).all():
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            numbers = np.fromstring(np.where(gap, 32, b).astype(np.uint8).tobytes(),
                                    dtype=np.int64, sep=" ")
        except (ValueError, DeprecationWarning):
            return None
    return numbers if numbers.size == len(length) else None


def _resolve(
    path: Path, raw: Array, defined_before: Array, total: int, sizes: Array, lines: Array, what: str
) -> Array:
    """0-based indices from OBJ's 1-based and negative (relative) ones, range-checked.

    Corners marked ``_MISSING`` (no texture index) stay ``_MISSING``.
    """
    base = np.repeat(np.asarray(defined_before, dtype=np.int64), sizes)
    missing = raw == _MISSING
    raw = np.where(missing, 1, raw)
    index = np.where(raw > 0, raw - 1, base + raw)
    bad = ((raw == 0) | (index < 0) | (index >= total)) & ~missing
    if bad.any():
        c = int(np.argmax(bad))
        face = int(np.searchsorted(np.cumsum(sizes), c, side="right"))
        have = f"only {int(base[c])} come before it" if raw[c] < 0 else f"the file has {total}"
        raise MeshError(
            f"face {face + 1} (line {int(lines[face])}) refers to {what} {int(raw[c])}, but {have}",
            path,
        )
    index[missing] = _MISSING
    return index


def _named_faces(path: Path | str | None, data: _ObjData, names: frozenset[str],
                 kind: str | None) -> Array:
    """(P,) bool: the polygons whose object, group or material (or only its ``kind`` of name)
    is one of ``names`` (``--keep skin --keep lips`` keeps both); an unknown name is an error
    that lists the file's names. Every name listed has faces, so a known name selects some."""
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    unknown = sorted(names - data.names(kind))
    if unknown:
        what = "object, group or material" if kind is None else kind
        have = ", ".join(sorted(data.names(kind), key=str.lower)) or "none"
        raise MeshError(f"no {what} named {', '.join(map(repr, unknown))} "
                        f"(the file has: {have})", path)
    mask = np.zeros(len(data.sizes), bool)
    for k, (names_of_kind, ids) in data.labels.items():
        if kind in (None, k):
            mask |= np.isin(ids, [i for i, n in enumerate(names_of_kind) if n in names])
    return mask


def _pose_keep_mask(path: Path, data: _ObjData, info: _ObjInfo) -> Array:
    """The neutral mesh's choice of parts applied to a key pose: by name when the pose names
    them, else by face number when it has as many faces as the neutral file."""
    assert info.keep is not None
    if info.keep <= data.names(info.kind):
        return _named_faces(path, data, info.keep, info.kind)
    if len(data.sizes) == len(info.file_mask):
        return info.file_mask
    missing = ", ".join(sorted(info.keep - data.names(info.kind)))
    raise MeshError(f"names no part called {missing} (kept from the neutral mesh) and has "
                    f"{len(data.sizes)} faces, the neutral file {len(info.file_mask)}: export "
                    "the key pose with the same objects, groups and materials", path)


def _compact(data: _ObjData, keep: Array) -> _ObjData:
    """Only the kept polygons, and only the ``v`` they use (renumbered, file order kept)."""
    corners = np.repeat(keep, data.sizes)
    corner_v = data.corner_v[corners]
    used = np.unique(corner_v)
    renumber = np.full(len(data.positions), -1, dtype=np.intp)
    renumber[used] = np.arange(len(used))
    return _ObjData(
        positions=data.positions[used],
        uvs=data.uvs,
        sizes=data.sizes[keep],
        corner_v=renumber[corner_v],
        corner_vt=data.corner_vt[corners],
        face_lines=data.face_lines[keep],
        labels={kind: (names, ids[keep]) for kind, (names, ids) in data.labels.items()},
        face_number=data.face_number[keep],
        v_number=data.v_number[used],
        libraries=data.libraries,
    )


def _fan_triangles(sizes: Array) -> Array:
    """Corner indices of the fan triangulation ``(c0, ci, ci+1)`` of each polygon."""
    starts = np.cumsum(sizes) - sizes
    per_face = sizes - 2
    face = np.repeat(np.arange(len(sizes)), per_face)
    k = np.arange(int(per_face.sum())) - np.repeat(np.cumsum(per_face) - per_face, per_face) + 1
    base = starts[face]
    return np.stack([base, base + k, base + k + 1], axis=1)


def _mesh_from_obj(path: Path, data: _ObjData) -> FaceMesh:
    """Split render vertices per distinct ``(v, vt)`` pair; ``weld`` is the ``v`` index."""
    _check_counts(path, len(data.positions), len(data.sizes))
    missing = data.corner_vt == _MISSING
    if missing.any():
        if len(data.uvs) == 0:  # none at all: made, and said (``made_uvs``)
            made = unwrap(data.positions, data.corner_v[_fan_triangles(data.sizes)], str(path))
            _MADE_UVS[made.mesh] = made.report(path)
            return made.mesh
        c = int(np.argmax(missing))
        face = int(np.searchsorted(np.cumsum(data.sizes), c, side="right"))
        raise MeshError(
            f"face {face + 1} (line {int(data.face_lines[face])}) has no texture coordinates",
            path,
        )
    n_vt = len(data.uvs)
    key = data.corner_v.astype(np.int64) * n_vt + data.corner_vt
    unique, inverse = np.unique(key, return_inverse=True)
    triangles = inverse.reshape(-1)[_fan_triangles(data.sizes)]
    return FaceMesh(
        rest=data.positions,
        triangles=triangles,
        uvs=data.uvs[unique % n_vt],
        weld=unique // n_vt,
        source=str(path),
    )


def _load_with_trimesh(path: Path, need_uvs: bool) -> tuple[Array, Array, Array | None]:
    """Vertices, triangles and (if any) UVs of a mesh file trimesh can read. With
    ``need_uvs``, UVs that are there but do not fit the vertices are refused; none at all is
    None (the caller makes them)."""
    if path.suffix.lower() in HEADS:
        raise MeshError(head_only(path), path)
    if path.suffix.lower() not in MESHES:
        raise MeshError(unknown_kind(path), path)
    suffix = path.suffix.lower().lstrip(".")
    try:
        import trimesh
    except ImportError as exc:  # pragma: no cover - trimesh is a dependency
        raise MeshError(f"cannot read .{suffix} files: trimesh is not installed", path) from exc
    try:
        if path.stat().st_size == 0:
            raise MeshError("the file is empty", path)
        if suffix == "stl":
            _check_stl_text(path)
        with warnings.catch_warnings():
            # numpy warns as trimesh casts a PLY value of 1e39 or NaN to float32: the values
            # are checked below, and a warning would print its source line before our message
            warnings.simplefilter("ignore")
            loaded = trimesh.load(str(path), force="mesh", process=False)
    except MeshError:
        raise
    except Exception as exc:  # trimesh raises many kinds; the user needs one message
        raise MeshError(f"cannot read the mesh ({type(exc).__name__}: {exc})", path) from exc
    if not isinstance(loaded, trimesh.Trimesh):
        raise MeshError("the file holds no triangle mesh", path)
    try:
        positions = np.asarray(loaded.vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(loaded.faces, dtype=np.int64).reshape(-1, 3)
        uv = getattr(loaded.visual, "uv", None)
        uvs = None if uv is None else np.asarray(uv, dtype=np.float64)
    except (ValueError, TypeError) as exc:
        raise MeshError(f"cannot read the mesh ({exc})", path) from exc
    if len(positions) == 0:
        raise MeshError("the mesh is empty (no vertices)", path)
    _check_counts(path, len(positions), len(faces))
    if len(faces) == 0:
        raise MeshError("the mesh has no faces", path)
    bad = ~np.isfinite(positions).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise MeshError(f"vertex {i + 1} has a non-finite coordinate (NaN or infinity)", path)
    _require_float32(path, positions, "vertex {}")
    out_of_range = (faces < 0) | (faces >= len(positions))
    if out_of_range.any():
        f = int(np.argmax(out_of_range.any(axis=1)))
        raise MeshError(
            f"face {f + 1} refers to a vertex that does not exist (the mesh has {len(positions)})",
            path,
        )
    if need_uvs and uvs is not None:
        if uvs.ndim != 2 or uvs.shape[0] != len(positions) or uvs.shape[1] < 2:
            # UVs for only some vertices: a damaged layout, not a missing one to make
            raise MeshError("the mesh has no texture coordinates (UVs); export it with UVs", path)
        uvs = uvs[:, :2]
        if not np.isfinite(uvs).all():
            i = int(np.argmax(~np.isfinite(uvs).all(axis=1)))
            raise MeshError(f"vertex {i + 1} has a non-finite texture coordinate", path)
        _require_float32(path, uvs, "the texture coordinate of vertex {}")
    return positions, faces, uvs


def _check_stl_text(path: Path) -> None:
    """A text STL must be ASCII: trimesh guesses other encodings with an optional package and
    fails with an ImportError (or garbage) on bytes no encoding explains."""
    size = path.stat().st_size
    with path.open("rb") as fh:
        head = fh.read(84)
    if not head.startswith(b"solid") or (
            len(head) == 84 and 84 + 50 * int.from_bytes(head[80:84], "little") == size):
        return  # binary STL (its header may start with "solid" too)
    from studio.core.files.safe_io import read_regular

    data = read_regular(path, size, MeshError, "mesh file")
    try:
        data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise MeshError(f"a text STL must be ASCII, but byte {exc.start + 1} is 0x"
                        f"{data[exc.start]:02x} (damaged, or another kind of file)", path) from None


def _check_counts(path: Path, vertices: int, faces: int) -> None:
    """The mesh budgets (vertices, faces), before the per-vertex work begins."""
    from studio.core.files.budgets import MESH_TRIANGLES, MESH_VERTICES

    MESH_VERTICES.check(vertices, "the mesh", path, MeshError)
    MESH_TRIANGLES.check(faces, "the mesh's face count", path, MeshError)


def _weld_by_position(positions: Array) -> tuple[Array, Array]:
    """(rows, weld): the first row of each distinct position, in the order the file first
    uses them, and each row's welded number (an index into ``rows``)."""
    _, first, inverse = np.unique(positions, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return first[order], rank[inverse.reshape(-1)]


def mesh_from_render_vertices(path: Path, positions: Array, faces: Array, uvs: Array) -> FaceMesh:
    """Weld render vertices whose positions are identical, keeping first-occurrence order."""
    rows, weld = _weld_by_position(positions)
    return FaceMesh(
        rest=positions[rows],
        triangles=faces,
        uvs=uvs,
        weld=weld,
        source=str(path),
    )


def _topology_by_faces(positions: Array, faces: Array, mesh: FaceMesh) -> _FileTopology | None:
    """The file topology of a neutral mesh whose side table is gone (reopened from a project):
    a pose file of as many triangles, each corner landing on one welded vertex of the mesh's
    triangle in the same place, is the neutral file's topology. None when it is not (the
    render-vertex comparison then names the mismatch)."""
    if len(positions) == mesh.n_vertices or faces.shape != mesh.triangles.shape:
        return None
    weld = np.full(len(positions), -1, np.int64)
    weld[faces] = mesh.welded_triangles
    if (weld < 0).any() or not np.array_equal(weld[faces], mesh.welded_triangles):
        return None
    return _FileTopology(weld, faces)


def _unwrapped_file(path: Path, positions: Array, faces: Array) -> FaceMesh:
    """A mesh file without UVs: its vertices welded by position (an STL repeats each corner
    in every triangle, which xatlas would cut into as many charts as triangles), the welded
    surface unwrapped, and the file's topology kept for its key poses (``_FILE_TOPOLOGY``)."""
    rows, weld = _weld_by_position(positions)
    made = unwrap(positions[rows], weld[faces], str(path))
    _MADE_UVS[made.mesh] = made.report(path)
    _FILE_TOPOLOGY[made.mesh] = _FileTopology(weld, faces)
    return made.mesh


# --------------------------------------------------------------------------------------------
# Checking key poses
# --------------------------------------------------------------------------------------------


def _check_obj_pose(path: Path, data: _ObjData, mesh: FaceMesh, info: _ObjInfo | None) -> None:
    kept = "" if info is None or info.keep is None else " in the parts kept"
    if len(data.positions) != mesh.n_welded:
        raise MeshError(
            f"has {len(data.positions)} vertices{kept}, the neutral mesh has {mesh.n_welded}", path
        )
    # Same triangles is what matters (a pose saved by save_obj has only triangles even when the
    # neutral file had quads). When they differ, the first mismatching face is named in the
    # file's own terms if the neutral mesh's polygons are known.
    tris = data.corner_v[_fan_triangles(data.sizes)]
    if np.array_equal(tris, mesh.welded_triangles):
        return
    if info is None:  # e.g. a neutral mesh restored from a project file
        _check_same_triangles(path, tris, mesh.welded_triangles)
        return
    neutral = info.data
    sizes, corners = neutral.sizes, neutral.corner_v
    if len(data.sizes) != len(sizes):
        raise MeshError(
            f"has {len(data.sizes)} faces{kept}, the neutral mesh has {len(sizes)}", path
        )
    size_differs = np.flatnonzero(data.sizes != sizes)
    first_bad = int(size_differs[0]) if len(size_differs) else len(sizes)
    n_same = int(sizes[:first_bad].sum())  # corners that line up before any size differs
    corner_differs = np.flatnonzero(data.corner_v[:n_same] != corners[:n_same])
    if len(corner_differs):
        face = int(np.searchsorted(np.cumsum(sizes), corner_differs[0], side="right"))
        first_bad = min(first_bad, face)
    if first_bad < len(sizes):
        starts_pose = np.cumsum(data.sizes) - data.sizes
        starts_neutral = np.cumsum(sizes) - sizes
        mine = data.corner_v[
            starts_pose[first_bad] : starts_pose[first_bad] + data.sizes[first_bad]
        ]
        theirs = corners[starts_neutral[first_bad] : starts_neutral[first_bad] + sizes[first_bad]]
        raise MeshError(
            f"face {int(data.face_number[first_bad]) + 1} (line "
            f"{int(data.face_lines[first_bad])}) uses vertices "
            f"{_one_based(data.v_number[mine])}, the neutral mesh's face "
            f"{int(neutral.face_number[first_bad]) + 1} uses "
            f"{_one_based(neutral.v_number[theirs])}",
            path,
        )


def _check_same_triangles(path: Path, tris: Array, neutral: Array) -> None:
    if len(tris) != len(neutral):
        raise MeshError(f"has {len(tris)} triangles, the neutral mesh has {len(neutral)}", path)
    differs = np.flatnonzero((np.asarray(tris) != neutral).any(axis=1))
    if len(differs):
        i = int(differs[0])
        raise MeshError(
            f"triangle {i + 1} uses vertices {_one_based(tris[i])}, the neutral mesh's "
            f"triangle {i + 1} uses {_one_based(neutral[i])}",
            path,
        )


def _one_based(indices: Array) -> str:
    return "(" + ", ".join(str(int(i) + 1) for i in indices) + ")"
