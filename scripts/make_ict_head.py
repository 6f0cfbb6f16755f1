#!/usr/bin/env python3
"""Packs the ICT-FaceKit light head (MIT, ../shared/data/ict-facekit) into the studio's bundled
sample resource, ``resources/ict_head/ict_head.npz``, with its licence and credits beside it.

    .venv/bin/python scripts/make_ict_head.py [ICT_FOLDER]

What is kept: the neutral mesh as the studio reads it (welded positions in centimetres, triangles
over render vertices, the UDIM UVs, the weld), which vertices are not skin (the ten eye, lash,
teeth and gum materials), and all 53 expressions as sparse offsets: per expression the vertices
it moves and their offsets as int16 steps of one scale (at most 1/65 534 of its largest offset,
well under a micrometre), and the kit's 68 landmark vertices. 3.6 MB instead of the 26 MB of
the OBJ set.
"""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studio.core.formats.assemble import project_from_files  # noqa: E402
from studio.core.sample.ict_head import NOT_SKIN_MATERIALS, resource_path  # noqa: E402


def pack(ict: Path, out: Path) -> None:
    import gzip

    with tempfile.TemporaryDirectory() as tmp:
        obj = Path(tmp) / "generic_neutral_mesh.obj"
        obj.write_bytes(gzip.decompress((ict / "generic_neutral_mesh.obj.gz").read_bytes()))
        shutil.copy(ict / "ICTFaceModelMaterial.mtl", tmp)
        project = project_from_files(obj, not_face=NOT_SKIN_MATERIALS)
    mesh = project.mesh
    udim = project.uv_tiles.udim_uvs(mesh) if project.uv_tiles is not None else mesh.uvs
    expressions = np.load(ict / "expressions.npz")
    arrays: dict[str, np.ndarray] = {
        "rest": mesh.rest, "triangles": mesh.triangles, "uvs": udim.astype(np.float32),
        "weld": mesh.weld, "not_face": project.not_face,
        "names": np.array(sorted(expressions.files)),
        # the kit's 68 facial landmarks (the iBUG 300-W order: jaw 0–16, brows 17–26, nose
        # 27–35, eyes 36–47, mouth 48–67) as welded vertex indices
        "landmarks": np.array(json.loads((ict / "vertex_indices.json").read_text())[
            "idx_to_landmark_verts"], np.int32),
    }
    for i, name in enumerate(sorted(expressions.files)):
        delta = expressions[name].astype(np.float64)
        moved = np.flatnonzero(np.abs(delta).max(axis=1) > 0.0)
        scale = float(np.abs(delta).max()) / 32767.0 or 1.0
        arrays[f"index_{i}"] = moved.astype(np.int32)
        arrays[f"steps_{i}"] = np.rint(delta[moved] / scale).astype(np.int16)
        arrays[f"scale_{i}"] = np.array(scale, np.float64)
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_suffix(".partial.npz")
    np.savez_compressed(partial, **arrays)
    partial.replace(out)
    for name in ("LICENSE", "CREDITS.md"):
        shutil.copyfile(ict / name, out.parent / name)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.1f} MB): {mesh.n_welded} vertices, "
          f"{len(expressions.files)} expressions")


if __name__ == "__main__":
    pack(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT.parent / "shared/data/ict-facekit",
         resource_path())
