"""The export folder's Blender script (``blender_wrinkles.py``): run in stock Blender (bpy 4.5
LTS) on the folder's face.glb, it builds technique 1 into the face's material, each area's
activation a driver on the shape keys through the link's gain and response curve, so that the
forehead wrinkles in a Cycles render when browInnerUp_L goes to 1, and nothing changes at 0."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from studio.core.formats.blender_material import link_term
from studio.core.formats.export import export_folder
from studio.core.wrinkles.response import ResponseCurve
from tests.test_blender_round_trip import JUDGED, set_up_head

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "blender_wrinkle_render.py"
CURVES = [ResponseCurve(), ResponseCurve("ease_in"), ResponseCurve("ease_out"),
          ResponseCurve("ease_in_out"), ResponseCurve("smooth_step", 0.2, 0.7),
          ResponseCurve("custom", points=((0.1, 0.2), (0.5, 0.9), (0.8, 0.4)))]


@pytest.mark.core
@pytest.mark.parametrize("curve", CURVES, ids=[c.kind for c in CURVES])
def test_a_link_s_driver_expression_is_its_gain_times_its_curve(curve):
    for x in np.linspace(-0.2, 1.2, 29):
        term = link_term(0.75, curve).format(x=repr(float(x)))
        got = eval(term, {"__builtins__": {}, "min": min, "max": max})
        want = 0.75 * float(curve.evaluate(x))
        assert got == pytest.approx(want, abs=1e-12), (curve.kind, x)


def rendered(out: Path, name: str) -> np.ndarray:
    with Image.open(out / f"{name}.png") as image:
        return np.asarray(image.convert("RGB")).astype(int)


def blender_render(folder: Path, out: Path, *options: str) -> dict:
    """Stock Blender (the bpy package) renders ``folder``'s export by
    scripts/blender_wrinkle_render.py into ``out``, JUDGED at 1 and at 0, wrinkles on and
    off; its report (bpy's version, the drivers' values)."""
    if importlib.util.find_spec("bpy") is None:
        pytest.fail("bpy is not installed: run 'bash scripts/setup.sh test'")
    done = subprocess.run([sys.executable, str(SCRIPT), str(folder), JUDGED, str(out),
                           *options], capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    mark = "BLENDER_WRINKLE_RENDER "
    (report,) = [json.loads(line[len(mark):]) for line in done.stdout.splitlines()
                 if line.startswith(mark)]
    assert report["bpy"].startswith("4.5")
    return report


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).max(-1) > 4


def test_moving_the_shape_key_wrinkles_the_forehead_in_a_cycles_render(tmp_path):
    export_folder(set_up_head(), tmp_path / "folder")
    out = tmp_path / "render"
    report = blender_render(tmp_path / "folder", out, "--technique", "1")
    activations = {label: value for label, value in report["activations"].items()
                   if label.startswith("activation: ")}  # technique 1's drivers
    assert activations.pop(f"activation: {JUDGED}") == pytest.approx(1.0)
    assert set(activations.values()) == {0.0}  # the other areas' poses are at 0
    wrinkles = changed(rendered(out, "pose1_on"), rendered(out, "pose1_off"))
    assert wrinkles.mean() >= 0.01, wrinkles.mean()
    assert not changed(rendered(out, "pose0_on"), rendered(out, "pose0_off")).any()
    rows, cols = np.nonzero(wrinkles)
    size = wrinkles.shape[0]
    # centred on the forehead above the eyes (at about 0.55 of the height), on the face's left
    # (the picture's right: the inner brow reaches over the middle)
    assert rows.mean() < 0.42 * size and cols.mean() > 0.55 * size, (rows.mean(), cols.mean())


def test_cavity_and_colour_flush_and_darken_the_wrinkles_in_a_cycles_render(tmp_path):
    """Issue 46: the set-up's cavity and colour maps, written into the folder and blended by
    the script with the same weights as the normals, make the wrinkled forehead redder and
    darker than the same folder without them; with the shape key at 0 nothing changes."""
    import copy

    if importlib.util.find_spec("bpy") is None:
        pytest.fail("bpy is not installed: run 'bash scripts/setup.sh test'")
    toned = set_up_head()
    assert toned.textures.has_tone  # new --auto made them with the furrows
    plain = copy.deepcopy(toned)
    plain.textures.cavity_maps.clear()
    plain.textures.colour_maps.clear()
    shots = {}
    for name, project in (("toned", toned), ("plain", plain)):
        export_folder(project, tmp_path / name)
        sheet = json.loads((tmp_path / name / "wrinkles.json").read_text())
        assert all(("cavity" in m) == (name == "toned") for m in sheet["wrinkle_maps"])
        out = tmp_path / f"{name}_render"
        done = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path / name), JUDGED,
                               str(out)], capture_output=True, text=True, timeout=600,
                              check=False)
        assert done.returncode == 0, done.stderr[-3000:]
        shots[name] = {k: rendered(out, k) for k in ("pose1_on", "pose0_on")}
    assert np.array_equal(shots["toned"]["pose0_on"], shots["plain"]["pose0_on"])
    wrinkled = changed(shots["plain"]["pose1_on"], shots["plain"]["pose0_on"])
    toned_px = shots["toned"]["pose1_on"][wrinkled].astype(float)
    plain_px = shots["plain"]["pose1_on"][wrinkled].astype(float)
    assert toned_px.sum(-1).mean() < plain_px.sum(-1).mean() - 3  # darker in the creases
    red = [(px[:, 0] / np.maximum(px[:, 1], 1.0)).mean() for px in (toned_px, plain_px)]
    assert red[0] > red[1] + 0.01, red  # and flushed
