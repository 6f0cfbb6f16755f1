"""``wrinkle-studio capture``: an ARKit blend-shape take (Live Link Face CSV, or a glTF animation
of morph weights) keyed onto a project's timeline, as File ▸ Import Capture… does in the studio
(studio/core/formats/capture.py)."""

from __future__ import annotations

import argparse
from pathlib import Path


def parse_fps(text: str) -> float:
    try:
        fps = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not 0 < fps <= 1000:
        raise argparse.ArgumentTypeError(f"{text}: the frame rate must be above 0, at most 1000")
    return fps


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("capture", help="key a facial capture take onto a project's timeline")
    p.add_argument("project", help="the .wrinkle project whose key poses the take drives")
    take = p.add_mutually_exclusive_group(required=True)
    take.add_argument("--csv", metavar="TAKE.csv",
                      help="a Live Link Face take: Timecode, BlendShapeCount, ARKit columns")
    take.add_argument("--gltf", metavar="TAKE.glb",
                      help="a glTF animation of morph weights (targets named in "
                           "mesh.extras.targetNames)")
    p.add_argument("--fps", type=parse_fps, metavar="N",
                   help="the timeline's frame rate to resample to (default: the project's)")
    p.add_argument("--take-fps", type=parse_fps, metavar="N",
                   help="the take's own frame rate (default: 60 if its timecodes reach frame "
                        "30, else 30)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.wrinkle",
                   help="where to write the project with the take on its timeline")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.files.safe_io import check_output
    from studio.core.formats.capture import apply_take, read_gltf_take, read_live_link_csv
    from studio.core.project.reader import load_project
    from studio.core.project.writer import save_project

    check_output(args.output, [args.project, args.csv or args.gltf], what="project")
    project = load_project(Path(args.project))
    take = (read_live_link_csv(args.csv, args.take_fps) if args.csv
            else read_gltf_take(args.gltf))
    timeline, report = apply_take(project.timeline, take, [p.name for p in project.poses],
                                  args.fps)
    project.timeline = timeline
    save_project(project, Path(args.output))
    print("\n".join(report.lines()))
    print(f"wrote {args.output}")
    return 0
