"""USD out (``export --usd FILE.usdz``): the mesh, UVs, key poses as UsdSkel blend shapes, the
maps and masks in the package, the set-up as custom data. Read by Pixar's own library (pxr)
as any USD tool would, checked by USD's validators (what ``usdchecker`` runs), imported by stock
Blender's USD importer with its shape keys, and opened back in the studio with its set-up."""

from __future__ import annotations

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.animation.timeline import sequence_all_poses
from studio.core.formats.usd.reader import load_usd
from studio.core.project.model import Project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.response import ResponseCurve

BLENDER_USD = """
import bpy, json, sys
bpy.ops.wm.read_factory_settings(use_empty=True)
result = bpy.ops.wm.usd_import(filepath=sys.argv[-1])
meshes = [{"vertices": len(o.data.vertices), "uv": [u.name for u in o.data.uv_layers],
           "keys": [k.name for k in o.data.shape_keys.key_blocks] if o.data.shape_keys else []}
          for o in bpy.context.scene.objects if o.type == "MESH"]
print("USD_REPORT " + json.dumps({"result": sorted(result), "meshes": meshes}))
"""


def face() -> Project:
    project = make_test_face(561, texture_size=64, mask_size=64)
    project.timeline = sequence_all_poses([p.name for p in project.poses], fps=30.0)
    project.influence.links["frown"]["between brows"] = 0.6
    project.influence.curves = {"squeeze": {"cheeks": ResponseCurve("ease_in")}}
    project.not_face = np.zeros(project.mesh.n_welded, bool)
    project.not_face[:30] = True
    return project


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> tuple[Project, Path]:
    folder = tmp_path_factory.mktemp("usd")
    project = face()
    save_project(project, folder / "face.wrinkle", backup=False)
    assert main(["export", str(folder / "face.wrinkle"), "--usd", str(folder / "face.usdz")]) == 0
    return project, folder / "face.usdz"


def test_pxr_reads_the_mesh_blend_shapes_animation_and_textures(exported):
    from pxr import Usd, UsdGeom, UsdSkel

    project, path = exported
    stage = Usd.Stage.Open(str(path))
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/Face/Mesh"))
    points = np.asarray(mesh.GetPointsAttr().Get())
    np.testing.assert_allclose(points, project.mesh.rest, atol=1e-6)
    binding = UsdSkel.BindingAPI(mesh.GetPrim())
    names = list(binding.GetBlendShapesAttr().Get())
    assert names == [p.name for p in project.poses]
    for target, pose in zip(binding.GetBlendShapeTargetsRel().GetTargets(), project.poses,
                            strict=True):
        shape = UsdSkel.BlendShape(stage.GetPrimAtPath(target))
        moved = np.asarray(points.copy())
        moved[np.asarray(shape.GetPointIndicesAttr().Get())] += np.asarray(
            shape.GetOffsetsAttr().Get())
        np.testing.assert_allclose(moved, pose.positions, atol=1e-6)
    # the skeleton's animation plays the timeline's weights at each of its keys
    query = UsdSkel.Cache().GetSkelQuery(UsdSkel.Skeleton(stage.GetPrimAtPath("/Face/Skeleton")))
    played = query.GetAnimQuery().GetPrim().GetAttribute("blendShapeWeights")
    keys = sorted({k.frame for t in project.timeline.tracks for k in t.keys})
    assert played.GetTimeSamples() == keys
    for frame in keys:
        want = project.timeline.weights_at(frame)
        np.testing.assert_allclose(played.Get(frame), [want.get(n, 0.0) for n in names],
                                   atol=1e-6)
    assert max(max(played.Get(f)) for f in keys) == 1.0
    assert stage.GetTimeCodesPerSecond() == 30.0
    with zipfile.ZipFile(path) as package:
        files = package.namelist()
    assert files[0] == "face.usdc"
    assert {"textures/diffuse.png", "textures/normal_neutral.png"} <= set(files)
    assert sum(f.startswith("textures/mask_") for f in files) == len(project.influence.areas)
    assert sum(f.startswith("textures/wrinkled_") for f in files) == \
        len(project.textures.wrinkle_maps)
    extras = json.loads(mesh.GetPrim().GetCustomDataByKey("wrinkleStudio"))
    assert extras["influence"]["links"] == project.influence.links


def test_usd_s_validators_find_nothing_wrong(exported):
    """What ``usdchecker`` checks (usd-core 0.25+ runs it through UsdValidation)."""
    from pxr import Usd, UsdValidation

    _, path = exported
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(Usd.Stage.Open(str(path)))
    assert [(e.GetName(), e.GetMessage()) for e in errors] == []


def test_the_studio_opens_it_again_with_its_set_up(exported):
    project, path = exported
    report: list[str] = []
    back = load_usd(path, report=report)
    assert back.name == project.name
    for got, want in zip(back.poses, project.poses, strict=True):
        assert got.name == want.name
        np.testing.assert_allclose(got.positions, want.positions, atol=1e-6)
    assert back.influence.links == project.influence.links
    assert back.influence.curves == {"squeeze": {"cheeks": ResponseCurve("ease_in")}}
    for got, want in zip(back.influence.areas, project.influence.areas, strict=True):
        assert got.name == want.name and got.wrinkle_map == want.wrinkle_map
        np.testing.assert_allclose(got.mask, want.mask, atol=1e-4)
    assert back.textures.wrinkle_map_names == project.textures.wrinkle_map_names
    for name, image in project.textures.wrinkle_maps.items():
        np.testing.assert_array_equal(back.textures.wrinkle_maps[name], image)
    np.testing.assert_array_equal(back.textures.normal_neutral, project.textures.normal_neutral)
    for got, want in zip(back.wdv.areas, project.wdv.areas, strict=True):
        assert (got.name, got.pose) == (want.name, want.pose)
        np.testing.assert_allclose(got.directions, want.directions, atol=1e-6)
        np.testing.assert_allclose(got.lengths, want.lengths, atol=1e-6)
    assert len(back.wdv.areas) == len(project.wdv.areas)
    np.testing.assert_array_equal(back.not_face, project.not_face)
    assert back.timeline.to_dict() == project.timeline.to_dict()


def test_stock_blender_imports_it_with_its_shape_keys(exported, tmp_path):
    project, path = exported
    script = tmp_path / "blender_usd.py"
    script.write_text(BLENDER_USD)
    done = subprocess.run([sys.executable, str(script), str(path)], capture_output=True,
                          text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    line = next(x for x in done.stdout.splitlines() if x.startswith("USD_REPORT "))
    report = json.loads(line[len("USD_REPORT "):])
    assert report["result"] == ["FINISHED"]
    [mesh] = report["meshes"]
    assert mesh["vertices"] == project.mesh.n_welded
    assert mesh["keys"] == ["Basis", *(p.name for p in project.poses)]
    assert mesh["uv"] == ["st"]


def test_usd_to_another_suffix_is_refused_in_one_line(tmp_path, capsys):
    project = tmp_path / "face.wrinkle"
    save_project(make_test_face(561, texture_size=64, mask_size=32), project, backup=False)
    assert main(["export", str(project), "--usd", str(tmp_path / "face.usda")]) == 2
    err = capsys.readouterr().err
    assert "face.usda" in err and ".usdz" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "face.usda").exists()


def test_new_from_the_package_keeps_the_set_up(exported, tmp_path):
    project, path = exported
    assert main(["new", "--mesh", str(path), "-o", str(tmp_path / "back.wrinkle")]) == 0
    from studio.core.project.reader import load_project

    back = load_project(tmp_path / "back.wrinkle")
    assert back.influence.links == project.influence.links
    assert [a.name for a in back.wdv.areas] == [a.name for a in project.wdv.areas]
    assert back.timeline.to_dict() == project.timeline.to_dict()
