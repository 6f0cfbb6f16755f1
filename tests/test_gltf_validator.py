"""The Khronos glTF validator over every kind of export: 0 errors and 0 warnings.

It is the npm package ``gltf-validator`` that ``scripts/setup.sh test`` installs into
``.node/`` (Node.js from the Debian packages), run by ``scripts/validate_gltf.js``. Without it
the test fails and says how to install it: a validator that is silently skipped proves nothing.
"""

from __future__ import annotations

import io
import json
import shutil
import subprocess
from contextlib import redirect_stdout
from pathlib import Path

import pytest

from studio.cli import main
from studio.core.animation.timeline import Timeline, sequence_all_poses
from studio.core.formats.export import export_folder
from studio.core.formats.gltf.codec import save_gltf
from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face
from tests.test_production_head import import_head

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "validate_gltf.js"


def validate(paths: list[Path]) -> list[dict]:
    """One validator report per file: its counts and messages."""
    node = shutil.which("node")
    if node is None or not (ROOT / ".node" / "node_modules" / "gltf-validator").is_dir():
        pytest.fail("the glTF validator is not installed: run 'bash scripts/setup.sh test' "
                    "(Node.js, and npm install --prefix .node gltf-validator)")
    done = subprocess.run([node, str(SCRIPT), *map(str, paths)], capture_output=True,
                          text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in done.stdout.splitlines()]


@pytest.fixture(scope="module")
def exports(tmp_path_factory) -> list[Path]:
    """The sample (with its timeline: an animation), the sample in the thesis's frame with no
    keys and no influence areas, the engine folder's GLB, and a production head (millimetres,
    Z up, UDIM tiles, ARKit poses) with every pose sequenced."""
    folder = tmp_path_factory.mktemp("exports")
    sample = make_test_face(1071, texture_size=128, mask_size=64)
    assert sample.timeline.has_keys
    save_gltf(sample, folder / "sample.glb")
    bare = make_test_face(561, texture_size=64, mask_size=32)
    bare.timeline = Timeline()
    bare.influence.areas.clear()
    save_gltf(bare, folder / "bare.glb", tangent_frame="thesis")
    export_folder(sample, folder / "engine")
    head_folder = folder / "head"
    _, args = import_head(head_folder, textures=True)
    with redirect_stdout(io.StringIO()):
        assert main(args) == 0
    head = load_project(head_folder / "mm.wrinkle")
    assert head.uv_tiles is not None
    head.timeline = sequence_all_poses([p.name for p in head.poses], interpolation="smooth")
    save_gltf(head, folder / "head.glb")
    return [folder / "sample.glb", folder / "bare.glb", folder / "engine" / "face.glb",
            folder / "head.glb"]


def test_every_export_is_valid_without_warnings(exports):
    reports = validate(exports)
    assert len(reports) == len(exports)
    for report in reports:
        problems = [m for m in report["messages"] if m["severity"] <= 1]  # errors, warnings
        assert (report["errors"], report["warnings"]) == (0, 0), (report["file"], problems)


def test_no_exported_map_or_mask_is_an_unused_object(exports):
    """Masks and further wrinkled maps are KHR_materials_variants materials, which the
    validator follows: none of their images is reported unused (an information). TEXCOORD_1
    is, by design: no material samples it, it carries the studio's welding through tools that
    drop custom attributes (core/formats/gltf/carry.py); so are the buffer views of
    extras.wrinklePlayer, which no accessor reads and wrinkles.js does."""
    for path, report in zip(exports[:1] + exports[3:], validate(exports[:1] + exports[3:]),
                            strict=True):
        unused = [m["pointer"] for m in report["messages"] if m["code"] == "UNUSED_OBJECT"]
        data = path.read_bytes()
        doc = json.loads(data[20:20 + int.from_bytes(data[12:16], "little")])
        player = [f"/bufferViews/{spec['bufferView']}"
                  for spec in doc["extras"]["wrinklePlayer"]["arrays"].values()]
        assert sorted(unused) == sorted(["/meshes/0/primitives/0/attributes/TEXCOORD_1",
                                         *player]), path
