"""``wrinkle-studio render``: a project (or the bundled sample) to a PNG, without a screen."""

from __future__ import annotations

import argparse
from pathlib import Path

from studio.cli import load_project_or_sample, parse_size, parse_vertices
from studio.core.errors import StudioError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a project (or the bundled sample) to a PNG")
    p.add_argument("project", nargs="?", help="a .wrinkle project (default: the bundled sample)")
    p.add_argument("--technique", choices=("none", "t1", "t2", "flat"), default="t2")
    p.add_argument("--pose", default="neutral", help="key pose to show (default: neutral)")
    p.add_argument("--weight", type=float, default=1.0, help="weight of that pose, 0..1")
    p.add_argument("--size", type=parse_size, default=(1280, 720), help="WxH (default 1280x720)")
    p.add_argument("--vertices", type=parse_vertices, help="resolution of the bundled sample")
    p.add_argument("--view", choices=("shaded", "heat", "normals", "uv"), default="shaded",
                   help="debug view (heat = wrinkle visibility)")
    p.add_argument("--wireframe", action="store_true", help="draw the triangle edges on top")
    p.add_argument("--yaw", type=float, help="camera yaw in degrees (0 = front, 90 = profile)")
    p.add_argument("--pitch", type=float, help="camera pitch in degrees")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.set_defaults(run=run_render)


def run_render(args: argparse.Namespace) -> int:
    from PIL import Image

    from studio.render.offscreen import OffscreenStudio
    from studio.render.renderer import RenderSettings

    if not 0.0 <= args.weight <= 1.0:
        raise StudioError(f"--weight {args.weight}: a pose weight is between 0 and 1")
    project = load_project_or_sample(args.project, args.vertices)
    weights = project.single_pose_weights(args.pose, args.weight)
    settings = RenderSettings(technique=args.technique, view=args.view, wireframe=args.wireframe)
    with OffscreenStudio(project, *args.size) as studio:
        if args.yaw is not None:
            studio.camera.yaw = args.yaw
        if args.pitch is not None:
            studio.camera.pitch = args.pitch
        image = studio.render(settings, weights)
    out = Path(args.output)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(image).save(out)
    except OSError as exc:
        raise StudioError(f"cannot write the image: {exc.strerror or exc}", out) from None
    print(f"wrote {out} ({args.size[0]}x{args.size[1]}, {args.technique}, pose {args.pose})")
    return 0
