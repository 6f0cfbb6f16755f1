"""The glTF container reader (``_Gltf`` in core/formats/gltf/codec.py) on small hand-made files.

Every file here is built byte by byte (JSON plus ``numpy`` bytes, GLB headers with ``struct``),
so the expected values are known without the reader: each component type, interleaved views
with a byteStride, accessor and view offsets, normalized integers, embedded (data: URI), GLB
(BIN chunk) and external .bin buffers, and images. Each broken file must raise ``MeshError``
naming the file and the exact problem, because that text is all a user sees when an import
fails: truncated GLB files, bad chunks, references that do not exist, views and accessors that
reach past their data, strides out of range, and the size budgets.
"""

from __future__ import annotations

import base64
import json
import struct
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from studio.core.files.errors import ImageError, MeshError
from studio.core.files.png import encode_png
from studio.core.formats.gltf.codec import BIN_CHUNK, JSON_CHUNK, _Gltf, _rgb

pytestmark = pytest.mark.core

ASSET = {"version": "2.0"}


def data_uri(blob: bytes) -> str:
    return "data:application/octet-stream;base64," + base64.b64encode(blob).decode()


def write_gltf(path: Path, doc: object) -> Path:
    path.write_text(json.dumps(doc))
    return path


def glb(chunks: list[tuple[int, bytes]], length: int | None = None, version: int = 2) -> bytes:
    """A GLB file: the 12-byte header, then each (kind, payload) chunk with its 8-byte header."""
    body = b"".join(struct.pack("<II", len(data), kind) + data for kind, data in chunks)
    total = 12 + len(body) if length is None else length
    return b"glTF" + struct.pack("<II", version, total) + body


def json_chunk(doc: object) -> tuple[int, bytes]:
    text = json.dumps(doc).encode()
    return JSON_CHUNK, text + b" " * (-len(text) % 4)


def expect(path: Path, problem: str, call: Callable[[], object]) -> MeshError:
    """``call`` raises a MeshError whose text is ``path: problem``."""
    with pytest.raises(MeshError) as info:
        call()
    assert info.value.problem == problem
    assert info.value.path == path
    assert str(info.value) == f"{path}: {problem}"
    return info.value


# The base document: twelve float32 numbers 0.5, 1.5, ... 11.5 in one view of 48 bytes, read by
# one VEC3 accessor of four elements.
FLOATS = np.arange(12, dtype=np.float32) + 0.5


def base_doc() -> dict:
    blob = FLOATS.tobytes()
    return {
        "asset": ASSET,
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}],
    }


def load(tmp_path: Path, doc: object, name: str = "face.gltf") -> tuple[_Gltf, Path]:
    path = write_gltf(tmp_path / name, doc)
    return _Gltf(path), path


def packed(tmp_path, accessors: list[tuple[dict, np.ndarray]]) -> _Gltf:
    """A file holding each array in its own 4-byte-aligned view, read by an accessor with the
    given fields (bufferView is filled in)."""
    blob, views, specs = b"", [], []
    for k, (spec, array) in enumerate(accessors):
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": array.nbytes})
        specs.append({"bufferView": k, **spec})
        blob += array.tobytes() + b"\0" * (-array.nbytes % 4)
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": views,
        "accessors": specs,
    }
    return load(tmp_path, doc)[0]


# --- decoding -------------------------------------------------------------------------------
def test_every_component_type_decodes_to_the_hand_made_values(tmp_path):
    arrays = [
        (5120, "VEC2", np.array([[-128, 0], [5, 127]], np.int8)),
        (5121, "SCALAR", np.array([[0], [200], [255]], np.uint8)),
        (5122, "VEC3", np.array([[-32768, 7, 32767]], np.int16)),
        (5123, "VEC4", np.array([[0, 1, 65535, 300], [9, 8, 7, 6]], np.uint16)),
        (5125, "SCALAR", np.array([[0], [4_000_000_000]], np.uint32)),
        (5126, "MAT2", np.array([[0.25, -1.5, 3.0, 1e-3]], np.float32)),
    ]
    g = packed(
        tmp_path,
        [({"componentType": c, "count": len(a), "type": kind}, a) for c, kind, a in arrays],
    )
    for k, (_, _, array) in enumerate(arrays):
        values = g.accessor(k)
        assert values.dtype == np.float64
        np.testing.assert_array_equal(values, array.astype(np.float64))


def test_interleaved_view_with_offsets_and_stride(tmp_path):
    # 8 padding bytes, then three vertices of [x y z u v] floats: stride 20 bytes.
    positions = np.array([[1, 2, 3], [4, 5, 6], [7, 8, 9]], np.float32)
    uvs = np.array([[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]], np.float32)
    blob = b"\xff" * 8 + np.hstack([positions, uvs]).astype(np.float32).tobytes()
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 8, "byteLength": 60, "byteStride": 20}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 3, "type": "VEC2"},
        ],
    }
    g, _ = load(tmp_path, doc)
    np.testing.assert_array_equal(g.accessor(0), positions.astype(np.float64))
    np.testing.assert_array_equal(g.accessor(1), uvs.astype(np.float64))


def test_an_accessor_offset_without_a_stride_and_a_single_element(tmp_path):
    doc = base_doc()
    doc["accessors"] = [
        {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 1, "type": "VEC4"}
    ]
    g, _ = load(tmp_path, doc)
    np.testing.assert_array_equal(g.accessor(0), [[2.5, 3.5, 4.5, 5.5]])


def test_the_smallest_and_largest_strides_are_allowed(tmp_path):
    blob = bytes(range(256))
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": 256, "uri": data_uri(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteLength": 12, "byteStride": 4},
            {"buffer": 0, "byteLength": 256, "byteStride": 252},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5121, "count": 3, "type": "VEC2"},
            {"bufferView": 1, "componentType": 5121, "count": 2, "type": "SCALAR"},
        ],
    }
    g, _ = load(tmp_path, doc)
    np.testing.assert_array_equal(g.accessor(0), [[0, 1], [4, 5], [8, 9]])
    np.testing.assert_array_equal(g.accessor(1), [[0], [252]])


def test_normalized_integers_scale_to_unit_range_and_floats_stay(tmp_path):
    arrays = [
        (5121, np.array([0, 51, 255], np.uint8), [0.0, 0.2, 1.0]),
        (5122, np.array([-32767, 0, 32767], np.int16), [-1.0, 0.0, 1.0]),
        (5120, np.array([-128, -127, 127], np.int8), [-1.0, -1.0, 1.0]),  # −128 clamps to −1
        (5123, np.array([0, 13107, 65535], np.uint16), [0.0, 0.2, 1.0]),
        (5126, np.array([1.5, -2.0, 300.0], np.float32), [1.5, -2.0, 300.0]),
    ]
    fields = {"count": 3, "type": "SCALAR", "normalized": True}
    g = packed(tmp_path, [({"componentType": c, **fields}, a) for c, a, _ in arrays])
    for k, (_, _, expected) in enumerate(arrays):
        np.testing.assert_allclose(g.accessor(k)[:, 0], expected, rtol=1e-12)


# --- buffers ----------------------------------------------------------------------------------
def test_a_buffer_without_byte_length_and_an_external_bin(tmp_path):
    values = np.array([1.0, 2.0, 3.0], np.float32)
    (tmp_path / "bin").mkdir()
    (tmp_path / "bin" / "data.bin").write_bytes(values.tobytes())
    doc = {
        "asset": ASSET,
        "buffers": [{"uri": "bin/data.bin"}, {"uri": data_uri(b"abcd")}],
        "bufferViews": [{"buffer": 0, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"}],
    }
    g, _ = load(tmp_path, doc)
    assert g.buffers == [values.tobytes(), b"abcd"]
    np.testing.assert_array_equal(g.accessor(0), [[1.0, 2.0, 3.0]])


@pytest.mark.parametrize(
    ("buffers", "problem"),
    [
        ({}, "'buffers' is not a JSON list"),
        ([5], "a buffer is not a JSON object"),
        ([{"byteLength": 4}], "a buffer has no data"),
        ([{"uri": 5}], "a buffer's uri is not text: 5"),
        (
            [{"uri": "data:application/octet-stream;base64"}],
            "a buffer's data URI is damaged (list index out of range)",
        ),
        ([{"byteLength": 10, "uri": data_uri(b"abcd")}], "a buffer declares 10 bytes but holds 4"),
        (
            [{"byteLength": "4", "uri": data_uri(b"abcd")}],
            "a buffer declares '4' bytes but holds 4",
        ),
        ([{"byteLength": -1, "uri": data_uri(b"abcd")}], "a buffer declares -1 bytes but holds 4"),
        (
            [{"uri": "../outside.bin"}],
            "a buffer refers outside the file's folder: '../outside.bin'",
        ),
    ],
)
def test_broken_buffers_are_named(tmp_path, buffers, problem):
    (tmp_path / "outside.bin").write_bytes(b"abcd")
    (tmp_path / "in").mkdir()
    path = tmp_path / "in" / "face.gltf"
    write_gltf(path, {"asset": ASSET, "buffers": buffers})
    expect(path, problem, lambda: _Gltf(path))


def test_a_missing_external_bin_names_the_bin(tmp_path):
    path = write_gltf(tmp_path / "face.gltf", {"asset": ASSET, "buffers": [{"uri": "gone.bin"}]})
    expect(
        (tmp_path / "gone.bin").resolve(),
        "the buffer 'gone.bin' of the glTF does not exist",
        lambda: _Gltf(path),
    )


def test_an_external_bin_over_the_file_budget(tmp_path, monkeypatch):
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FILE_BYTES", "200")
    (tmp_path / "big.bin").write_bytes(bytes(1000))
    path = write_gltf(tmp_path / "face.gltf", {"asset": ASSET, "buffers": [{"uri": "big.bin"}]})
    expect(
        (tmp_path / "big.bin").resolve(),
        "the buffer 'big.bin' of the glTF is 1000 bytes, more than the limit of 200 bytes "
        "(set WRINKLE_STUDIO_MAX_FILE_BYTES to raise it)",
        lambda: _Gltf(path),
    )


# --- the document -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "doc",
    [
        {"buffers": []},
        {"asset": "2.0"},
        {"asset": {"version": "1.0"}},
        {"asset": {}},
        [1, 2],
    ],
)
def test_a_document_that_is_not_gltf_2(tmp_path, doc):
    path = write_gltf(tmp_path / "face.gltf", doc)
    expect(path, "not a glTF 2.0 file (asset.version is not 2.x)", lambda: _Gltf(path))


def test_text_that_is_not_json(tmp_path):
    path = tmp_path / "face.gltf"
    path.write_text("{not json")
    expect(
        path,
        "not a glTF file (Expecting property name enclosed in double quotes: line 1 "
        "column 2 (char 1))",
        lambda: _Gltf(path),
    )


def test_a_missing_gltf_file(tmp_path):
    path = tmp_path / "none.gltf"
    expect(path, "the glTF file does not exist", lambda: _Gltf(path))


def test_a_gltf_file_over_the_file_budget(tmp_path, monkeypatch):
    path = write_gltf(tmp_path / "face.gltf", base_doc())
    size = path.stat().st_size
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FILE_BYTES", "100")
    expect(
        path,
        f"the glTF file is {size} bytes, more than the limit of 100 bytes (set "
        "WRINKLE_STUDIO_MAX_FILE_BYTES to raise it)",
        lambda: _Gltf(path),
    )


def test_json_nested_too_deeply(tmp_path, monkeypatch):
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_JSON_DEPTH", "2")
    doc = {"asset": ASSET, "extras": [[1]]}
    path = write_gltf(tmp_path / "face.gltf", doc)
    expect(
        path,
        "the nesting of the glTF JSON is 3 levels, more than the limit of 2 levels "
        "(set WRINKLE_STUDIO_MAX_JSON_DEPTH to change it)",
        lambda: _Gltf(path),
    )
    glb_path = tmp_path / "face.glb"
    glb_path.write_bytes(glb([json_chunk(doc)]))
    expect(
        glb_path,
        "the nesting of the GLB's JSON is 3 levels, more than the limit of 2 "
        "levels (set WRINKLE_STUDIO_MAX_JSON_DEPTH to change it)",
        lambda: _Gltf(glb_path),
    )


# --- GLB containers ---------------------------------------------------------------------------
def glb_doc() -> dict:
    return {
        "asset": ASSET,
        "buffers": [{"byteLength": 8}],
        "bufferViews": [{"buffer": 0, "byteLength": 8}],
        "accessors": [{"bufferView": 0, "componentType": 5123, "count": 4, "type": "SCALAR"}],
    }


BIN = np.array([10, 20, 30, 40], np.uint16).tobytes()
OTHER = np.array([1, 2, 3, 4], np.uint16).tobytes()


@pytest.mark.parametrize(
    "chunks",
    [
        [json_chunk(glb_doc()), (BIN_CHUNK, BIN)],
        [(BIN_CHUNK, BIN), json_chunk(glb_doc())],  # chunk order does not matter
        [json_chunk(glb_doc()), (0x12345678, OTHER), (BIN_CHUNK, BIN)],  # unknown kinds skipped
        [json_chunk(glb_doc()), (BIN_CHUNK, BIN), (BIN_CHUNK, OTHER)],  # the first BIN counts
        [json_chunk(glb_doc()), (BIN_CHUNK, BIN), json_chunk({"asset": {"version": "1"}})],
    ],
)
def test_a_glb_reads_its_json_and_first_bin_chunk(tmp_path, chunks):
    path = tmp_path / "face.glb"
    path.write_bytes(glb(chunks))
    g = _Gltf(path)
    assert g.buffers == [BIN]
    np.testing.assert_array_equal(g.accessor(0)[:, 0], [10, 20, 30, 40])


def test_an_empty_bin_chunk_at_the_very_end_is_read(tmp_path):
    path = tmp_path / "empty.glb"
    doc = {"asset": ASSET, "buffers": [{"byteLength": 0}]}
    path.write_bytes(glb([json_chunk(doc), (BIN_CHUNK, b"")]))
    assert _Gltf(path).buffers == [b""]


@pytest.mark.parametrize(
    ("data", "problem"),
    [
        (b"glTF" + bytes(15), "the GLB file is truncated"),
        (glb([(BIN_CHUNK, b"")]), "the GLB file has no JSON chunk"),  # exactly 20 bytes
        (
            glb([(JSON_CHUNK, b"")]),
            "the GLB's JSON is damaged (Expecting value: line 1 column 1 (char 0))",
        ),
        (glb([json_chunk(glb_doc())], version=1), "the GLB header is damaged or not version 2 (1)"),
        (glb([(BIN_CHUNK, BIN)], length=100), "the GLB file is truncated (28 of 100 bytes)"),
        (glb([(BIN_CHUNK, BIN), (0x12345678, b"")]), "the GLB file has no JSON chunk"),
        (glb([json_chunk(glb_doc())]), "a buffer has no data"),
    ],
    ids=["19 bytes", "20 bytes", "empty JSON", "version 1", "short", "no JSON", "no BIN"],
)
def test_broken_glb_files_are_named(tmp_path, data, problem):
    path = tmp_path / "bad.glb"
    path.write_bytes(data)
    expect(path, problem, lambda: _Gltf(path))


def test_a_chunk_longer_than_the_file(tmp_path):
    data = glb([json_chunk({"asset": ASSET}), (BIN_CHUNK, BIN)])
    data = data[:-16] + struct.pack("<II", 64, BIN_CHUNK) + BIN
    path = tmp_path / "bad.glb"
    path.write_bytes(data)
    expect(path, "a GLB chunk is truncated", lambda: _Gltf(path))


# --- broken views and accessors ---------------------------------------------------------------
def acc(**changes: object) -> Callable[[dict], None]:
    def change(doc: dict) -> None:
        doc["accessors"][0].update(changes)

    return change


def view(**changes: object) -> Callable[[dict], None]:
    def change(doc: dict) -> None:
        doc["bufferViews"][0].update(changes)

    return change


def drop(key: str) -> Callable[[dict], None]:
    def change(doc: dict) -> None:
        del doc["accessors"][0][key]

    return change


INVALID_VIEW = "buffer view 0 has an invalid byteOffset, byteLength or byteStride"
INVALID_COUNT = "accessor 0 has an invalid count or byteOffset"


@pytest.mark.parametrize(
    ("change", "problem"),
    [
        (acc(sparse={"count": 1}), "accessor 0's sparse block is malformed (missing 'indices')"),
        (acc(componentType=5124), "accessor 0 has an unknown component type 5124 or type 'VEC3'"),
        (acc(type="VEC5"), "accessor 0 has an unknown component type 5126 or type 'VEC5'"),
        (acc(componentType=[5126]), "accessor 0 is malformed (unhashable type: 'list')"),
        (acc(count=0), INVALID_COUNT),
        (acc(count=1.5), INVALID_COUNT),
        (acc(count=True), INVALID_COUNT),
        (acc(count="4"), INVALID_COUNT),
        (acc(byteOffset=-4), INVALID_COUNT),
        (acc(byteOffset=True), INVALID_COUNT),
        (drop("bufferView"), "accessor 0 has no bufferView (no data)"),
        (acc(byteOffset=2), "accessor 0's elements overlap or are misaligned"),
        (view(byteStride=8), "accessor 0's elements overlap or are misaligned"),
        (acc(count=5), "accessor 0 reaches past its buffer view's end"),
        (acc(count=13, type="SCALAR"), "accessor 0 reaches past its buffer view's end"),
        (acc(count=2, byteOffset=28), "accessor 0 reaches past its buffer view's end"),
        (acc(bufferView=1), "a reference to bufferViews[1], which does not exist (the file has 1)"),
        (
            acc(bufferView=-1),
            "a reference to bufferViews[-1], which does not exist (the file has 1)",
        ),
        (view(byteOffset=-4), INVALID_VIEW),
        (view(byteOffset="0"), INVALID_VIEW),
        (view(byteLength=None), INVALID_VIEW),
        (view(byteStride=2), INVALID_VIEW),
        (view(byteStride=253), INVALID_VIEW),
        (view(byteStride=12.0), INVALID_VIEW),
        (view(byteLength=52), "buffer view 0 reaches past its buffer's end"),
        (view(byteOffset=4), "buffer view 0 reaches past its buffer's end"),
        (view(buffer=1), "a reference to buffers[1], which does not exist (the file has 1)"),
        (view(buffer=None), "a reference to buffers[None], which does not exist (the file has 1)"),
    ],
)
def test_broken_accessors_and_views_are_named(tmp_path, change, problem):
    doc = base_doc()
    change(doc)
    g, path = load(tmp_path, doc)
    expect(path, problem, lambda: g.accessor(0))


def test_a_stride_just_outside_the_range_is_refused_for_bytes(tmp_path):
    # uint8 elements would fit any stride, so only the 4..252 rule refuses 3 and 253.
    blob = bytes(range(256))
    for stride in (2, 3, 253):
        doc = {
            "asset": ASSET,
            "buffers": [{"byteLength": 256, "uri": data_uri(blob)}],
            "bufferViews": [{"buffer": 0, "byteLength": 256, "byteStride": stride}],
            "accessors": [{"bufferView": 0, "componentType": 5121, "count": 1, "type": "SCALAR"}],
        }
        g, path = load(tmp_path, doc)
        expect(path, INVALID_VIEW, lambda g=g: g.accessor(0))


def test_non_finite_floats_are_refused(tmp_path):
    blob = np.array([0.0, np.nan, 1.0, np.inf], np.float32).tobytes()
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": 16, "uri": data_uri(blob)}],
        "bufferViews": [{"buffer": 0, "byteLength": 16}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "SCALAR"}],
    }
    g, path = load(tmp_path, doc)
    expect(path, "accessor 0 holds non-finite numbers (NaN or infinity)", lambda: g.accessor(0))


@pytest.mark.parametrize(
    ("accessors", "index", "problem"),
    [
        (None, 1, "a reference to accessors[1], which does not exist (the file has 1)"),
        (None, -1, "a reference to accessors[-1], which does not exist (the file has 1)"),
        (None, "0", "a reference to accessors['0'], which does not exist (the file has 1)"),
        ([5], 0, "accessors[0] is not a JSON object"),
        ({}, 0, "'accessors' is not a JSON list"),
    ],
)
def test_references_to_accessors(tmp_path, accessors, index, problem):
    doc = base_doc()
    if accessors is not None:
        doc["accessors"] = accessors
    g, path = load(tmp_path, doc)
    expect(path, problem, lambda: g.accessor(index))


def test_the_vertex_budget_counts_elements_and_thirds_of_indices(tmp_path, monkeypatch):
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_MESH_VERTICES", "2")
    doc = base_doc()
    doc["accessors"] = [
        {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
        {"bufferView": 0, "componentType": 5126, "count": 8, "type": "SCALAR"},
        {"bufferView": 0, "componentType": 5126, "count": 9, "type": "SCALAR"},
    ]
    g, path = load(tmp_path, doc)
    over = (
        "is 3 vertices, more than the limit of 2 vertices (set "
        "WRINKLE_STUDIO_MAX_MESH_VERTICES to change it)"
    )
    expect(path, f"accessor 0 {over}", lambda: g.accessor(0))
    np.testing.assert_array_equal(g.accessor(1)[:, 0], FLOATS[:8])  # 8 // 3 = 2 triangles
    expect(path, f"accessor 2 {over}", lambda: g.accessor(2))


# --- typed accessors --------------------------------------------------------------------------
def test_typed_accessors_check_type_and_integer_components(tmp_path):
    indices = np.array([0, 1, 2, 2], np.uint8)
    blob = FLOATS.tobytes() + indices.tobytes()
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 4},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 12, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5121, "count": 3, "type": "SCALAR"},
        ],
    }
    g, path = load(tmp_path, doc)
    np.testing.assert_array_equal(
        g.typed(1, ("SCALAR",), "the indices", integer=True)[:, 0], [0, 1, 2]
    )
    np.testing.assert_array_equal(g.typed(0, ("SCALAR",), "the weights")[:, 0], FLOATS)
    expect(
        path,
        "the positions (accessor 0) is 'SCALAR' of component type 5126, expected VEC3 or VEC4",
        lambda: g.typed(0, ("VEC3", "VEC4"), "the positions"),
    )
    expect(
        path,
        "the indices (accessor 0) is 'SCALAR' of component type 5126, expected "
        "SCALAR of unsigned integers",
        lambda: g.typed(0, ("SCALAR",), "the indices", integer=True),
    )


# --- images -----------------------------------------------------------------------------------
PIXELS = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3) * 7


def test_images_from_a_view_a_data_uri_and_a_file(tmp_path):
    png = encode_png(PIXELS)
    blob = b"\0" * 4 + png + b"\0" * 3
    (tmp_path / "tex.png").write_bytes(png)
    doc = {
        "asset": ASSET,
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 4, "byteLength": len(png)}],
        "images": [
            {"bufferView": 0, "mimeType": "image/png"},
            {"uri": "data:image/png;base64," + base64.b64encode(png).decode()},
            {"uri": "tex.png"},
        ],
        "textures": [{"source": 2}],
    }
    g, _ = load(tmp_path, doc)
    for k in range(3):
        np.testing.assert_array_equal(g.image(k), PIXELS)
    np.testing.assert_array_equal(g.texture_image({"index": 0}), PIXELS)
    assert g.texture_image(None) is None and g.texture_image({}) is None


def test_broken_images_and_textures_are_named(tmp_path):
    doc = {
        "asset": ASSET,
        "buffers": [{"uri": data_uri(b"not an image")}],
        "bufferViews": [{"buffer": 0, "byteLength": 12}],
        "images": [{"bufferView": 0}, {"name": "no data"}],
        "textures": [{"source": 0}, {}],
    }
    g, path = load(tmp_path, doc)
    with pytest.raises(ImageError) as info:
        g.image(0)
    assert info.value.path == Path(f"{path} (image 0)")
    assert info.value.problem.startswith("not an image this studio can read")
    expect(path, "image 1 is malformed ('uri')", lambda: g.image(1))
    for index in (2, -1):  # never read from the end, as Python would
        expect(
            path,
            f"a reference to images[{index}], which does not exist (the file has 2)",
            lambda index=index: g.image(index),
        )
    for info_ in ({"index": 1}, {"index": 5}, {"index": -1}, {"texCoord": 0}):
        expect(
            path,
            "a material refers to a texture that does not exist",
            lambda info_=info_: g.texture_image(info_),
        )
    del doc["images"]
    g, path = load(tmp_path, doc)
    expect(
        path,
        "a reference to images[0], which does not exist (the file has 0)",
        lambda: g.image(0),
    )


def test_rgb_expands_grey_and_drops_alpha():
    fallback = np.zeros((1, 1, 3), np.uint8)
    assert _rgb(None, fallback) is fallback
    grey = np.array([[0, 100], [200, 255]], np.uint8)
    rgb = _rgb(grey, fallback)
    assert rgb.shape == (2, 2, 3)
    for channel in range(3):
        np.testing.assert_array_equal(rgb[:, :, channel], grey)
    rgba = np.arange(2 * 2 * 4, dtype=np.uint8).reshape(2, 2, 4)
    out = _rgb(rgba, fallback)
    np.testing.assert_array_equal(out, rgba[:, :, :3])
    assert out.flags.c_contiguous
