"""The user's own input files and values: greyscale masks, frame-file patterns and numbers from
the command line, text and binary STL meshes, capture takes with a bad number, UDIM texture sets
and a glTF's own maps placed in the atlas, part names that look like eyes or teeth. Each problem
must give one message that names the file (or the option) and what is wrong."""

from __future__ import annotations

import argparse
import re
import struct
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.files.errors import ImageError, MeshError, ProjectError, StudioError
from studio.core.files.images import load_grey, load_rgb, read_image, write_image, write_png
from studio.core.files.input_checks import (
    check_camera,
    check_frame_pattern,
    finite,
    finite_float,
)
from studio.core.formats.assemble import (
    FLAT_NORMAL,
    _embedded_to_atlas,
    project_from_files,
    suggest_not_face,
)
from studio.core.formats.capture import CaptureError, _first_bad_number, read_live_link_csv
from studio.core.formats.texture_sets import load_texture
from studio.core.mesh.meshio import load_mesh
from studio.core.mesh.uv_tiles import plan_layout
from studio.core.wrinkles.textures import SKIN, FaceTextures

pytestmark = pytest.mark.core


# --- greyscale masks ------------------------------------------------------------------------

def test_a_grey_mask_is_read_as_fractions_of_full_scale(tmp_path: Path) -> None:
    """8-bit grey 0/51/255 is 0/0.2/1; 16-bit grey 0/13107/65535 the same, as (H, W) float32."""
    write_png(tmp_path / "m8.png", np.array([[0, 51, 255]], np.uint8))
    write_png(tmp_path / "m16.png", np.array([[0], [13107], [65535]], np.uint16))
    m8, m16 = load_grey(tmp_path / "m8.png"), load_grey(tmp_path / "m16.png")
    assert m8.dtype == np.float32 and m8.shape == (1, 3)
    assert m16.dtype == np.float32 and m16.shape == (3, 1)
    np.testing.assert_allclose(m8, [[0.0, 0.2, 1.0]], atol=1e-7)
    np.testing.assert_allclose(m16, [[0.0], [0.2], [1.0]], atol=1e-7)


def test_a_colour_mask_is_read_by_its_luminance(tmp_path: Path) -> None:
    """RGB masks weigh red, green and blue 0.2126 / 0.7152 / 0.0722 (Rec. 709)."""
    image = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255], [0, 0, 0]]],
                     np.uint8)
    write_png(tmp_path / "rgb.png", image)
    grey = load_grey(tmp_path / "rgb.png")
    assert grey.dtype == np.float32 and grey.shape == (1, 5)
    np.testing.assert_allclose(grey, [[0.2126, 0.7152, 0.0722, 1.0, 0.0]], atol=1e-6)


def test_a_masks_alpha_channel_is_ignored(tmp_path: Path) -> None:
    """RGBA is read by the luminance of its colour, grey+alpha by its grey: alpha plays no part."""
    write_png(tmp_path / "rgba.png", np.array([[[255, 0, 0, 0], [0, 0, 255, 255]]], np.uint8))
    write_png(tmp_path / "la.png", np.array([[[51, 255], [255, 0]]], np.uint8))
    np.testing.assert_allclose(load_grey(tmp_path / "rgba.png"), [[0.2126, 0.0722]], atol=1e-6)
    np.testing.assert_allclose(load_grey(tmp_path / "la.png"), [[0.2, 1.0]], atol=1e-7)


def test_a_mask_that_is_not_an_image_names_the_file(tmp_path: Path) -> None:
    """A file of other bytes is an ImageError naming it."""
    (tmp_path / "mask.png").write_bytes(b"not an image at all")
    with pytest.raises(ImageError, match=r"mask\.png: not an image this studio can read"):
        load_grey(tmp_path / "mask.png")


# --- command-line values ---------------------------------------------------------------------

@pytest.mark.parametrize(("text", "value"), [("1.5", 1.5), ("-2", -2.0), ("1e3", 1000.0),
                                             (" 7 ", 7.0)])
def test_finite_float_takes_numbers(text: str, value: float) -> None:
    """Any finite number, as float() spells it, is taken."""
    assert finite_float(text) == value


@pytest.mark.parametrize(("text", "message"), [
    ("abc", "'abc' is not a number"), ("", "'' is not a number"),
    ("inf", "'inf' is not a finite number"), ("-inf", "'-inf' is not a finite number"),
    ("nan", "'nan' is not a finite number"), ("1e999", "'1e999' is not a finite number")])
def test_finite_float_refuses_words_and_infinities(text: str, message: str) -> None:
    """Words, infinity and NaN are argparse errors that quote what was typed."""
    with pytest.raises(argparse.ArgumentTypeError) as caught:
        finite_float(text)
    assert str(caught.value) == message


@pytest.mark.parametrize("pattern", ["out.png", "frame_%04d.png", "f%d.png", "f%16d.png",
                                     "f%.16d.png", "100%%_%03d.png", "%-5d_%+d.png"])
def test_frame_patterns_with_sensible_widths_are_taken(pattern: str,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """Patterns without a width, or with widths up to 16, pass."""
    monkeypatch.delenv("WRINKLE_STUDIO_MAX_PATTERN_WIDTH", raising=False)
    check_frame_pattern(pattern)


@pytest.mark.parametrize(("pattern", "width"), [("f%017d.png", 17), ("f%999999999d.png",
                                                                     999_999_999),
                                                ("f%.20d.png", 20), ("a%d_%3.40d.png", 40)])
def test_a_frame_pattern_wider_than_the_budget_is_refused(
        pattern: str, width: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """A field width or precision over 16 is refused, naming the option, the width, the limit,
    a smaller width to write and the setting that raises it."""
    monkeypatch.delenv("WRINKLE_STUDIO_MAX_PATTERN_WIDTH", raising=False)
    with pytest.raises(StudioError) as caught:
        check_frame_pattern(pattern)
    assert str(caught.value) == (
        f"-o {pattern}: the field width is {width:,} characters, more than the limit of 16 "
        "characters (write a smaller width like %04d or set WRINKLE_STUDIO_MAX_PATTERN_WIDTH "
        "to change it)")


@pytest.mark.parametrize("pattern", ["f%*d.png", "f%.*d.png", "f%04d_%*s.png"])
def test_a_star_width_in_a_frame_pattern_is_refused(pattern: str) -> None:
    """A '*' width or precision would need an argument: refused, suggesting a written width."""
    with pytest.raises(StudioError) as caught:
        check_frame_pattern(pattern)
    assert str(caught.value) == (f"-o {pattern}: a '*' width needs an argument the pattern "
                                 "cannot have; write the width, e.g. %04d")


# --- the saved camera ------------------------------------------------------------------------

GOOD_CAMERA = {"target": [0, 1.5, -2], "distance": 3, "yaw": -720.0, "pitch": 0,
               "fov_y": 179.5, "radius": 0.25}


@pytest.mark.parametrize("view", [None, [], "camera", {}, {"wireframe": True},
                                  {"camera": GOOD_CAMERA}, {"camera": {}},
                                  {"camera": {"fov_y": 0.01, "pitch": -90}}])
def test_a_view_without_a_camera_or_with_a_sound_one_is_taken(view: object) -> None:
    """No view, no camera block, or a camera whose numbers can place a camera: no error."""
    check_camera(view, "p.wrinkle")


@pytest.mark.parametrize(("camera", "problem"), [
    ("front", "must be a JSON object"), ([1, 2], "must be a JSON object"),
    ({"target": [0, 0]}, "target must be three finite numbers"),
    ({"target": [0, 0, 0, 0]}, "target must be three finite numbers"),
    ({"target": [0, 0, "1"]}, "target must be three finite numbers"),
    ({"target": [0, float("nan"), 0]}, "target must be three finite numbers"),
    ({"target": [True, 0, 0]}, "target must be three finite numbers"),
    ({"target": "0 0 0"}, "target must be three finite numbers"),
    ({"distance": "2"}, "distance must be a finite number"),
    ({"yaw": float("inf")}, "yaw must be a finite number"),
    ({"pitch": None}, "pitch must be a finite number"),
    ({"fov_y": float("nan")}, "fov_y must be a finite number"),
    ({"radius": True}, "radius must be a finite number"),
    ({"yaw": [1], "distance": "x"}, "distance must be a finite number"),
    ({"distance": 0}, "distance must be positive"),
    ({"distance": -1.5}, "distance must be positive"),
    ({"radius": 0.0}, "radius must be positive"), ({"radius": -2}, "radius must be positive"),
    ({"fov_y": 0}, "fov_y must be between 0 and 180 degrees"),
    ({"fov_y": 180}, "fov_y must be between 0 and 180 degrees"),
    ({"fov_y": -30}, "fov_y must be between 0 and 180 degrees"),
    ({"fov_y": 270.5}, "fov_y must be between 0 and 180 degrees"),
])
def test_a_camera_that_cannot_place_a_camera_is_refused_naming_the_field(
        camera: object, problem: str) -> None:
    """Each bad field of view.camera is a ProjectError naming the file and the field."""
    with pytest.raises(ProjectError) as caught:
        check_camera({"camera": camera}, "p.wrinkle")
    assert str(caught.value) == f"p.wrinkle: project.json: view.camera {problem}"
    assert caught.value.path == Path("p.wrinkle")
    with pytest.raises(ProjectError) as caught:
        check_camera({"camera": camera})
    assert str(caught.value) == f"project.json: view.camera {problem}"


def test_finite_means_a_real_number_that_is_not_infinite() -> None:
    """Ints and floats count; booleans, strings, None, infinity and NaN do not."""
    assert finite(0) and finite(-3) and finite(2.5)
    for value in (True, False, "1", None, float("inf"), float("-inf"), float("nan"), [1]):
        assert not finite(value), value


# --- STL meshes ----------------------------------------------------------------------------

TEXT_STL = (b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
            b"vertex 0 1 0\nendloop\nendfacet\nendsolid t\n")


def binary_stl(header: bytes, triangles: int, count: int | None = None) -> bytes:
    """A binary STL: 80-byte header, triangle count, 50 bytes a triangle (floats whose bytes
    are far from ASCII)."""
    body = b"".join(struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1.5, 0, 0, 0, -2.25, 0, 0)
                    for _ in range(triangles))
    return header.ljust(80, b" ") + struct.pack("<I", triangles if count is None else count) + body


NO_UVS = "the mesh has no texture coordinates (UVs); export it with UVs"


@pytest.mark.parametrize("data", [TEXT_STL, binary_stl(b"solid made by an exporter", 1),
                                  binary_stl(b"solid", 3), binary_stl(b"binary STL", 2)],
                         ids=["text", "binary-solid-header", "binary-solid-3", "binary"])
def test_text_and_binary_stls_are_read(tmp_path: Path, data: bytes) -> None:
    """ASCII STLs and binary ones (even with a header starting 'solid') are read as meshes;
    STL has no UVs, so they are made (issue #37) and the user is told."""
    from studio.core.mesh.meshio import made_uvs

    path = tmp_path / "face.stl"
    path.write_bytes(data)
    assert (made_uvs(load_mesh(path)) or "").startswith(f"no UVs in {path}: made them with xatlas")


@pytest.mark.parametrize(("data", "byte", "value"), [
    (b"solid face\n\xff\xfe\x93 facet normal 0 0 1\n", 12, "ff"),
    (TEXT_STL[:-2] + b"\xe9\n", len(TEXT_STL) - 1, "e9"),
    (binary_stl(b"solid x", 1, count=2), 95, "80"),  # the count disagrees with the size
], ids=["short", "long", "binary-with-wrong-count"])
def test_a_text_stl_with_bytes_outside_ascii_is_refused_naming_the_byte(
        tmp_path: Path, data: bytes, byte: int, value: str) -> None:
    """A file starting 'solid' that is not a binary STL must be ASCII: the message names the
    file, the first bad byte (counting from 1) and its value."""
    path = tmp_path / "bad.stl"
    path.write_bytes(data)
    with pytest.raises(MeshError) as caught:
        load_mesh(path)
    assert str(caught.value) == (f"{path}: a text STL must be ASCII, but byte {byte} is 0x{value}"
                                 " (damaged, or another kind of file)")
    assert caught.value.path == path


def test_a_damaged_binary_stl_is_not_called_a_text_stl(tmp_path: Path) -> None:
    """A file not starting 'solid' is binary: damage in it is not reported as bad ASCII."""
    path = tmp_path / "bin.stl"
    path.write_bytes(binary_stl(b"binary", 1, count=2))
    with pytest.raises(MeshError) as caught:
        load_mesh(path)
    assert "ASCII" not in str(caught.value)
    assert caught.value.path == path


# --- capture takes -------------------------------------------------------------------------

def write_csv(path: Path, rows: list[str]) -> Path:
    path.write_text("Timecode,BlendShapeCount,EyeBlinkLeft,JawOpen\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize(("cell", "line", "column"), [
    ("abc", 3, "JawOpen"), ("nan", 2, "EyeBlinkLeft"), ("inf", 4, "JawOpen"),
    ("-Infinity", 3, "EyeBlinkLeft"), ("", 4, "EyeBlinkLeft")])
def test_a_take_with_a_value_that_is_not_a_finite_number_names_line_and_column(
        tmp_path: Path, cell: str, line: int, column: str) -> None:
    """The first bad value (in file order) is named by its line, its column and what it says."""
    values = {(2, "EyeBlinkLeft"): "0.1", (2, "JawOpen"): "0.2", (3, "EyeBlinkLeft"): "0.3",
              (3, "JawOpen"): "0.4", (4, "EyeBlinkLeft"): "0.5", (4, "JawOpen"): "0.6"}
    values[(line, column)] = cell
    if (line, column) != (4, "JawOpen"):
        values[(4, "JawOpen")] = "oops"  # a later bad value is not the one named
    rows = [f"00:00:01:{n:02d}.000,2,{values[(n + 2, 'EyeBlinkLeft')]},{values[(n + 2, 'JawOpen')]}"
            for n in range(3)]
    path = write_csv(tmp_path / "take.csv", rows)
    with pytest.raises(CaptureError) as caught:
        read_live_link_csv(path)
    assert str(caught.value) == (f"{path}: line {line}, column '{column}': '{cell}' is not a "
                                 "finite number")
    assert caught.value.path == path


def test_the_bad_number_search_finds_the_first_bad_cell_or_says_so(tmp_path: Path) -> None:
    """Searched row by row, then column by column; with no bad cell it still names the file."""
    path = tmp_path / "t.csv"
    error = _first_bad_number([["1", "2"], ["3", "x"], ["y", "4"]], [5, 9, 12], ["a", "b"], path)
    assert str(error) == f"{path}: line 9, column 'b': 'x' is not a finite number"
    assert error.path == path
    error = _first_bad_number([["1", "2"], ["3", "4"]], [2, 3], ["a", "b"], path)
    assert isinstance(error, CaptureError)
    assert str(error) == f"{path}: a value is not a number"
    assert error.path == path


# --- part names ----------------------------------------------------------------------------

def test_part_names_that_look_like_eyes_teeth_or_tongue_are_suggested() -> None:
    """Whole words (any case, spaces or underscores around them) are suggested, in order;
    skin parts whose names merely contain such a word are not."""
    names = ["Face", "Left Eye", "eyeball_R", "Teeth Upper", "tongue", "Mouth Bag", "mouthbag",
             "Tear Line", "Eyelid", "Eyebrows", "lashes", "Steeth", "EYE_L", "gums", "skin"]
    assert suggest_not_face(names) == ["Left Eye", "eyeball_R", "Teeth Upper", "tongue",
                                       "Mouth Bag", "mouthbag", "Tear Line", "lashes", "EYE_L",
                                       "gums"]
    assert suggest_not_face([]) == []


# --- UDIM texture sets and a glTF's own maps -----------------------------------------------

TWO_TILES_OBJ = """v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
vt 0.1 0.1
vt 0.9 0.1
vt 0.1 0.9
vt 1.1 0.1
vt 1.9 0.1
vt 1.1 0.9
f 1/1 2/2 3/3
f 2/4 4/5 3/6
"""


def tile_image(value: int) -> np.ndarray:
    """A 2 × 2 RGB tile, each texel its own colour."""
    return np.array([[[value, 1, 2], [value, 3, 4]], [[value, 5, 6], [value, 7, 8]]], np.uint8)


def test_texture_sets_are_composed_into_the_atlas_with_their_own_fills(tmp_path: Path) -> None:
    """A face on tiles 1001 and 1002 (both skin: side by side in the top half of the atlas):
    each given file lands in its tile's cell; the cells without a file and the unused half take
    skin colour in the diffuse map and a flat normal in the normal maps."""
    (tmp_path / "face.obj").write_text(TWO_TILES_OBJ)
    write_png(tmp_path / "skin.1001.png", tile_image(10))
    write_png(tmp_path / "nrm.1002.png", tile_image(20))
    write_png(tmp_path / "wrinkled.png", tile_image(30))  # no tile in its name: tile 1001
    project = project_from_files(tmp_path / "face.obj", diffuse=tmp_path / "skin.1001.png",
                                 normal=tmp_path / "nrm.1002.png",
                                 wrinkled=tmp_path / "wrinkled.png")
    assert project.uv_tiles is not None
    assert project.uv_tiles.layout.tiles == (1001, 1002)
    textures = project.textures
    for image in (textures.diffuse, textures.normal_neutral, textures.normal_wrinkled):
        assert image.shape == (4, 4, 3) and image.dtype == np.uint8
    assert np.array_equal(textures.diffuse[:2, :2], tile_image(10))
    assert (textures.diffuse[:2, 2:] == SKIN).all() and (textures.diffuse[2:] == SKIN).all()
    assert np.array_equal(textures.normal_neutral[:2, 2:], tile_image(20))
    assert (textures.normal_neutral[:2, :2] == FLAT_NORMAL).all()
    assert (textures.normal_neutral[2:] == FLAT_NORMAL).all()
    assert np.array_equal(textures.normal_wrinkled[:2, :2], tile_image(30))
    assert (textures.normal_wrinkled[:2, 2:] == FLAT_NORMAL).all()
    assert (textures.normal_wrinkled[2:] == FLAT_NORMAL).all()


def test_a_texture_set_without_any_tile_the_mesh_uses_is_refused(tmp_path: Path) -> None:
    """The message names the file, the set's tiles and the mesh's tiles, each in order."""
    (tmp_path / "face.obj").write_text(TWO_TILES_OBJ)
    for tile in (1004, 1003, 1011):
        write_png(tmp_path / f"skin.{tile}.png", tile_image(tile % 256))
    path = tmp_path / "skin.1004.png"
    message = (f"{path}: none of the texture's tiles (1003, 1004, 1011) is one the mesh's UVs "
               "use (1001, 1002)")
    with pytest.raises(ImageError, match=f"^{re.escape(message)}$"):
        project_from_files(tmp_path / "face.obj", diffuse=path)
    layout = plan_layout([1002, 1001])
    with pytest.raises(ImageError, match=f"^{re.escape(message)}$"):
        load_texture(path, layout, np.zeros(3, np.uint8))


def test_a_gltfs_own_maps_are_placed_in_the_first_tiles_cell() -> None:
    """Diffuse, neutral normals and every named wrinkled map keep their names and texels in tile
    1001's cell (full resolution), the rest filled with skin colour or a flat normal."""
    layout = plan_layout([1001, 1002], skin_tiles=[1001])  # 1001: (0, 0, ½), 1002: (½, 0, ¼)
    textures = FaceTextures(tile_image(40), tile_image(50),
                            wrinkle_maps={"brow": tile_image(60), "smile": tile_image(70)})
    _embedded_to_atlas(textures, layout)
    assert textures.wrinkle_map_names == ["brow", "smile"]
    images = {"diffuse": (textures.diffuse, 40, SKIN),
              "neutral": (textures.normal_neutral, 50, FLAT_NORMAL),
              "brow": (textures.wrinkle_maps["brow"], 60, FLAT_NORMAL),
              "smile": (textures.wrinkle_maps["smile"], 70, FLAT_NORMAL)}
    for name, (image, value, fill) in images.items():
        assert image.shape == (4, 4, 3) and image.dtype == np.uint8, name
        assert np.array_equal(image[:2, :2], tile_image(value)), name
        assert (image[:2, 2:] == fill).all() and (image[2:] == fill).all(), name


# --- other image formats -------------------------------------------------------------------

def pillow_file(path: Path, image: object, **params: object) -> Path:
    """Save a Pillow image (or an array) as the file ``path``."""
    (image if isinstance(image, Image.Image) else Image.fromarray(image)).save(path, **params)
    return path


def test_16_bit_and_float_tiffs_are_read_as_16_bit(tmp_path: Path) -> None:
    """A 16-bit TIFF keeps its values; 32-bit integer and float images are clipped to 0–65535."""
    sixteen = np.array([[0, 1, 65535]], np.uint16)
    got = read_image(pillow_file(tmp_path / "a.tif", Image.fromarray(sixteen)))
    assert got.dtype == np.uint16 and np.array_equal(got, sixteen)
    floats = np.array([[-5.0, 12.0, 70000.0]], np.float32)
    got = read_image(pillow_file(tmp_path / "f.tif", Image.fromarray(floats)))
    assert got.dtype == np.uint16 and np.array_equal(got, [[0, 12, 65535]])
    ints = np.array([[-1, 300, 1 << 20]], np.int32)
    got = read_image(pillow_file(tmp_path / "i.tif", Image.fromarray(ints)))
    assert got.dtype == np.uint16 and np.array_equal(got, [[0, 300, 65535]])


def test_palette_and_grey_images_of_other_formats(tmp_path: Path) -> None:
    """A palette GIF comes back as RGB, a grey BMP as grey, an RGB TIFF as it was."""
    rgb = np.array([[[255, 0, 0], [0, 0, 255]]], np.uint8)
    palette = Image.fromarray(rgb).quantize(colors=2)
    got = read_image(pillow_file(tmp_path / "p.gif", palette))
    assert got.dtype == np.uint8 and np.array_equal(got, rgb)
    grey = np.array([[0, 7, 255]], np.uint8)
    assert np.array_equal(read_image(pillow_file(tmp_path / "g.bmp", grey)), grey)
    assert np.array_equal(load_rgb(tmp_path / "g.bmp"), np.repeat(grey[:, :, None], 3, axis=2))
    assert np.array_equal(read_image(pillow_file(tmp_path / "c.tif", rgb)), rgb)


def test_write_image_picks_tiff_by_name_and_png_otherwise(tmp_path: Path) -> None:
    """'.tif'/'.TIFF' names get an 8-bit TIFF, others a PNG; both read back exactly."""
    image = np.array([[[1, 2, 3], [250, 251, 252]]], np.uint8)
    for name, magic in (("a.tif", b"II*\0"), ("b.TIFF", b"II*\0"), ("c.png", b"\x89PNG")):
        write_image(tmp_path / name, image)
        assert (tmp_path / name).read_bytes()[:4] == magic, name
        assert np.array_equal(read_image(tmp_path / name), image), name


def test_an_image_over_the_pixel_budget_is_refused_before_decoding(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """PNG or not, an image with more pixels than the budget names the file and the setting."""
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_IMAGE_PIXELS", "20")
    write_png(tmp_path / "big.png", np.zeros((3, 7), np.uint8))
    pillow_file(tmp_path / "big.bmp", np.zeros((3, 7), np.uint8))
    for name in ("big.png", "big.bmp"):
        with pytest.raises(ImageError) as caught:
            read_image(tmp_path / name)
        assert str(caught.value) == (f"{tmp_path / name}: the image is 21 pixels, more than the "
                                     "limit of 20 pixels (set WRINKLE_STUDIO_MAX_IMAGE_PIXELS "
                                     "to change it)")
    write_png(tmp_path / "ok.png", np.zeros((4, 5), np.uint8))
    assert read_image(tmp_path / "ok.png").shape == (4, 5)


def test_big_endian_grey_alpha_and_cmyk_tiffs_are_read(tmp_path: Path) -> None:
    """A big-endian 16-bit TIFF keeps its values, grey+alpha stays grey+alpha, CMYK becomes RGB."""
    big = np.array([[0, 258, 65535]], np.uint16)
    got = read_image(pillow_file(tmp_path / "b.tif", Image.fromarray(big.astype(">u2"))))
    assert got.dtype == np.uint16 and np.array_equal(got, big)
    la = np.array([[[10, 255], [200, 0]]], np.uint8)
    got = read_image(pillow_file(tmp_path / "la.tif", Image.fromarray(la, "LA")))
    assert np.array_equal(got, la)
    rgb = np.array([[[255, 0, 0], [0, 128, 255]]], np.uint8)
    got = read_image(pillow_file(tmp_path / "c.tif", Image.fromarray(rgb).convert("CMYK")))
    assert got.shape == (1, 2, 3) and np.array_equal(got, rgb)


def test_an_image_file_too_large_or_not_a_file_is_named(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """Over the file budget, missing, or a folder: an ImageError naming the image and the fix."""
    write_png(tmp_path / "a.png", np.zeros((8, 8), np.uint8))
    size = (tmp_path / "a.png").stat().st_size
    monkeypatch.setenv("WRINKLE_STUDIO_MAX_FILE_BYTES", "10")
    with pytest.raises(ImageError) as caught:
        read_image(tmp_path / "a.png")
    assert str(caught.value) == (f"{tmp_path / 'a.png'}: the image is {size} bytes, more than "
                                 "the limit of 10 bytes (set WRINKLE_STUDIO_MAX_FILE_BYTES to "
                                 "raise it)")
    monkeypatch.delenv("WRINKLE_STUDIO_MAX_FILE_BYTES")
    with pytest.raises(ImageError, match=r"nope\.png: the image does not exist$"):
        read_image(tmp_path / "nope.png")
    with pytest.raises(ImageError, match=r"not a file: this is a folder, not an image$"):
        read_image(tmp_path)


@pytest.mark.parametrize("name", ["x.png", "x.tif"])
def test_an_image_that_cannot_be_written_names_the_file(tmp_path: Path, name: str) -> None:
    """Writing into a folder that does not exist is an ImageError naming the image."""
    path = tmp_path / "missing" / name
    with pytest.raises(ImageError) as caught:
        write_image(path, np.zeros((2, 2, 3), np.uint8))
    assert str(caught.value) == (f"{path}: cannot write the image: the folder "
                                 f"{tmp_path / 'missing'} does not exist")
