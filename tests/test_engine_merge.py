"""O3DE blends at most 16 morph-target masks: a project with more is offered a merge of its
weakest masks into the ones they overlap most (``export --layout o3de --merge-weakest``, the
engine dialog's question) instead of only a refusal, and the sheet and the command say what was
merged."""

from __future__ import annotations

import json

import numpy as np
import pytest

from studio.core.animation.poses import KeyPose
from studio.core.engines.export import SHEET, export_layout
from studio.core.engines.plan import LayoutError, plan_export
from studio.core.project.model import Project
from studio.core.project.writer import save_project
from tests.test_engine_layouts import arkit_face, check_sheet_against_files, pil_pixels, run_cli

WEAK_GAIN = 0.05


def seventeen_masks() -> Project:
    """The ARKit face's five driving poses, eleven more on the left forehead, and a cheek puff
    that raises the cheeks at a twentieth of the smile's gain: the weakest of 17 masks, lying
    wholly under the smile's."""
    project = arkit_face()
    for i in range(11):
        project.influence.links[f"extra_{i}"] = {"forehead left": 1.0}
    project.influence.links["cheekPuff"] = {"cheeks": WEAK_GAIN}
    project.poses += [KeyPose(name, project.poses[0].positions)
                      for name in project.influence.links if name not in project.pose_names]
    return project


@pytest.mark.core
def test_over_the_limit_is_refused_with_the_merge_offered(tmp_path):
    plan = plan_export(seventeen_masks(), "o3de")
    assert plan.used == 17 and plan.mergeable and plan.merged == []
    with pytest.raises(LayoutError, match="merging the 1 weakest masks") as refused:
        export_layout(seventeen_masks(), tmp_path / "out", "o3de")
    assert refused.value.mergeable
    assert not (tmp_path / "out").exists()
    assert not plan_export(seventeen_masks(), "metahuman").mergeable  # fixed regions: no merge


@pytest.mark.core
def test_the_weakest_mask_is_merged_into_the_one_it_lies_under(tmp_path):
    project = seventeen_masks()
    plan, _ = export_layout(project, tmp_path, "o3de", merge=True)
    (merge,) = plan.merged
    assert (merge.mask, merge.into) == ("cheekPuff", "mouthSmile_R")
    assert merge.overlap == pytest.approx(1.0)
    assert plan.used == len(plan.masks) == 16
    folder = tmp_path / "face_wrinklemasks"
    assert not (folder / "cheekPuff_wrinklemask.tif").exists()
    # the smile's mask holds the cheek puff's gain too, added and clamped
    cheeks = next(a for a in project.influence.areas if a.name == "cheeks")
    layer = project.textures.map_index(cheeks.wrinkle_map)
    smile = pil_pixels(folder / "mouthSmile_R_wrinklemask.tif")[:, :, layer]
    want = np.clip(cheeks.mask * np.float32(1.0 + WEAK_GAIN), 0, 1)
    assert np.array_equal(smile, np.round(want * 255).astype(np.uint8))
    sheet = check_sheet_against_files(project, tmp_path)
    (said,) = sheet["merged"]
    assert (said["mask"], said["into"]) == ("cheekPuff", "mouthSmile_R")
    assert "weakest" in said["note"]


def test_the_command_offers_the_merge_and_says_what_it_merged(tmp_path):
    save_project(seventeen_masks(), tmp_path / "many.wrinkle")
    args = ["export", str(tmp_path / "many.wrinkle"), "--layout", "o3de", "--folder"]
    refused = run_cli(*args, str(tmp_path / "refused"))
    assert refused.returncode == 2 and "--merge-weakest" in refused.stderr
    done = run_cli(*args, str(tmp_path / "out"), "--merge-weakest")
    assert done.returncode == 0, done.stderr
    assert "merged: the mask of 'cheekPuff' (the weakest" in done.stdout
    assert "into 'mouthSmile_R'" in done.stdout
    assert json.loads((tmp_path / "out" / SHEET).read_text())["limit"]["used"] == 16


def test_the_sample_s_eighteen_masks_fit_o3de_merged():
    """The sample (17 wrinkling poses when the issue tried it, 18 with the pucker since issue
    38): refused, then merged to 16, each merged mask into one over the same skin."""
    from studio.core.setup.sample_setup import sample_project

    project = sample_project()
    assert plan_export(project, "o3de").used == 18
    plan = plan_export(project, "o3de", merge=True)
    assert plan.used == 16 and len(plan.merged) == 2
    plan.check()
    masks = {t.name for t in plan.masks}
    for merge in plan.merged:
        assert merge.mask not in masks and merge.into in masks
        assert merge.overlap > 0  # into a mask over the same skin
