"""``wrinkle-studio export``: a project out to an engine (glTF, masks, links, GLSL)."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("export", help="export a project as glTF, or a folder for an engine")
    p.add_argument("project", help="the .wrinkle project")
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument("--gltf", help="binary glTF file to write (.glb)")
    target.add_argument("--folder", help="folder for face.glb, mask PNGs, wrinkles.json, GLSL")
    p.add_argument("--bits", type=int, choices=(8, 16), default=16, help="per-area mask depth")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.files.safe_io import check_output
    from studio.core.project.export import export_folder
    from studio.core.project.gltf import save_gltf
    from studio.core.project.reader import load_project

    if args.gltf:
        check_output(args.gltf, [args.project], what="glTF file")
    else:
        check_output(args.folder, [args.project], make_folders=True, what="folder")
    project = load_project(Path(args.project))
    if args.gltf:
        save_gltf(project, Path(args.gltf))
        print(f"wrote {args.gltf}")
    else:
        files = export_folder(project, args.folder, args.bits)
        print(f"wrote {len(files)} files to {args.folder}")
    return 0
