"""``wrinkle-studio sample``: write the bundled sample (the ICT-FaceKit head, set up) as a
project file, or the procedural test face at a given resolution."""

from __future__ import annotations

import argparse

from studio.commands.options import load_project_or_sample, parse_vertices


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sample", help="write the bundled sample head as a .wrinkle project")
    p.add_argument("-o", "--output", required=True, help="project file to write")
    p.add_argument("--vertices", type=parse_vertices,
                   help="write the procedural test face with this many vertices instead")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.files.safe_io import check_output
    from studio.core.project.writer import save_project

    out = check_output(args.output, what="project")
    project = load_project_or_sample(None, args.vertices)
    save_project(project, out)
    what = (f"procedural test face, {args.vertices} vertices" if args.vertices else
            f"{project.name}, {project.mesh.n_welded} vertices, {len(project.poses)} poses")
    print(f"wrote {out} ({what})")
    return 0
