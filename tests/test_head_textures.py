"""Issue 46: a head's own textures. An FBX (its albedo embedded, or beside it), a glTF, a VRM and
an OBJ with its ``.mtl`` each bring the skin's base colour: a default render of the new project
shows it, and the report says which texture was read, or that it was missing."""

from __future__ import annotations

import io
import shutil
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.cli import main
from studio.core.files.images import read_image
from tests.gltf_avatar import build_avatar
from tests.production_head import build_head
from tests.test_vrm import build_vrm

GREEN = (40, 170, 70)  # an albedo no skin has: plain skin colour is red over green
BUMPY = (200, 128, 220)  # a normal map tilted toward +u: the neutral changes the light


def _image(path: Path, colour: tuple[int, int, int], size: int = 128) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.full((size, size, 3), colour, np.uint8)).save(path)
    return path


def _new_and_render(folder: Path, head: Path) -> tuple[np.ndarray, str]:
    """``new --mesh HEAD`` then a default ``render`` of it: the face's median colour, and
    what ``new`` said."""
    out = io.StringIO()
    project = folder / "head.wrinkle"
    with redirect_stdout(out):
        assert main(["new", "--mesh", str(head), "-o", str(project)]) == 0
        assert main(["render", str(project), "--size", "320x320", "-o",
                     str(folder / "render.png")]) == 0
    image = read_image(folder / "render.png")[:, :, :3].astype(int)
    face = np.abs(image - image[0, 0]).max(-1) > 8
    assert face.mean() > 0.05, face.mean()
    return np.median(image[face], axis=0), out.getvalue()


def _green(colour: np.ndarray) -> bool:
    red, green, blue = colour
    return green > 1.5 * red and green > 1.5 * blue


def test_an_obj_s_mtl_map_kd_is_the_albedo(tmp_path):
    """Blender's OBJ export: ``mtllib`` on top, ``map_Kd`` relative to the .mtl (a name with a
    space), the normal map as ``map_Bump -bm``; the head on UDIM tile 1001, its eyes on 1002
    with a texture of their own."""
    head = build_head("cm")
    obj = head.write_obj(tmp_path / "head.obj")
    obj.write_text("mtllib head.mtl\n" + obj.read_text())
    _image(tmp_path / "textures" / "skin albedo.png", GREEN)
    _image(tmp_path / "textures" / "eye.png", (250, 250, 250))
    (tmp_path / "head.mtl").write_text(
        "# Blender MTL File\nnewmtl eye_L\nKd 0.8 0.8 0.8\nmap_Kd textures/eye.png\n\n"
        "newmtl head\nNs 250\nKd 0.8 0.8 0.8\nmap_Kd textures/skin albedo.png\n"
        "map_Bump -bm 1.000000 textures/skin_normal.png\n")
    colour, said = _new_and_render(tmp_path, obj)
    assert _green(colour), colour
    assert "diffuse map: texture textures/skin albedo.png of material head (" in said, said
    assert ("normal map: texture textures/skin_normal.png of material head not found" in said
            ), said


def test_an_obj_without_its_textures_opens_plain_and_says_so(tmp_path):
    head = build_head("cm")
    obj = head.write_obj(tmp_path / "head.obj")
    obj.write_text("mtllib head.mtl\n" + obj.read_text())
    (tmp_path / "head.mtl").write_text("newmtl head\nmap_Kd skin.png\n")
    colour, said = _new_and_render(tmp_path, obj)
    assert not _green(colour) and colour[0] > colour[1], colour
    assert "texture skin.png of material head not found" in said, said
    assert ": plain skin colour" in said


@pytest.mark.parametrize("build", [build_avatar, build_vrm], ids=["glb", "vrm"])
def test_a_gltf_s_and_a_vrm_s_base_colour_is_the_albedo(tmp_path, build):
    path = build(tmp_path / f"avatar.{'glb' if build is build_avatar else 'vrm'}",
                 skin_colour=GREEN)
    colour, _ = _new_and_render(tmp_path, path)
    assert _green(colour), colour


@pytest.fixture(scope="module")
def fbx_heads(tmp_path_factory):
    """Blender's FBX export of a head whose skin material shows an albedo and a normal map:
    embedded in the file, and referenced from a folder beside it; the folder of the latter
    then moved (the absolute paths it wrote are stale, its relative ones still hold) and the
    maps are nowhere else on the disk."""
    pytest.importorskip("bpy")
    from tests.fbx_blender import write_fbx

    folder = tmp_path_factory.mktemp("fbx_textures")
    maps = folder / "artist" / "maps"
    albedo, normal = _image(maps / "skin_albedo.png", GREEN), _image(maps / "skin_n.png", BUMPY)
    (folder / "embedded").mkdir()
    embedded = write_fbx(folder / "embedded" / "head.fbx", poses=["browDown_L"],
                         texture=albedo, normal=normal, embed=True)
    write_fbx(folder / "artist" / "head.fbx", poses=["browDown_L"], texture=albedo,
              normal=normal)
    shutil.move(folder / "artist", folder / "handed_over")
    return {"embedded": embedded, "referenced": folder / "handed_over" / "head.fbx"}


@pytest.mark.parametrize("kind", ["embedded", "referenced"])
def test_an_fbx_s_albedo_embedded_or_beside_it_is_the_albedo(fbx_heads, kind, tmp_path):
    colour, said = _new_and_render(tmp_path, fbx_heads[kind])
    assert _green(colour), (kind, colour)
    where = "embedded in the file" if kind == "embedded" else "maps/skin_albedo.png"
    line = next(x for x in said.splitlines() if "diffuse map: texture" in x)
    assert "of material M_Skin" in line and where in line, line
    assert any("normal map: texture" in x and "M_Skin" in x and "not found" not in x
               for x in said.splitlines()), said


def test_an_fbx_whose_textures_were_left_behind_says_so(fbx_heads, tmp_path):
    """The referenced FBX copied alone to another folder: its maps are not found; it opens in
    plain skin and the report names each texture."""
    lone = tmp_path / "lone" / "head.fbx"
    lone.parent.mkdir()
    shutil.copy(fbx_heads["referenced"], lone)
    colour, said = _new_and_render(tmp_path, lone)
    assert not _green(colour) and colour[0] > colour[1], colour
    assert "skin_albedo.png of material M_Skin not found" in said, said
    assert "skin_n.png of material M_Skin not found" in said, said
