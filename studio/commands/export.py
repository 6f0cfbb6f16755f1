"""``wrinkle-studio export``: a project out to an engine (glTF, masks, links, GLSL)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from studio.commands.options import add_look_options
from studio.core.engines.layouts import LAYOUTS

if TYPE_CHECKING:
    from studio.core.formats.web_export import WebLook


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("export", help="export a project as glTF, or a folder for an engine")
    p.add_argument("project", help="the .wrinkle project")
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument("--gltf", help="binary glTF file to write (.glb)")
    target.add_argument("--folder", help="folder for face.glb, mask PNGs, wrinkles.json, GLSL "
                                          "and blender_wrinkles.py (technique 1 in Blender)")
    target.add_argument("--usd", metavar="FILE.usdz",
                        help="USD package to write (.usdz): the mesh, its blend shapes, the "
                             "maps and masks, the set-up as custom data")
    target.add_argument("--web", metavar="DIR",
                        help="folder for index.html: a page that plays the face with both "
                             "techniques in any browser, offline (?pose=NAME&weight=W&"
                             "technique=none|t1|t2 links to a pose)")
    p.add_argument("--bits", type=int, choices=(8, 16), default=16, help="per-area mask depth")
    add_look_options(p)  # the web page's
    p.add_argument("--layout", choices=list(LAYOUTS),
                   help="with --folder: repack masks and wrinkle maps the way that engine's "
                        "shader samples them, with a JSON sheet of its names (see "
                        "docs/engines/)")
    p.add_argument("--merge-weakest", action="store_true",
                   help="with --layout: where the engine blends fewer masks than the project "
                        "has (o3de: 16), merge the weakest into the ones they overlap most "
                        "instead of refusing")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.engines.export import export_layout
    from studio.core.engines.plan import LayoutError
    from studio.core.files.errors import StudioError
    from studio.core.files.safe_io import check_output, check_output_folder
    from studio.core.formats.export import export_folder
    from studio.core.formats.gltf.codec import save_gltf
    from studio.core.project.reader import load_project

    if args.web:
        return run_web(args)
    if args.usd:
        return run_usd(args)
    if args.gltf:
        if args.layout:
            raise StudioError("--layout needs --folder: a layout is several textures and a sheet")
        check_output(args.gltf, [args.project], what="glTF file")
    else:
        check_output_folder(args.folder, what="export folder")
    project = load_project(Path(args.project))
    if args.gltf:
        beside = save_gltf(project, Path(args.gltf))
        print(f"wrote {args.gltf} (beside it: {', '.join(p.name for p in beside)})")
    elif args.layout:
        try:
            plan, files = export_layout(project, args.folder, args.layout, args.bits,
                                        inputs=[args.project], merge=args.merge_weakest)
        except LayoutError as exc:  # the project does not fit the engine: say which project
            offer = " (export again with --merge-weakest)" if exc.mergeable else ""
            raise StudioError(exc.problem + offer, args.project) from None
        print(f"wrote {len(files)} files to {args.folder} ({plan.layout.label}: "
              f"{plan.samplers} samplers)")
        for merge in plan.merged:
            print(f"merged: {merge.describe()}")
        for area, why in plan.unassigned:
            print(f"not exported: area '{area}': {why}")
    else:
        files = export_folder(project, args.folder, args.bits)
        print(f"wrote {len(files)} files to {args.folder}")
    return 0


def run_usd(args: argparse.Namespace) -> int:
    """The face as one USD package (core/formats/usd/writer.py)."""
    from studio.core.files.errors import StudioError
    from studio.core.files.safe_io import check_output
    from studio.core.formats.usd.writer import save_usdz
    from studio.core.project.reader import load_project

    if args.layout:
        raise StudioError("--layout needs --folder: a layout is several textures and a sheet")
    if Path(args.usd).suffix.lower() != ".usdz":
        raise StudioError("--usd writes a .usdz package (the stage and its textures in one "
                          "file): name the file .usdz", args.usd)
    check_output(args.usd, [args.project], what="USD package")
    save_usdz(load_project(Path(args.project)), Path(args.usd))
    print(f"wrote {args.usd}")
    return 0


def run_web(args: argparse.Namespace) -> int:
    """The web player, seen as ``render --frame face --yaw 0`` sees the face and lit as
    ``render`` lights it, so that the page and the studio's picture of a pose agree."""
    from studio.core.files.errors import StudioError
    from studio.core.files.safe_io import check_output_folder
    from studio.core.formats.web_export import export_web
    from studio.core.mesh.camera import OrbitCamera
    from studio.core.project.reader import load_project
    from studio.core.setup.face_frame import aim

    if args.layout:
        raise StudioError("--layout needs --folder: a layout is several textures and a sheet")
    check_output_folder(args.web, what="web folder")
    project = load_project(Path(args.project))
    camera = OrbitCamera.from_dict(project.view.get("camera", {}))
    aim(camera, project, "face")
    camera.yaw = 0.0
    files = export_web(project, args.web, camera, web_look(args.look, args.light_rig))
    size = sum(f.stat().st_size for f in files)
    print(f"wrote {files[0]} ({size / 1e6:.1f} MB; open it in a browser, no network needed)")
    return 0


def web_look(look: str = "clay", light_rig: str = "studio") -> WebLook:
    """The light, blend and tangent frame ``render`` draws with (its default view, in this
    look), for the web page."""
    from studio.core.project.view_settings import ViewSettings
    from studio.render.settings import web_look as look_of

    return look_of(ViewSettings(look=look, light_rig=light_rig))
