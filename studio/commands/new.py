"""``wrinkle-studio new``: a project from a neutral mesh, key-pose meshes or a glTF with morph
targets, and texture maps."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from studio.commands.furrow_flags import add_furrow_flags, furrow_values
from studio.core.files.errors import StudioError
from studio.core.files.naming import shown, shown_list
from studio.core.mesh.file_kinds import kinds_read

EXIT_CANCELLED = 130  # as a shell reports a command stopped by Ctrl+C


def parse_pose(text: str) -> tuple[str, str]:
    name, sep, path = text.partition("=")
    if not sep or not name or not path:
        raise argparse.ArgumentTypeError(f"'{text}' is not NAME=FILE")
    return name, path


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("new", help="make a project from your own meshes and maps")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--mesh", help=f"neutral mesh ({kinds_read()}; a glTF, VRM, FBX or "
                        "USD brings its blend shapes as the key poses)")
    source.add_argument("--gltf", help="glTF or VRM with morph targets: they (a VRM's "
                        "expressions) become the key poses; "
                        "in a whole avatar the face is found (the meshes the targets move, "
                        "eyes and teeth not face, the rest left out) and said")
    p.add_argument("--pose", action="append", type=parse_pose, default=[], metavar="NAME=FILE",
                   help="a key-pose mesh with the neutral mesh's topology (repeatable)")
    p.add_argument("--diffuse", help="diffuse (skin colour) map")
    p.add_argument("--normal", help="neutral normal map (default: flat)")
    p.add_argument("--wrinkle-normal", help="wrinkled normal map (default: flat)")
    p.add_argument("--keep", action="extend", nargs="+", metavar="PART",
                   help="keep only these OBJ objects, groups or materials, or glTF meshes, "
                        "nodes or materials (repeatable; the same parts are taken from every "
                        "key pose)")
    p.add_argument("--not-face", action="extend", nargs="+", default=[], metavar="PART",
                   help="OBJ objects, groups or materials, or glTF meshes, nodes or materials "
                        "that are not skin (eyes, teeth): never wrinkled (a glTF's are "
                        "suggested when none are named)")
    p.add_argument("--up", metavar="AXIS",
                   help="the head's up axis (x, y, z, -x, -y, -z); by default found from the "
                        "poses' motion or the mesh's extent, and said")
    p.add_argument("--front", metavar="AXIS",
                   help="the way the face looks (x, y, z, -x, -y, -z), at right angles to up; "
                        "by default found from the way the moving skin faces (a VRM's own), "
                        "and said")
    p.add_argument("--flip-green", action="store_true",
                   help="the normal maps use the DirectX convention (green down)")
    p.add_argument("--auto", action="store_true",
                   help="a starting point for both techniques: for each key pose, wrinkle "
                        "vectors where it moves the skin and a soft mask where it compresses it "
                        "(and, without --wrinkle-normal, a wrinkled map synthesised from them)")
    p.add_argument("-o", "--output", required=True, help="project file to write (.wrinkle)")
    add_furrow_flags(p)
    p.set_defaults(run=run)


def _obj_choice(args: argparse.Namespace, found: list[str]
                ) -> tuple[list[str] | None, list[str] | None]:
    """(keep, not face) for ``project_from_files``: the user's, or — for an OBJ of several
    parts with ``--auto`` — the parts found (helpers, hair cards and joint markers left out;
    eyes, teeth and lashes not face), said in one line of ``found``; without ``--auto`` the
    line only suggests. What the user names wins: ``--keep`` replaces the parts left out,
    ``--not-face`` the parts not face."""
    from studio.core.formats.assemble import choose_obj_parts

    keep, not_face = args.keep, args.not_face or None
    choice = (choose_obj_parts(args.mesh, dict(args.pose))
              if args.mesh and (keep is None or not_face is None) else None)
    if choice is None:
        return keep, not_face
    if keep is not None:  # the user's parts: suggest not face among them only
        choice.face, choice.left_out = list(keep), {}
        choice.not_face = {n: why for n, why in choice.not_face.items() if n in keep}
    if not_face is not None:
        choice.not_face = {n: "named" for n in not_face}
    if not args.auto:
        if choice.left_out or (choice.not_face and args.not_face == []):
            found.append(f"suggested, applied with --auto: {choice.line()}")
        return keep, not_face
    found.append(choice.line())
    if keep is None and choice.left_out:
        keep = choice.face
    return keep, not_face if not_face is not None else (list(choice.not_face) or None)


def run(args: argparse.Namespace) -> int:
    from studio.commands.progress_bar import ProgressBar
    from studio.core.files.safe_io import check_output
    from studio.core.project.writer import save_project
    from studio.core.setup.face_frame import parse_axis
    from studio.core.setup.new_setup import new_project
    from studio.core.setup.stage_clock import StageClock, stage

    for axis in (args.up, args.front):
        if axis is not None:
            parse_axis(axis)  # a bad axis fails before any work
    check_output(args.output, [args.mesh, args.gltf, args.diffuse, args.normal,
                               args.wrinkle_normal, *(path for _, path in args.pose)],
                 what="project")
    names = [name for name, _ in args.pose]
    if len(set(names)) != len(names):
        raise StudioError("two --pose options have the same name")
    found: list[str] = []  # what was chosen in an OBJ's parts, then in the files
    keep, not_face = _obj_choice(args, found)
    out = Path(args.output)
    bar = ProgressBar()
    try:  # Ctrl+C stops it: the project file is written whole at the end, or not at all
        with StageClock(heard=bar.stage).running():
            made = new_project(args.mesh or args.gltf, dict(args.pose), args.diffuse,
                               args.normal, args.wrinkle_normal, flip=args.flip_green,
                               keep=keep, not_face=not_face, up=args.up, front=args.front,
                               auto=args.auto, progress=bar.step,
                               furrows=furrow_values(args))
            with stage("writing"):
                save_project(made.project, out)
    except KeyboardInterrupt:
        bar.close()
        print(f"cancelled: {shown(out)} not written", file=sys.stderr)
        return EXIT_CANCELLED
    bar.close()
    project, done = made.project, made.done or []
    found += made.found
    # names come from the user's files: each shown on the line it belongs to, escaped
    print(f"wrote {shown(out)}: {project.mesh.n_welded} vertices, key poses: "
          f"{shown_list((p.name for p in project.poses), limit=1000) or 'none'}")
    for line in found:
        print(shown(line, 4000))
    print(f"assumed: {made.assumed}")
    if project.uv_tiles is not None:
        print(f"UV tiles {', '.join(map(str, project.uv_tiles.layout.tiles))} packed into one "
              f"atlas (skin on {', '.join(map(str, project.skin_tiles()))})")
    if project.not_face is not None and args.not_face:
        print(f"not face ({shown_list(args.not_face)}): {int(project.not_face.sum())} "
              "vertices")
    for line in done:
        print(shown(line, 4000))
    return 0
