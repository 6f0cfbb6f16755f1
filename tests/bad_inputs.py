"""A corpus of bad inputs, generated on demand: truncated, oversized, wrong-type, special files,
traversal and deep nesting, for the command line's per-case tests (tests/test_bad_inputs.py).

Nothing here is stored in the repository as bytes: each case is made in a fresh folder from a
small valid project, so the corpus follows the file formats as they change.
"""

from __future__ import annotations

import base64
import io
import json
import os
import struct
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.png import SIGNATURE, encode_png
from studio.core.formats.gltf.codec import save_gltf
from studio.core.mesh.meshio import save_obj
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face


def small_project():
    return make_test_face(561, texture_size=64, mask_size=32)


# what write_base leaves: the glTF export carries the Blender script and the three.js module
# with its example page beside the .glb
BASE_FILES = ("p.wrinkle", "face.obj", "face.glb", "blender_wrinkles.py", "wrinkles.js",
              "example.html")


def write_base(folder: Path) -> None:
    """p.wrinkle (a valid small project), face.obj (its mesh), face.glb (its glTF, with the
    files every glTF export writes beside it)."""
    project = small_project()
    save_project(project, folder / "p.wrinkle", backup=False)
    save_obj(folder / "face.obj", project.mesh)
    save_gltf(project, folder / "face.glb")


def png_claiming(width: int, height: int, depth: int = 8, colour: int = 2) -> bytes:
    """A tiny PNG whose header claims ``width`` × ``height`` (its data is one empty row)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + crc

    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    return b"".join((SIGNATURE, chunk(b"IHDR", header), chunk(b"IDAT", zlib.compress(b"\0")),
                     chunk(b"IEND", b"")))


def rewrite_project(source: Path, target: Path, change_doc: Callable[[dict], None] | None = None,
                    members: dict[str, bytes] | None = None) -> None:
    """A copy of the project at ``source`` with project.json changed and members replaced or
    added."""
    members = dict(members or {})
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info)
            if info.filename == "project.json" and change_doc is not None:
                doc = json.loads(data)
                change_doc(doc)
                data = json.dumps(doc).encode()
            zout.writestr(info.filename, members.pop(info.filename, data))
        for name, data in members.items():
            zout.writestr(name, data)


def gltf_doc(folder: Path) -> tuple[dict, bytes]:
    """The JSON and binary chunk of face.glb."""
    data = (folder / "face.glb").read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    return doc, data[20 + length + 8:]


def write_gltf(path: Path, doc: dict, binary: bytes | None = None) -> None:
    """A .gltf (JSON) file with the binary as a data URI, or a .glb."""
    if path.suffix == ".gltf":
        buffers = doc.get("buffers")
        if (binary is not None and isinstance(buffers, list) and buffers
                and isinstance(buffers[0], dict) and "uri" not in buffers[0]):
            doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                        + base64.b64encode(binary).decode())
        path.write_text(json.dumps(doc))
        return
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob = binary or b""
    blob += b"\0" * (-len(blob) % 4)
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(blob))
                     + struct.pack("<II", len(text), 0x4E4F534A) + text
                     + struct.pack("<II", len(blob), 0x004E4942) + blob)


def _mutate_gltf(change: Callable[[dict], None], suffix: str = ".glb"):
    def make(folder: Path) -> None:
        doc, binary = gltf_doc(folder)
        change(doc)
        write_gltf(folder / f"bad{suffix}", doc, binary)
    return make


def _prim(doc: dict) -> dict:
    return doc["meshes"][0]["primitives"][0]


def _deep(depth: int) -> str:
    return "[" * depth + "]" * depth


@dataclass
class Case:
    """One bad input: files to make, the command line, and a phrase its message must hold."""

    name: str
    args: list[str]
    needle: str
    make: Callable[[Path], None] | None = None
    output: str | None = None  # a file that must not appear (or change)


def _shared_masks(folder: Path) -> None:
    """60 areas pointing at one 4096² 16-bit mask: 64 MB of floats each, 3.8 GB in all."""
    mask = encode_png(np.zeros((4096, 4096), np.uint16), level=1)

    def change(doc: dict) -> None:
        first = doc["influence"]["areas"][0]
        doc["influence"]["areas"] = [dict(first, name=f"a{i}", mask="masks/shared.png")
                                     for i in range(60)]
        doc["influence"]["links"] = {}
    rewrite_project(folder / "p.wrinkle", folder / "bad.wrinkle", change,
                    {"masks/shared.png": mask})


def _fifo(name: str) -> Callable[[Path], None]:
    return lambda folder: os.mkfifo(folder / name)


def _unrelated_high(folder: Path) -> None:
    """The face's own mesh and UVs, moved ten face-sizes away: every ray misses it."""
    project = small_project()
    lo, hi = project.mesh.bounds()
    save_obj(folder / "high.obj", project.mesh, project.mesh.rest + 10.0 * (hi - lo))


def _stl_not_ascii(folder: Path) -> None:
    (folder / "bad.stl").write_bytes(b"solid face\n\xff\xfe\x93 facet normal 0 0 1\n")


def _new_mesh(name: str, mesh: str, needle: str, make: Callable[[Path], None]) -> Case:
    """``new --mesh MESH -o out.wrinkle`` on a bad mesh file: refused, and no project made."""
    return Case(name, ["new", "--mesh", mesh, "-o", "out.wrinkle"], needle, make, "out.wrinkle")


def _text(name: str, text: str) -> Callable[[Path], None]:
    return lambda folder: (folder / name).write_text(text)


def _ply(kind: str, rows: list[str]) -> Callable[[Path], None]:
    """bad.ply: an ASCII PLY of one triangle, x y z s t per vertex as ``kind`` (float/double)."""
    header = ["ply", "format ascii 1.0", f"element vertex {len(rows)}",
              *(f"property {kind} {axis}" for axis in "xyzst"),
              "element face 1", "property list uchar int vertex_indices", "end_header"]
    return _text("bad.ply", "\n".join([*header, *rows, "3 0 1 2"]) + "\n")


def _pose_beyond_float32(folder: Path) -> None:
    """pose.obj: face.obj with its second vertex's x at 1e39."""
    lines = (folder / "face.obj").read_text().splitlines()
    second = [i for i, line in enumerate(lines) if line.startswith("v ")][1]
    lines[second] = "v 1e39 " + " ".join(lines[second].split()[2:])
    (folder / "pose.obj").write_text("\n".join(lines) + "\n")


def _rest_scaled(factor: float) -> Callable[[Path], None]:
    """bad.wrinkle: p.wrinkle with its neutral positions multiplied by ``factor``."""
    def build(folder: Path) -> None:
        with zipfile.ZipFile(folder / "p.wrinkle") as z:
            rest = np.load(io.BytesIO(z.read("mesh/rest.npy")))
        out = io.BytesIO()
        np.save(out, (rest * np.float32(factor)).astype(np.float32))
        rewrite_project(folder / "p.wrinkle", folder / "bad.wrinkle",
                        members={"mesh/rest.npy": out.getvalue()})
    return build


def _doc(change: Callable[[dict], None]) -> Callable[[Path], None]:
    return lambda folder: rewrite_project(folder / "p.wrinkle", folder / "bad.wrinkle", change)


def _long_timeline(doc: dict) -> None:
    doc["timeline"]["end"] = 10 ** 9


def _tiny_fps(doc: dict) -> None:
    doc["timeline"]["fps"] = 1e-300


def _bad_camera(doc: dict) -> None:
    doc["view"]["camera"] = {"yaw": [1], "distance": "far"}


def _deep_project(folder: Path) -> None:
    rewrite_project(folder / "p.wrinkle", folder / "bad.wrinkle",
                    members={"project.json": ('{"format": "wrinkle-studio-project", '
                                              f'"version": 2, "view": {_deep(100000)}}}').encode()})


def _huge_texture_in_project(folder: Path) -> None:
    rewrite_project(folder / "p.wrinkle", folder / "bad.wrinkle",
                    members={"textures/diffuse.png": png_claiming(16384, 16384, 16)})


def _set(path: str, value: object) -> Callable[[dict], None]:
    """A change that sets doc[a][b]… (path parts split on '/', numbers as list indices)."""
    def change(doc: dict) -> None:
        *parents, last = path.split("/")
        node = doc
        for part in parents:
            node = node[int(part)] if isinstance(node, list) else node[part]
        node[int(last) if isinstance(node, list) else last] = value
    return change


def _short_target(doc: dict) -> None:
    """The first morph target reads only 3 of the mesh's positions (its own accessor)."""
    target = _prim(doc)["targets"][0]["POSITION"]
    doc["accessors"].append(dict(doc["accessors"][target], count=3))
    _prim(doc)["targets"][0]["POSITION"] = len(doc["accessors"]) - 1


def _outside_buffer(doc: dict) -> None:
    doc["buffers"][0] = {"uri": "../../../../etc/passwd", "byteLength": 10}


CASES = [
    # data lost or overwritten
    Case("export over its own project", ["export", "p.wrinkle", "--gltf", "p.wrinkle"],
         "overwrite the input"),
    Case("bake map over its project", ["bake", "p.wrinkle", "--high", "face.obj", "--png",
                                       "p.wrinkle"], "overwrite the input"),
    Case("bake project over the high mesh", ["bake", "p.wrinkle", "--high", "face.obj", "-o",
                                             "face.obj"], "overwrite the input"),
    Case("new over its mesh", ["new", "--mesh", "face.obj", "-o", "face.obj"],
         "overwrite the input"),
    Case("render over its project", ["render", "p.wrinkle", "-o", "p.wrinkle"],
         "overwrite the input"),
    Case("bake an unrelated high mesh", ["bake", "p.wrinkle", "--high", "high.obj", "--size",
                                         "64", "--png", "out.png"], "of the face's size",
         _unrelated_high, "out.png"),
    # memory and time
    Case("one mask shared by 60 areas", ["export", "bad.wrinkle", "--gltf", "out.glb"],
         "WRINKLE_STUDIO_MAX_TOTAL_IMAGE_BYTES", _shared_masks, "out.glb"),
    Case("16384² texture in a project", ["export", "bad.wrinkle", "--gltf", "out.glb"],
         "WRINKLE_STUDIO_MAX_IMAGE_PIXELS", _huge_texture_in_project, "out.glb"),
    Case("16384² diffuse map", ["new", "--mesh", "face.obj", "--diffuse", "big.png", "-o",
                                "out.wrinkle"], "WRINKLE_STUDIO_MAX_IMAGE_PIXELS",
         lambda f: (f / "big.png").write_bytes(png_claiming(16384, 16384)), "out.wrinkle"),
    Case("10⁹-frame timeline as GIF", ["render", "bad.wrinkle", "--size", "64x48", "--gif",
                                       "out.gif"], "WRINKLE_STUDIO_MAX_FRAMES",
         _doc(_long_timeline), "out.gif"),
    Case("%999999999d pattern", ["render", "p.wrinkle", "--frames", "0:2", "--size", "64x48",
                                 "-o", "f%999999999d.png"], "MAX_PATTERN_WIDTH"),
    Case("/dev/zero as a mesh", ["new", "--mesh", "/dev/zero", "-o", "out.wrinkle"],
         "a device", None, "out.wrinkle"),
    Case("/dev/zero as a project", ["export", "/dev/zero", "--gltf", "out.glb"], "a device",
         None, "out.glb"),
    Case("/dev/zero as an image", ["new", "--mesh", "face.obj", "--diffuse", "/dev/zero", "-o",
                                   "out.wrinkle"], "a device", None, "out.wrinkle"),
    Case("FIFO as a mesh", ["new", "--mesh", "fifo.obj", "-o", "out.wrinkle"], "FIFO",
         _fifo("fifo.obj"), "out.wrinkle"),
    Case("FIFO as a project", ["export", "fifo.wrinkle", "--gltf", "out.glb"], "FIFO",
         _fifo("fifo.wrinkle"), "out.glb"),
    Case("FIFO as an image", ["new", "--mesh", "face.obj", "--normal", "fifo.png", "-o",
                              "out.wrinkle"], "FIFO", _fifo("fifo.png"), "out.wrinkle"),
    Case("FIFO as a glTF", ["new", "--gltf", "fifo.glb", "-o", "out.wrinkle"], "FIFO",
         _fifo("fifo.glb"), "out.wrinkle"),
    Case("folder as a project", ["export", "sub", "--gltf", "out.glb"], "folder",
         lambda f: (f / "sub").mkdir(), "out.glb"),
    # tracebacks before: each now one line, exit 2
    Case("malformed camera block", ["render", "bad.wrinkle", "--size", "64x48", "-o",
                                    "out.png"], "view.camera", _doc(_bad_camera), "out.png"),
    Case("fps 1e-300", ["render", "bad.wrinkle", "--size", "64x48", "--gif", "out.gif"],
         "frame rate", _doc(_tiny_fps), "out.gif"),
    Case("deeply nested project.json", ["export", "bad.wrinkle", "--gltf", "out.glb"],
         "nest", _deep_project, "out.glb"),
    Case("-o in a missing folder", ["sample", "-o", "nowhere/x.wrinkle"], "does not exist"),
    Case("-o under a file", ["export", "p.wrinkle", "--gltf", "face.obj/x.glb"],
         "not a folder"),
    Case("-o is a folder", ["render", "p.wrinkle", "--size", "64x48", "-o", "sub"], "folder",
         lambda f: (f / "sub").mkdir()),
    Case("--yaw inf", ["render", "p.wrinkle", "--yaw", "inf", "-o", "out.png"], "finite",
         None, "out.png"),
    Case("--size 16384x16384", ["render", "p.wrinkle", "--size", "16384x16384", "-o",
                                "out.png"], "MAX_RENDER_PIXELS", None, "out.png"),
    Case("STL that is not ASCII", ["new", "--mesh", "bad.stl", "-o", "out.wrinkle"], "ASCII",
         _stl_not_ascii, "out.wrinkle"),
    Case("glTF accessor out of range", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "accessors[999]", _mutate_gltf(lambda d: _prim(d)["attributes"].update(POSITION=999)),
         "out.wrinkle"),
    Case("glTF negative accessor", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "accessors[-1]", _mutate_gltf(lambda d: _prim(d)["attributes"].update(POSITION=-1)),
         "out.wrinkle"),
    Case("glTF wrong component type", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "component type", _mutate_gltf(_set("accessors/0/componentType", 5130)), "out.wrinkle"),
    Case("glTF positions as scalars", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "POSITION", _mutate_gltf(_set("accessors/0/type", "SCALAR")), "out.wrinkle"),
    Case("glTF float indices", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "indices", _mutate_gltf(lambda d: d["accessors"][_prim(d)["indices"]].update(
             componentType=5126)), "out.wrinkle"),
    Case("glTF morph target of 3 vertices", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "morph target '", _mutate_gltf(_short_target), "out.wrinkle"),
    Case("glTF accessor past its view", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "past", _mutate_gltf(_set("accessors/0/count", 10 ** 6)), "out.wrinkle"),
    Case("glTF view past its buffer", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"],
         "past", _mutate_gltf(_set("bufferViews/0/byteOffset", 10 ** 9)), "out.wrinkle"),
    Case("glTF buffer outside its folder", ["new", "--gltf", "bad.gltf", "-o", "out.wrinkle"],
         "outside", _mutate_gltf(_outside_buffer, ".gltf"), "out.wrinkle"),
    Case("glTF deep JSON", ["new", "--gltf", "bad.gltf", "-o", "out.wrinkle"], "nesting",
         lambda f: (f / "bad.gltf").write_text('{"asset": {"version": "2.0"}, "x": '
                                               + _deep(200000) + "}"), "out.wrinkle"),
    Case("glTF truncated", ["new", "--gltf", "bad.glb", "-o", "out.wrinkle"], "truncated",
         lambda f: (f / "bad.glb").write_bytes((f / "face.glb").read_bytes()[:5000]),
         "out.wrinkle"),
    Case("glTF that is a PNG", ["new", "--gltf", "bad.gltf", "-o", "out.wrinkle"],
         "not a glTF", lambda f: (f / "bad.gltf").write_bytes(png_claiming(4, 4)),
         "out.wrinkle"),
    Case("project truncated", ["export", "bad.wrinkle", "--gltf", "out.glb"], "truncated",
         lambda f: (f / "bad.wrinkle").write_bytes((f / "p.wrinkle").read_bytes()[:9000]),
         "out.glb"),
    Case("project member escaping the archive", ["export", "bad.wrinkle", "--gltf", "out.glb"],
         "unsafe", lambda f: rewrite_project(f / "p.wrinkle", f / "bad.wrinkle",
                                             members={"../evil.txt": b"x"}), "out.glb"),
    _new_mesh(
        "OBJ face index out of range", "bad.obj",
        "bad.obj", lambda f: (f / "bad.obj").write_text("v 0 0 0\nvt 0 0\nf 1/1 2/1 9/1\n")),
    # numbers beyond 32-bit floats: numpy warned as they were cast (issue #30)
    _new_mesh(
        "OBJ vertex of 1e39", "bad.obj",
        "vertex 2 (line 2) is outside the range of 32-bit floats",
        _text("bad.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n")),
    _new_mesh(
        "OBJ texture coordinate of -1e39", "bad.obj",
        "texture coordinate 2 (line 5) is outside the range of 32-bit floats",
        _text("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 0 -1e39\nf 1/1 2/2 3/1\n")),
    Case("OBJ key pose of 1e39", ["new", "--mesh", "face.obj", "--pose", "smile=pose.obj", "-o",
                                  "out.wrinkle"],
         "pose.obj: vertex 2 (line 3) is outside the range of 32-bit floats",
         _pose_beyond_float32, "out.wrinkle"),
    _new_mesh(
        "PLY double vertex of 1e39", "bad.ply",
        "vertex 2 is outside the range of 32-bit floats",
        _ply("double", ["0 0 0 0 0", "1e39 0 0 1 0", "0 1 0 0 1"])),
    _new_mesh(
        "PLY double UV of 1e39", "bad.ply",
        "the texture coordinate of vertex 3 is outside the range of 32-bit floats",
        _ply("double", ["0 0 0 0 0", "1 0 0 1 0", "0 1 0 0 1e39"])),
    _new_mesh(
        "PLY float vertex of 1e39", "bad.ply",
        "vertex 2 has a non-finite coordinate",
        _ply("float", ["0 0 0 0 0", "1e39 0 0 1 0", "0 1 0 0 1"])),
    _new_mesh(
        "PLY float UV of NaN", "bad.ply",
        "vertex 2 has a non-finite texture coordinate",
        _ply("float", ["0 0 0 0 0", "1 0 0 nan 0", "0 1 0 0 1"])),
    # 32-bit floats, but past what 32-bit geometry can square: numpy warned of an overflow in
    # the normals (issue #30)
    _new_mesh(
        "OBJ vertex of 1e10", "bad.obj",
        "the mesh has a coordinate of 1e+10 at vertex 1: the studio takes coordinates up to 1e+09",
        _text("bad.obj", "v 0 0 0\nv 1e10 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n")),
    Case("project positions of 1e30", ["export", "bad.wrinkle", "--gltf", "out.glb"],
         "the studio takes coordinates up to 1e+09", _rest_scaled(1e30), "out.glb"),
    _new_mesh(
        "OFF vertex of 1e39", "bad.off",
        "vertex 2 is outside the range of 32-bit floats",
        _text("bad.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n")),
]


def make_case(case: Case, folder: Path) -> None:
    write_base(folder)
    if case.make is not None:
        case.make(folder)

