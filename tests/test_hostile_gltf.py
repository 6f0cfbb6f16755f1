"""Hostile glTF files (issue #39), each built here to probe one rule and run through the real
command line in a subprocess under a memory limit: exit code 2 (or 0 for a file that is valid
though unusual), exactly one line on stderr, no traceback, no warning (``-W error``), no control
character in anything printed, under 500 MB of address space and 30 s.

The files are generated in each test's folder from a small face (an 8 × 8 grid on a dome, UVs,
one morph target), so nothing large is stored in the repository: the biggest is a PNG that
claims 8192² pixels at 16 bits in a few hundred kB, or an 11 MB .gltf built in a second.
"""

from __future__ import annotations

import base64
import functools
import json
import os
import resource
import struct
import subprocess
import sys
import time
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from studio.core.files.png import SIGNATURE
from studio.core.project.reader import load_project
from tests.gltf_avatar import glb_bytes

ROOT = Path(__file__).resolve().parents[1]
ADDRESS_SPACE_MB = 500  # the bound, as a hard limit: past it the child gets MemoryError
SECONDS = 30  # the bound on one file
# The child prints its peak memory and time on its last stderr line, which the test removes.
RUNNER = ("import sys, time\n"
          "from studio.cli import main\n"
          "start = time.perf_counter()\n"
          "try:\n"
          "    code = main(sys.argv[1:])\n"
          "finally:\n"
          "    with open('/proc/self/status') as status:\n"
          "        text = status.read()\n"
          "    peak = int(text.split('VmHWM:')[1].split()[0])\n"
          "    sys.stderr.write(f'\\nPEAK_RSS_KB {peak} {time.perf_counter() - start:.3f}\\n')\n"
          "sys.exit(code)\n")


@dataclass
class Result:
    code: int
    stderr: list[str]  # its lines, without the child's report
    stdout: str
    peak_mb: float
    seconds: float


def _limit_memory() -> None:  # runs in the child before exec
    limit = ADDRESS_SPACE_MB << 20
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def run_cli(args: list[str], cwd: Path, env: dict[str, str] | None = None) -> Result:
    """The command line on ``args`` in a child limited to ADDRESS_SPACE_MB of address space
    (one BLAS thread and two malloc arenas: each thread reserves address space it never
    uses), warnings as errors; a hang fails the test at SECONDS."""
    child_env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1",
                     OMP_NUM_THREADS="1", MALLOC_ARENA_MAX="2", **(env or {}))
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-W", "error", "-c", RUNNER, *args], cwd=cwd,
                          env=child_env, capture_output=True, text=True, timeout=SECONDS,
                          preexec_fn=_limit_memory)
    seconds = time.perf_counter() - start
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    peak = 0.0
    if lines and lines[-1].startswith("PEAK_RSS_KB"):
        peak = int(lines.pop().split()[1]) / 1024
    report = os.environ.get("WRINKLE_HOSTILE_REPORT")  # figures for docs/reliability.md
    if report:
        with open(report, "a") as out:
            test = os.environ.get("PYTEST_CURRENT_TEST", "").split(" ")[0].split("::")[-1]
            out.write(f"{test}\t{args[0]}\t{done.returncode}\t{peak:.0f} MB\t{seconds:.2f} s\n")
    return Result(done.returncode, lines, done.stdout, peak, seconds)


def clean(text: str) -> bool:
    """No control or format character but the newlines between lines (an ANSI escape, a
    carriage return, a bidirectional override …)."""
    import unicodedata

    return not any(unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp") and c != "\n"
                   for c in text)


def check_rule(result: Result, code: int = 2, needle: str = "") -> str:
    """The issue's rule for every file; returns the error line ('' on success)."""
    assert result.code == code, (result.code, result.stderr, result.stdout[-2000:])
    assert result.seconds < SECONDS
    assert 0 < result.peak_mb < ADDRESS_SPACE_MB
    assert clean(result.stdout), result.stdout
    assert all(clean(line) for line in result.stderr), result.stderr
    assert not any(line.lstrip().startswith("Traceback") for line in result.stdout.splitlines())
    if code == 0:
        assert result.stderr == []
        return ""
    assert len(result.stderr) == 1, result.stderr
    line = result.stderr[0]
    assert line.startswith("wrinkle-studio: error: "), line  # not a traceback's, a warning's
    assert needle in line, line
    return line


# --- building glTF files -------------------------------------------------------------------
class Gltf:
    """A glTF document and its one binary buffer, written as a .glb or a .gltf (data URI)."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.doc: dict = {"asset": {"version": "2.0"}, "accessors": [], "bufferViews": [],
                          "buffers": [{"byteLength": 0}]}

    def view(self, data: bytes) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob),
                                        "byteLength": len(data)})
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array: np.ndarray | None, kind: str, component: int = 5126,
                 **fields: object) -> int:
        """An accessor of ``array`` (float32, or the component type's integers) on its own
        view; ``None`` for one with no view (``fields`` then says what it claims)."""
        spec: dict = {"componentType": component, "type": kind}
        if array is not None:
            spec.update(bufferView=self.view(np.ascontiguousarray(array).tobytes()),
                        count=len(array))
        spec.update(fields)
        self.doc["accessors"].append(spec)
        return len(self.doc["accessors"]) - 1

    def sparse(self, count: int, kind: str, indices: list[int], values: np.ndarray) -> int:
        """A sparse accessor with no base view: ``count`` elements, zeros but ``values``."""
        return self.accessor(None, kind, count=count, sparse={
            "count": len(indices),
            "indices": {"bufferView": self.view(np.array(indices, np.uint32).tobytes()),
                        "componentType": 5125},
            "values": {"bufferView": self.view(np.ascontiguousarray(values,
                                                                    np.float32).tobytes())}})

    def write(self, path: Path) -> Path:
        self.doc["buffers"][0]["byteLength"] = len(self.blob)
        if path.suffix == ".gltf":
            self.doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                             + base64.b64encode(bytes(self.blob)).decode())
            path.write_text(json.dumps(self.doc))
            return path
        path.write_bytes(glb_bytes(self.doc, bytes(self.blob)))
        return path


def grid(n: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions on a face-sized dome (metres), UVs (v down, as glTF stores them), triangles."""
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    x, y = (u - 0.5) * 0.16, (v - 0.5) * 0.2
    z = 0.08 * np.sqrt(np.clip(1 - (x / 0.1) ** 2 - (y / 0.12) ** 2, 0, 1))
    positions = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    uvs = np.stack([u, 1 - v], -1).reshape(-1, 2).astype(np.float32)
    q = np.arange(n * n).reshape(n, n)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return positions, uvs, triangles.astype(np.uint32)


def face(n: int = 8, name: str = "head", targets: int = 1) -> tuple[Gltf, dict]:
    """A valid scene: one node showing one mesh of an ``n`` × ``n`` grid with ``targets``
    morph targets (the first lifts the dome a little); returns the file and its primitive."""
    g = Gltf()
    positions, uvs, triangles = grid(n)
    offsets = np.zeros_like(positions)
    offsets[:, 1] = positions[:, 2] * 0.1
    prim = {"attributes": {"POSITION": g.accessor(positions, "VEC3"),
                           "TEXCOORD_0": g.accessor(uvs, "VEC2")},
            "indices": g.accessor(triangles.ravel(), "SCALAR", 5125)}
    if targets:
        moved = g.accessor(offsets, "VEC3")
        prim["targets"] = [{"POSITION": moved}] + [
            {"POSITION": g.accessor(offsets * (i + 2), "VEC3")} for i in range(targets - 1)]
    g.doc.update(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0, "name": name}],
                 meshes=[{"name": name, "primitives": [prim],
                          "extras": {"targetNames": [f"pose{i}" for i in range(targets)]}}])
    return g, prim


def new(tmp_path: Path, g: Gltf, name: str = "face.glb", *extra: str,
        env: dict[str, str] | None = None) -> Result:
    g.write(tmp_path / name)
    return run_cli(["new", "--gltf", name, "-o", "out.wrinkle", *extra], tmp_path, env)


def refused(tmp_path: Path, g: Gltf, needle: str, name: str = "face.glb", *extra: str,
            env: dict[str, str] | None = None) -> str:
    """The file is refused by the rule, and no project is written."""
    line = check_rule(new(tmp_path, g, name, *extra, env=env), 2, needle)
    assert not (tmp_path / "out.wrinkle").exists()
    return line


def animate(g: Gltf, times: int, input_accessor: int | None = None,
            output_accessor: int | None = None) -> None:
    """A weights animation on node 0 whose sampler reads the accessors given (by default a
    sparse one of ``times`` key times and one of ``times`` × targets weights)."""
    targets = len(g.doc["meshes"][0]["primitives"][0].get("targets", []))
    if input_accessor is None:
        input_accessor = g.sparse(times, "SCALAR", [times - 1], np.array([[1.0]]))
    if output_accessor is None:
        output_accessor = g.sparse(times * targets, "SCALAR", [0], np.array([[1.0]]))
    g.doc["animations"] = [{"channels": [{"sampler": 0, "target": {"node": 0,
                                                                    "path": "weights"}}],
                            "samplers": [{"input": input_accessor,
                                          "output": output_accessor}]}]


@functools.lru_cache(maxsize=8)  # the same few images serve several tests: made once
def png_rows(width: int, height: int, depth: int, colour: int, row_filter: int = 0) -> bytes:
    """A valid PNG of zeros, compressed a row at a time (an 8192² 16-bit RGBA image is 537 MB
    raw and a few hundred kB here, built without holding the raw rows); every row declares
    ``row_filter`` (of zeros, any filter decodes to zeros)."""
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    row = bytes([row_filter]) + b"\0" * (width * channels * depth // 8)
    pack = zlib.compressobj(9)
    idat = b"".join(pack.compress(row) for _ in range(height)) + pack.flush()

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data)))

    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    return SIGNATURE + chunk(b"IHDR", header) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def textured(g: Gltf, prim: dict, png: bytes) -> None:
    """The primitive's material shows ``png`` (embedded in the buffer) as its base colour."""
    g.doc.update(images=[{"bufferView": g.view(png), "mimeType": "image/png"}],
                 textures=[{"source": 0}],
                 materials=[{"name": "skin", "pbrMetallicRoughness": {
                     "baseColorTexture": {"index": 0}}}])
    prim["material"] = 0


# --- the base file is read, so that a refusal below is the rule's, not a broken base ----------
def test_the_base_face_is_read(tmp_path: Path) -> None:
    g, _ = face()
    result = new(tmp_path, g)
    check_rule(result, 0)
    assert "key poses: pose0" in result.stdout
    assert result.peak_mb < 200


# --- 1. memory: budgets checked on what the file declares, before allocating ----------------
def test_a_sparse_accessor_without_a_base_claiming_20m_elements(tmp_path: Path) -> None:
    g, prim = face()
    prim["targets"][0]["POSITION"] = g.sparse(20_000_000, "VEC3", [0], np.ones((1, 3)))
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_GLTF_VALUES")


def test_morph_targets_sharing_one_accessor_over_the_pose_limit(tmp_path: Path) -> None:
    g, prim = face(150)  # checked after reading 1 500 × 22 500 offsets: 809 MB (issue #39)
    prim["targets"] = prim["targets"] * 1500
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_POSES")


def test_morph_targets_sharing_one_accessor_over_the_number_budget(tmp_path: Path) -> None:
    g, prim = face(150)  # 22 500 vertices × 900 targets × 3: 61 million numbers, on paper
    prim["targets"] = prim["targets"] * 900
    g.doc["meshes"][0]["extras"]["targetNames"] = [f"t{i}" for i in range(900)]
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_GLTF_VALUES")


def test_a_head_at_the_number_budget_is_read_in_bounded_memory(tmp_path: Path) -> None:
    """30 000 vertices with 170 morph targets of their own: 15.6 million numbers, just inside
    the budget, read, welded and saved under the memory limit (a hundred targets once took
    485 MB: the welding sorted every vertex's offsets as one record)."""
    g, _ = face(173, targets=170)
    result = new(tmp_path, g)
    check_rule(result, 0)
    assert "170 morph targets" in result.stdout


def test_a_studio_file_with_targets_sharing_one_accessor(tmp_path: Path) -> None:
    """The studio's own files are read by another path (extras.wrinkleStudio marks them, and
    any file can claim it): a thousand key poses made of one shared accessor are refused as
    they are read, before the thousand copies are made."""
    g, prim = face(150)
    prim["targets"] = prim["targets"] * 1000
    g.doc["extras"] = {"wrinkleStudio": {"name": "face"}}
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_GLTF_VALUES")


def test_one_mesh_placed_by_a_thousand_nodes_over_the_budget(tmp_path: Path) -> None:
    g, _ = face(100)  # 10 000 vertices placed 1 000 times
    g.doc["nodes"] = [{"children": list(range(1, 1001))}] + [
        {"mesh": 0, "translation": [i * 0.3, 0.0, 0.0]} for i in range(1000)]
    line = refused(tmp_path, g, "WRINKLE_STUDIO_MAX_GLTF_VALUES")
    assert "placed by node" in line


def test_a_png_inside_the_pixel_budget_decoding_to_half_a_gigabyte(tmp_path: Path) -> None:
    g, prim = face()
    textured(g, prim, png_rows(8192, 8192, 16, 6))  # 8192² RGBA at 16 bits: 512 MiB decoded
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_IMAGE_BYTES")


@pytest.mark.parametrize("png", [(4096, 4096, 16, 6, 2), (8192, 4096, 8, 6, 4)],
                         ids=["4096x4096-RGBA-16bit-Up", "8192x4096-RGBA-8bit-Paeth"])
def test_a_png_at_the_image_budget_is_read_in_bounded_memory(tmp_path: Path, png: tuple
                                                             ) -> None:
    """128 MiB decoded, the most one image may be: decoded, made a project and saved under
    the memory limit (Pillow's 8-bit decoding and the Paeth filter once cost 3–6 copies)."""
    g, prim = face()
    textured(g, prim, png_rows(*png))
    check_rule(new(tmp_path, g), 0)


def maps(g: Gltf, prim: dict, count: int) -> None:
    """The primitive's material shows ``count`` 4096² RGBA 16-bit maps (128 MiB each,
    decoded): base colour, normal and the studio's wrinkled normal map, as many as asked."""
    pngs = [png_rows(4096, 4096, 16, 6, 2) for _ in range(count)]
    g.doc.update(images=[{"bufferView": g.view(png), "mimeType": "image/png"} for png in pngs],
                 textures=[{"source": i} for i in range(count)])
    material: dict = {"name": "skin", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}
    if count > 1:
        material["normalTexture"] = {"index": 1}
    if count > 2:
        material["extras"] = {"wrinkleNormalTexture": {"index": 2}}
    g.doc["materials"] = [material]
    prim["material"] = 0


def test_two_maps_at_the_image_budget_are_read_in_bounded_memory(tmp_path: Path) -> None:
    g, prim = face()
    maps(g, prim, 2)
    check_rule(new(tmp_path, g), 0)


def test_three_maps_over_the_files_image_budget(tmp_path: Path) -> None:
    g, prim = face()
    maps(g, prim, 3)
    refused(tmp_path, g, "WRINKLE_STUDIO_MAX_GLTF_IMAGE_BYTES")


def test_an_11_mb_gltf_with_a_data_uri_is_read_in_little_memory(tmp_path: Path) -> None:
    g, _ = face()
    g.view(np.random.default_rng(0).bytes(8_000_000))  # unused: 10.7 MB of base64
    result = new(tmp_path, g, "face.gltf")
    check_rule(result, 0)
    assert (tmp_path / "face.gltf").stat().st_size > 10_000_000
    assert result.peak_mb < 250  # the nesting pre-scan once cost 125 bytes a byte: 1.3 GB


def test_a_sparse_animation_claiming_a_million_keys(tmp_path: Path) -> None:
    g, _ = face(targets=2)
    animate(g, 1_000_000)
    assert "face.glb: " in refused(tmp_path, g, "WRINKLE_STUDIO_MAX_TIMELINE_KEYS")


# --- 2. what `new` writes obeys the reader's budgets ------------------------------------------
def test_new_never_writes_a_project_its_reader_refuses(tmp_path: Path) -> None:
    """With the reader's container budget lowered to 1 000, an animation of 600 samples of two
    poses (1 200 keys, each a JSON list) is refused by the writer, not written unreadable."""
    g, _ = face(targets=2)
    times = g.accessor(np.arange(600, dtype=np.float32)[:, None] / 24, "SCALAR")
    weights = g.accessor(np.zeros((1200, 1), np.float32), "SCALAR")
    animate(g, 600, times, weights)
    env = {"WRINKLE_STUDIO_MAX_JSON_CONTAINERS": "1000"}
    result = new(tmp_path, g, env=env)
    if result.code == 0:  # written: then it must be readable under the same budgets
        os.environ.update(env)
        try:
            load_project(tmp_path / "out.wrinkle")
        finally:
            del os.environ["WRINKLE_STUDIO_MAX_JSON_CONTAINERS"]
    check_rule(result, 2, "WRINKLE_STUDIO_MAX_JSON_CONTAINERS")
    assert not (tmp_path / "out.wrinkle").exists()


# --- 3. no traceback: timeline lengths bounded -------------------------------------------------
def test_an_animation_key_at_3e38_seconds(tmp_path: Path) -> None:
    g, _ = face()
    times = g.accessor(np.array([[0.0], [3e38]], np.float32), "SCALAR")
    weights = g.accessor(np.array([[0.0], [1.0]], np.float32), "SCALAR")
    animate(g, 2, times, weights)
    assert "face.glb: " in refused(tmp_path, g, "WRINKLE_STUDIO_MAX_FRAMES")


def test_render_of_a_timeline_ending_past_2_to_the_63_frames(tmp_path: Path) -> None:
    """A project whose timeline ends at frame 7.2e39 (as the animation above made before it
    was bounded): `render --gif` counted its frames with len(range(...)), an OverflowError."""
    g, _ = face()
    check_rule(new(tmp_path, g), 0)
    from tests.bad_inputs import rewrite_project

    rewrite_project(tmp_path / "out.wrinkle", tmp_path / "long.wrinkle",
                    lambda doc: doc["timeline"].update(end=7_200_000_000 * 10 ** 30))
    result = run_cli(["render", "long.wrinkle", "--size", "64x48", "--gif", "out.gif"],
                     tmp_path)
    check_rule(result, 2, "WRINKLE_STUDIO_MAX_FRAMES")


# --- 4. no noise: overflow said in one line, names from the file escaped ------------------------
def test_node_transforms_overflowing_float32(tmp_path: Path) -> None:
    g, _ = face()
    g.doc["scenes"] = [{"nodes": [1]}]
    g.doc["nodes"] = [{"mesh": 0, "scale": [1e30, 1e30, 1e30]},
                      {"children": [0], "scale": [1e20, 1e20, 1e20]}]
    refused(tmp_path, g, "the studio takes coordinates up to 1e+09")


def test_node_transforms_overflowing_float64(tmp_path: Path) -> None:
    g, _ = face()
    g.doc["scenes"] = [{"nodes": [1]}]
    g.doc["nodes"] = [{"mesh": 0, "scale": [1e200, 1e200, 1e200]},
                      {"children": [0], "scale": [1e200, 1e200, 1e200]}]
    refused(tmp_path, g, "node 0's place in the scene overflows")


def test_a_texture_transform_overflowing_the_uvs(tmp_path: Path) -> None:
    g, prim = face()
    textured(g, prim, png_rows(4, 4, 8, 2))
    g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        "KHR_texture_transform": {"scale": [1e308, 1e308]}}
    refused(tmp_path, g, "TEXCOORD_0 (through its KHR_texture_transform) has the texture "
            "coordinate (0, 1e+308) at vertex 0")


def test_uvs_beyond_32_bit_floats(tmp_path: Path) -> None:
    g, prim = face()
    prim["attributes"]["TEXCOORD_0"] = g.accessor(np.full((64, 2), 3e38, np.float32), "VEC2")
    refused(tmp_path, g, "TEXCOORD_0 has the texture coordinate (3e+38, 3e+38) at vertex 0")


HOSTILE = "face\nTraceback (most recent call last):\x1b[2J\x1b[31m\u202e\r"


def test_names_from_the_file_are_escaped_on_success(tmp_path: Path) -> None:
    g, _ = face(name=HOSTILE)
    g.doc["meshes"][0]["extras"]["targetNames"] = ["smile\x1b]0;pwned\x07\nfrown"]
    result = new(tmp_path, g)
    check_rule(result, 0)
    assert "face\\x0aTraceback" in result.stdout
    assert "smile\\x1b]0;pwned\\x07\\x0afrown" in result.stdout


def test_names_from_the_file_are_escaped_in_keeps_list(tmp_path: Path) -> None:
    g, _ = face(name=HOSTILE)
    line = refused(tmp_path, g, "--keep nose", "face.glb", "--keep", "nose")
    assert "face\\x0aTraceback" in line


def test_extension_names_and_uris_are_escaped(tmp_path: Path) -> None:
    g, _ = face()
    g.doc["extensionsRequired"] = ["EXT_\x1b[2Jevil\nTraceback"]
    assert "EXT_\\x1b[2Jevil\\x0aTraceback" in refused(tmp_path, g, "requires the glTF")
    g, prim = face()
    g.doc.update(images=[{"uri": "missing\n\x1b[2J.png"}], textures=[{"source": 0}],
                 materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])
    prim["material"] = 0
    result = new(tmp_path, g)  # a missing texture is said, not refused (issue 46)
    check_rule(result, 0)
    assert "image missing\\x0a\\x1b[2J.png of material (unnamed) not found" in result.stdout


def test_renders_pose_list_is_escaped(tmp_path: Path) -> None:
    """A project whose pose name holds an ANSI escape and a newline (another tool wrote it):
    `render --pose` with a name it does not have lists the poses on one line."""
    g, _ = face()
    check_rule(new(tmp_path, g), 0)
    from tests.bad_inputs import rewrite_project

    rewrite_project(tmp_path / "out.wrinkle", tmp_path / "named.wrinkle",
                    lambda doc: doc.update(poses=[HOSTILE]))
    result = run_cli(["render", "named.wrinkle", "--pose", "nope", "-o", "x.png"], tmp_path)
    assert "face\\x0aTraceback" in check_rule(result, 2, "nope")


# --- 5. the right words ----------------------------------------------------------------------
def test_a_scene_that_shows_no_mesh_says_so(tmp_path: Path) -> None:
    g, _ = face()
    g.doc["nodes"] = [{"name": "empty"}]
    line = refused(tmp_path, g, "the scene shows no mesh")
    assert "texture coordinates" not in line


def test_a_node_cycle_without_a_scene_says_so(tmp_path: Path) -> None:
    g, _ = face()
    del g.doc["scene"], g.doc["scenes"]
    g.doc["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
    line = refused(tmp_path, g, "cycle")
    assert "texture coordinates" not in line


def test_a_mesh_of_points_is_no_triangle_mesh(tmp_path: Path) -> None:
    g, prim = face()
    prim["mode"] = 0  # points, with UVs
    line = refused(tmp_path, g, "the file holds no triangle mesh")
    assert "texture coordinates" not in line


def test_a_frame_number_of_thousands_of_digits(tmp_path: Path) -> None:
    g, _ = face()
    animate(g, 2)
    g.doc["animations"][0]["extras"] = {"wrinkleStudio": {"end": "9" * 5000}}
    line = refused(tmp_path, g, "is not a frame number")
    assert "sys.set_int_max_str_digits" not in line


def test_a_missing_image_is_said_and_the_head_opens_plain(tmp_path: Path) -> None:
    """Issue 46: a texture left behind is a hand-over slip, not a broken head (Blender opens
    the material untextured): the report names the image, called an image, and the project
    is written with plain skin."""
    g, prim = face()
    g.doc.update(images=[{"uri": "skin.png"}], textures=[{"source": 0}],
                 materials=[{"name": "Skin",
                             "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])
    prim["material"] = 0
    result = new(tmp_path, g, "face.gltf")
    check_rule(result, 0)
    assert ("diffuse map: image skin.png of material Skin not found beside the file: plain "
            "skin colour") in result.stdout, result.stdout
    assert (tmp_path / "out.wrinkle").exists()


def test_an_image_that_is_no_image_is_said_and_the_head_opens_plain(tmp_path: Path) -> None:
    g, prim = face()
    (tmp_path / "skin.png").write_bytes(b"not a picture at all")
    g.doc.update(images=[{"uri": "skin.png"}], textures=[{"source": 0}],
                 materials=[{"name": "Skin", "normalTexture": {"index": 0}}])
    prim["material"] = 0
    result = new(tmp_path, g, "face.gltf")
    check_rule(result, 0)
    assert "normal map: image skin.png of material Skin is unreadable (not an image" in \
        result.stdout, result.stdout
    assert ": a flat normal map" in result.stdout


def test_a_percent_encoded_uri_names_its_file(tmp_path: Path) -> None:
    """glTF URIs are URIs: "my%20face.bin" is the file "my face.bin" beside the glTF (and an
    encoded "%2e%2e/" is still refused as outside its folder)."""
    g, _ = face()
    (tmp_path / "my face.bin").write_bytes(bytes(g.blob))
    g.write(tmp_path / "face.gltf")
    doc = json.loads((tmp_path / "face.gltf").read_text())
    doc["buffers"][0]["uri"] = "my%20face.bin"
    (tmp_path / "face.gltf").write_text(json.dumps(doc))
    check_rule(run_cli(["new", "--gltf", "face.gltf", "-o", "out.wrinkle"], tmp_path), 0)
    doc["buffers"][0]["uri"] = "%2e%2e/my%20face.bin"
    (tmp_path / "face.gltf").write_text(json.dumps(doc))
    (tmp_path / "out.wrinkle").unlink()
    check_rule(run_cli(["new", "--gltf", "face.gltf", "-o", "out.wrinkle"], tmp_path), 2,
               "refers outside the file's folder: '%2e%2e/my%20face.bin'")


def test_a_file_uri_is_an_unsupported_scheme(tmp_path: Path) -> None:
    g, _ = face()
    g.doc["buffers"] = [{"uri": "file:///etc/hostname"}]
    line = refused(tmp_path, g, "unsupported URI scheme 'file:'", "face.glb")
    assert "does not exist" not in line


def test_a_5000_digit_integer_does_not_suggest_python_settings(tmp_path: Path) -> None:
    g, _ = face()
    g.write(tmp_path / "face.gltf")
    text = (tmp_path / "face.gltf").read_text().replace('"scene": 0', '"scene": ' + "9" * 5000)
    (tmp_path / "face.gltf").write_text(text)
    line = check_rule(run_cli(["new", "--gltf", "face.gltf", "-o", "out.wrinkle"], tmp_path), 2,
                      "thousands of digits")
    assert "sys.set_int_max_str_digits" not in line


# --- 6. invalid files are refused --------------------------------------------------------------
def test_unsigned_byte_positions_need_mesh_quantization(tmp_path: Path) -> None:
    def file(declared: bool) -> Gltf:
        g, prim = face(targets=0)
        positions = np.round(grid()[0] * 1000 + 120).astype(np.uint8)
        prim["attributes"]["POSITION"] = g.accessor(
            np.hstack([positions, np.zeros((len(positions), 1), np.uint8)]), "VEC3", 5121)
        g.doc["bufferViews"][-1]["byteStride"] = 4
        g.doc["accessors"][-1]["count"] = len(positions)
        if declared:
            g.doc["extensionsUsed"] = g.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
        return g

    refused(tmp_path, file(False), "POSITION (accessor 3) is stored as unsigned bytes, which "
            "glTF allows only in a file that declares KHR_mesh_quantization")
    check_rule(new(tmp_path, file(True)), 0)
    (tmp_path / "out.wrinkle").unlink()
    g, prim = face()  # a morph target's offsets too
    prim["targets"][0]["POSITION"] = g.accessor(np.zeros((64, 4), np.int8), "VEC3", 5120)
    g.doc["bufferViews"][-1]["byteStride"] = 4
    refused(tmp_path, g, "morph target 'pose0' (accessor 4) is stored as signed bytes, which "
            "glTF allows only in a file that declares KHR_mesh_quantization")


# --- 7. speed: scenes of many nodes cost work by what they hold, not by their depth ---------------
# (placing them took 12 and 6.6 s before issue #39: a multiplication per level and per node)


def empty_nodes(count: int = 200_000) -> Gltf:
    g, _ = face()
    g.doc["scenes"] = [{"nodes": list(range(count + 1))}]
    g.doc["nodes"] += [{} for _ in range(count)]
    return g


def nested_levels(count: int = 100_000) -> Gltf:
    """The face's node under ``count`` - 1 others, each a child of the one before, each moving
    its child a micrometre."""
    g, _ = face()
    g.doc["scenes"] = [{"nodes": [1]}]
    g.doc["nodes"] += [{"children": [i + 2], "translation": [0.0, 1e-6, 0.0]}
                       for i in range(count - 2)] + [{"children": [0]}]
    return g


def placing_work(tmp_path: Path, g: Gltf, monkeypatch) -> tuple[int, int]:
    """(matrices kept, rounds of multiplying them) to walk the scene and place its meshes:
    the work, counted rather than timed (the machine is shared)."""
    from studio.core.formats.gltf import scene
    from studio.core.formats.gltf.container import _Gltf

    work = []
    real = scene.chain_products

    def counted(world, up):
        work.append((len(world), real(world, up)))
        return work[-1][1]

    monkeypatch.setattr(scene, "chain_products", counted)
    placed = scene.placed_meshes(_Gltf(g.write(tmp_path / "scene.glb")))
    assert [index for index, _, _ in placed] == [0]
    [done] = work
    return done


def test_two_million_root_nodes_without_a_scene(tmp_path: Path) -> None:
    """Just inside the JSON's container budget: every node a root. The roots are walked one
    at a time (a list of two million of them with a matrix each took 480 MB)."""
    g, _ = face()
    del g.doc["scene"], g.doc["scenes"]
    g.doc["nodes"] += [{}] * 1_990_000
    result = new(tmp_path, g)
    check_rule(result, 0)
    assert result.peak_mb < 300


def test_200000_empty_nodes(tmp_path: Path, monkeypatch) -> None:
    kept, rounds = placing_work(tmp_path, empty_nodes(), monkeypatch)
    assert kept <= 2 and rounds <= 1  # the empty nodes are never multiplied
    check_rule(new(tmp_path, empty_nodes()), 0)


def test_100000_nested_levels(tmp_path: Path, monkeypatch) -> None:
    g = nested_levels()
    kept, rounds = placing_work(tmp_path, g, monkeypatch)
    assert kept >= 99_999 and rounds <= 18  # log2 of the chain, not one round per level
    result = new(tmp_path, g)
    check_rule(result, 0)
    placed = load_project(tmp_path / "out.wrinkle").mesh.rest
    np.testing.assert_allclose(placed.mean(axis=0)[1] - grid()[0].mean(axis=0)[1],
                               (100_000 - 2) * 1e-6, rtol=1e-4)  # every level's micrometre
