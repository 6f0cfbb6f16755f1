"""``wrinkle-studio render``: a project (or the bundled sample) to a PNG — one pose, or the
timeline's animation as numbered frames, an animated GIF or (with imageio-ffmpeg) a video."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from studio.commands.options import (
    add_look_options,
    load_project_or_sample,
    parse_size,
    parse_vertices,
)
from studio.core.files import atomic_write, safe_io
from studio.core.files.errors import StudioError
from studio.core.files.input_checks import finite_float
from studio.core.files.naming import shown
from studio.core.project.model import Project
from studio.core.project.view_settings import BLENDS, DEBUG_VIEWS, RELIEFS, ViewSettings
from studio.core.setup.face_frame import aim, parse_axis
from studio.core.wrinkles.relief import suggested_relief_depth
from studio.core.wrinkles.techniques import TECHNIQUES
from studio.render.animation import (
    AnimationWriter,
    animation_weights,
    check_animation_budget,
    frame_path,
    video_available,
)


def parse_frames(text: str) -> tuple[int, int, int]:
    """``START:END[:STEP]`` like a Python slice: END itself is not rendered."""
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        start, end = int(parts[0]), int(parts[1])
        step = int(parts[2]) if len(parts) == 3 else 1
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a frame range like 0:96 or 0:96:2"
                                         ) from None
    if step < 1:
        raise argparse.ArgumentTypeError(f"'{text}': the step must be at least 1")
    if end <= start:
        raise argparse.ArgumentTypeError(f"'{text}': the end frame must come after the start")
    if end - start > 100_000 * step:
        raise argparse.ArgumentTypeError(f"'{text}': more than 100000 frames")
    return start, end, step


def parse_depth(text: str) -> float:
    """A relief depth: a finite number, 0 or more (model units)."""
    try:
        depth = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not 0.0 <= depth < float("inf"):
        raise argparse.ArgumentTypeError(f"'{text}': the relief depth must be 0 or more")
    return depth


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a project (or the bundled sample) to a PNG, or "
                                      "its animation to frames, a GIF or a video")
    p.add_argument("project", nargs="?", help="a .wrinkle project (default: the bundled sample)")
    p.add_argument("--technique", choices=tuple(TECHNIQUES), default="t2",
                   help="; ".join(f"{t.key}: {t.label}" for t in TECHNIQUES.values()))
    p.add_argument("--pose", default="neutral", help="key pose to show (default: neutral)")
    p.add_argument("--weight", type=finite_float, default=1.0, help="weight of that pose, 0..1")
    p.add_argument("--size", type=parse_size, default=(1280, 720), help="WxH (default 1280x720)")
    p.add_argument("--vertices", type=parse_vertices,
                   help="render the procedural test face (the thesis's study) at this many "
                        "vertices instead of the bundled sample head")
    p.add_argument("--view", choices=DEBUG_VIEWS, default="shaded",
                   help="debug view (heat: the wrinkle weight; heat-shows: the weight times how "
                        "much the revealed wrinkled map differs from the neutral one)")
    p.add_argument("--wireframe", action="store_true", help="draw the triangle edges on top")
    add_look_options(p)
    p.add_argument("--blend", choices=BLENDS, default="colour",
                   help="mix two shaded colours (the thesis) or the two normals (light once)")
    p.add_argument("--relief", choices=RELIEFS, default="off",
                   help="wrinkles in depth: displace the surface (tessellation, OpenGL 4.0; "
                        "shows in silhouette) or parallax mapping (cheaper, not in silhouette)")
    p.add_argument("--relief-depth", type=parse_depth, metavar="D",
                   help="depth of the deepest wrinkle in model units (default: 1.4%% of the "
                        "face's size, 0.03 for the sample face)")
    p.add_argument("--frame", choices=("face", "all"),
                   help="frame the face (the skin the poses deform) or the whole mesh, seen "
                        "from the face's front (default: the project's saved camera, else face)")
    p.add_argument("--up", type=parse_up, metavar="AXIS",
                   help="the head's up axis (x, y, z, -x, -y, -z) when the detected one is "
                        "wrong")
    p.add_argument("--yaw", type=finite_float,
                   help="camera yaw in degrees (0 = front, 90 = profile)")
    p.add_argument("--pitch", type=finite_float, help="camera pitch in degrees")
    p.add_argument("--frames", type=parse_frames, metavar="START:END[:STEP]",
                   help="render the timeline's animation, frames START up to (not including) END "
                        "at the project's frame rate; -o then names the files, e.g. "
                        "out/frame_%%04d.png")
    p.add_argument("--gif", metavar="OUT.gif", help="write the animation as an animated GIF "
                                                    "(the whole timeline unless --frames)")
    p.add_argument("--video", metavar="OUT.mp4", help="write the animation as a video "
                                                      "(needs imageio-ffmpeg)")
    p.add_argument("-o", "--output", help="PNG file to write (a pattern with --frames)")
    p.set_defaults(run=run_render)


def run_render(args: argparse.Namespace) -> int:
    if args.frames is not None or args.gif or args.video:
        return run_animation(args)
    if not args.output:
        raise StudioError("say where to write the image: -o OUT.png")
    from PIL import Image

    from studio.render.offscreen import OffscreenStudio

    if not 0.0 <= args.weight <= 1.0:
        raise StudioError(f"--weight {args.weight}: a pose weight is between 0 and 1")
    out = safe_io.check_output(args.output, [args.project], make_folders=True, what="image")
    project = load_project_or_sample(args.project, args.vertices)
    weights = project.single_pose_weights(args.pose, args.weight)
    with OffscreenStudio(project, *args.size) as studio:
        _aim(studio, args, project)
        image = studio.render(_settings(args, project), weights)
    with atomic_write.atomic_output(out, make_folders=True, what="image") as handle:
        Image.fromarray(image).save(handle, format="PNG")
    relief = "" if args.relief == "off" else f", relief {args.relief}"
    print(f"wrote {shown(out)} ({args.size[0]}x{args.size[1]}, {args.technique}{relief}, "
          f"pose {shown(args.pose)})")
    return 0


def _settings(args: argparse.Namespace, project: Project):
    """The command line's view model, drawn the way the viewport draws its own."""
    from studio.render.settings import render_settings

    depth = args.relief_depth
    if depth is None:
        depth = suggested_relief_depth(*project.mesh.bounds())
    view = ViewSettings(technique=args.technique, debug_view=args.view,
                        wireframe=args.wireframe, blend=args.blend, relief=args.relief,
                        look=args.look, light_rig=args.light_rig,
                        relief_depth=depth)
    return render_settings(view)


def parse_up(text: str) -> str:
    try:
        parse_axis(text)
    except StudioError as exc:
        raise argparse.ArgumentTypeError(exc.problem) from None
    return text


def _aim(studio, args: argparse.Namespace, project: Project) -> None:
    """The camera the options ask for: re-aimed at the face or the whole mesh when --frame or
    --up is given (else the project's own), then turned by --yaw and --pitch."""
    if args.up is not None:
        project.view["up"] = args.up
    if args.frame is not None or args.up is not None:
        aim(studio.camera, project, args.frame or "face")
    if args.yaw is not None:
        studio.camera.yaw = args.yaw
    if args.pitch is not None:
        studio.camera.pitch = args.pitch


def run_animation(args: argparse.Namespace,
                  progress: Callable[[int, int], None] | None = None) -> int:
    from studio.render.offscreen import OffscreenStudio

    if args.frames is not None and not args.output and not args.gif and not args.video:
        raise StudioError("say where to write the frames: -o out/frame_%04d.png (or --gif)")
    if args.frames is None and args.output:
        raise StudioError("-o with an animation needs --frames START:END[:STEP]")
    if args.video and not video_available():
        raise StudioError("--video needs imageio-ffmpeg, which is not installed "
                          "(pip install imageio-ffmpeg)")
    if args.output:
        frame_path(args.output, 0)  # a bad pattern fails before any rendering
    project = load_project_or_sample(args.project, args.vertices)
    timeline = project.timeline
    start, end, step = args.frames or (timeline.start, timeline.end + 1, 1)
    # counted before a range is made: len() of a range past 2**63 frames raises OverflowError
    check_animation_budget(max(0, -(-(end - start) // step)), args.size, args.gif is not None,
                           args.project)
    frames = range(start, end, step)
    animation_weights(project, frames[:1])  # no keys: say so before opening a context
    writer = AnimationWriter(timeline.fps, args.output, args.gif, args.video, args.size,
                             step, [args.project])
    try:
        with OffscreenStudio(project, *args.size) as studio:
            _aim(studio, args, project)
            for i, frame in enumerate(frames):  # weights frame by frame: memory stays flat
                image = studio.render(_settings(args, project),
                                      animation_weights(project, [frame])[0])
                writer.add(frame, image)
                if progress is not None:
                    progress(i + 1, len(frames))
    except BaseException:
        writer.abort()
        raise
    writer.close(step)
    outputs = [shown(p) for p in (writer.written[:1] if writer.written else [])]
    if writer.written:
        outputs = [f"{len(writer.written)} frames ({shown(writer.written[0])} …)"]
    outputs += [shown(p) for p in (writer.gif, writer.video) if p is not None]
    print(f"wrote {', '.join(outputs)} ({args.size[0]}x{args.size[1]}, {args.technique}, "
          f"frames {start}:{end}:{step} at {timeline.fps:g} fps)")
    return 0
