"""The web page's own JavaScript, run under Node.js: the activations the exported page computes
from its links' gains and response curves are the studio's, for random links, gains, curves and
pose mixes. The page's script is taken from the exported ``index.html`` itself (not a copy of it
in Python), its data inflated by its own code (tests/js/page_activations.cjs)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from studio.commands.export import web_look
from studio.core.formats.web_export import web_page
from studio.core.mesh.camera import OrbitCamera
from studio.core.project.model import Project
from studio.core.sample.synthetic import make_test_face
from studio.core.wrinkles.response import ResponseCurve

HARNESS = Path(__file__).parent / "js" / "page_activations.cjs"


def node() -> str:
    found = shutil.which("node")
    if found is None:
        pytest.fail("Node.js is not installed: run 'bash scripts/setup.sh' (it installs the "
                    "Debian packages in resources/debian-packages.txt) or apt-get install nodejs")
    return found


def page_activations(page: Path, weights: np.ndarray, wanted: str = "activations"
                     ) -> np.ndarray:
    """What the page's ``Face.activations`` gives for each row of pose weights (``wanted``
    "rest": the rest technique 2 measures from, after the page's ``Face.deform``)."""
    done = subprocess.run([node(), str(HARNESS), str(page), wanted],
                          input=json.dumps(weights.tolist()),
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return np.asarray(json.loads(done.stdout))


def random_curve(rng: np.random.Generator) -> ResponseCurve:
    kind = str(rng.choice(["linear", "ease_in", "ease_out", "ease_in_out", "smooth_step",
                           "custom"]))
    if kind == "smooth_step":
        start, end = sorted(rng.uniform(0, 1, 2))
        return ResponseCurve(kind, float(start), float(max(end, start + 0.05)))
    if kind == "custom":
        xs = np.sort(rng.choice(np.linspace(0, 1, 21), int(rng.integers(2, 6)), replace=False))
        return ResponseCurve(kind, points=tuple((float(x), float(rng.uniform(0, 1)))
                                                for x in xs))
    return ResponseCurve(kind)


def random_links(project: Project, rng: np.random.Generator) -> None:
    """Every pose linked to a random few areas, with gains mostly below 1 (where a dropped gain
    shows: above 1 the clamp hides much of it) and a random curve each."""
    influence = project.influence
    areas = [a.name for a in influence.areas]
    influence.links = {}
    influence.curves = {}
    for pose in project.poses:
        chosen = rng.choice(areas, int(rng.integers(1, 4)), replace=False)
        influence.links[pose.name] = {str(a): float(rng.choice([rng.uniform(0.05, 0.95),
                                                                 rng.uniform(1.0, 2.5)],
                                                                p=[0.8, 0.2]))
                                      for a in chosen}
        influence.curves[pose.name] = {str(a): random_curve(rng) for a in chosen}
    influence.areas[int(rng.integers(len(areas)))].activation = float(rng.uniform(0, 0.4))
    influence.areas[int(rng.integers(len(areas)))].visible = False


@pytest.mark.parametrize("seed", [3, 17, 50])
def test_the_page_s_script_gives_the_studio_s_activations_for_random_links(tmp_path, seed):
    rng = np.random.default_rng(seed)
    project = make_test_face(561, texture_size=64, mask_size=32)
    random_links(project, rng)
    page = tmp_path / "index.html"
    page.write_text(web_page(project, OrbitCamera(), web_look()), encoding="utf-8")
    names = [p.name for p in project.poses]
    weights = np.concatenate([
        np.eye(len(names)),  # each pose alone at 1
        rng.uniform(0, 1, (20, len(names))) * (rng.uniform(0, 1, (20, len(names))) < 0.5),
        rng.uniform(0, 1, (10, len(names)))])
    on_page = page_activations(page, weights)
    for row, got in zip(weights, on_page, strict=True):
        mix = dict(zip(names, row.tolist(), strict=True))
        np.testing.assert_allclose(got, project.influence.activations(mix), atol=2e-3,
                                   err_msg=str(mix))
    assert np.ptp(on_page) > 0.5  # the mixes reach well into the activations' range
