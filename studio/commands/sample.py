"""``wrinkle-studio sample``: write the bundled sample face as a project file."""

from __future__ import annotations

import argparse

from studio.commands.options import parse_vertices


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sample", help="write the bundled sample face as a .wrinkle project")
    p.add_argument("-o", "--output", required=True, help="project file to write")
    p.add_argument("--vertices", type=parse_vertices, default=2172,
                   help="vertex count of the sample face (default 2172)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.files.safe_io import check_output
    from studio.core.project.sample import make_sample
    from studio.core.project.writer import save_project

    out = check_output(args.output, what="project")
    save_project(make_sample(args.vertices), out)
    print(f"wrote {out} (sample face, {args.vertices} vertices)")
    return 0
