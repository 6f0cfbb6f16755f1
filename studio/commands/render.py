"""``wrinkle-studio render``: a project (or the bundled sample) to a PNG — one pose, or the
timeline's animation as numbered frames, an animated GIF or (with imageio-ffmpeg) a video."""

from __future__ import annotations

import argparse
import importlib.util
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np

from studio.cli import load_project_or_sample, parse_size, parse_vertices
from studio.core import atomic_write, budgets, safe_io
from studio.core.errors import StudioError
from studio.core.input_checks import check_frame_pattern, finite_float
from studio.core.project import Project
from studio.core.relief import suggested_relief_depth


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


def frame_path(pattern: str, frame: int) -> Path:
    """``out/frame_%04d.png`` with the frame number filled in."""
    check_frame_pattern(pattern)
    try:
        return Path(pattern % frame)
    except (TypeError, ValueError):
        raise StudioError(f"-o {pattern}: with --frames, name the files with a frame-number "
                          "pattern like out/frame_%04d.png") from None


def animation_weights(project: Project, frames: Sequence[float]) -> list[dict[str, float]]:
    """The pose weights at each frame (tracks evaluated for all frames at once)."""
    timeline = project.timeline
    if not timeline.has_keys:
        raise StudioError("the project has no animation (its timeline has no keys)")
    curves = {t.pose: t.values_at(frames) for t in timeline.tracks if t.keys}
    return [{pose: float(v[i]) for pose, v in curves.items()} for i in range(len(frames))]


def render_frames(studio, settings, project: Project, frames: Sequence[int]
                  ) -> Iterator[np.ndarray]:
    """Render the animation frame by frame (lazily, so a caller can stop or report progress)."""
    for weights in animation_weights(project, frames):
        yield studio.render(settings, weights)


VIDEO_MUXERS = {".mp4": "mp4", ".m4v": "mp4", ".mov": "mov", ".mkv": "matroska",
                ".webm": "webm", ".avi": "avi"}  # the video's temporary file has no suffix


def video_available() -> bool:
    return importlib.util.find_spec("imageio_ffmpeg") is not None


class AnimationWriter:
    """Frames one at a time into numbered PNGs, an animated GIF and/or an MP4."""

    def __init__(self, fps: float, pattern: str | None = None, gif: str | None = None,
                 video: str | None = None, size: tuple[int, int] = (0, 0),
                 step: int = 1, inputs: Sequence[str | Path | None] = ()) -> None:
        """Check every destination (not an input, writable) before the first frame; the GIF
        and the video go to temporary files renamed into place by :meth:`close` (``abort``
        removes them), the GIF streamed frame by frame (``step`` frames apart in time)."""
        from studio.core.gif_stream import GifStream

        self.fps, self.pattern, self.inputs = fps, pattern, list(inputs)
        self.gif, self.video = (Path(gif) if gif else None), (Path(video) if video else None)
        self.written: list[Path] = []
        self._video = None
        self._outputs: list = []  # open atomic_output contexts: (context, handle)
        if pattern is not None:
            safe_io.check_output(frame_path(pattern, 0), self.inputs, make_folders=True,
                                 what="frame")
        for path, what in ((self.gif, "GIF"), (self.video, "video")):
            if path is not None:
                safe_io.check_output(path, self.inputs, make_folders=True, what=what)
        if self.video is not None and not video_available():
            raise StudioError("--video needs imageio-ffmpeg (pip install imageio-ffmpeg)")
        self._gif = None
        if self.gif is not None:
            self._gif = GifStream(self._open(self.gif, "GIF"), 1000.0 * step / fps)
        if self.video is not None:
            import imageio_ffmpeg

            handle = self._open(self.video, "video")
            w, h = size
            muxer = VIDEO_MUXERS.get(self.video.suffix.lower(), "mp4")
            self._video = imageio_ffmpeg.write_frames(handle.name, (w, h), fps=fps,
                                                      macro_block_size=1,
                                                      output_params=["-f", muxer])
            self._video.send(None)

    def _open(self, path: Path, what: str):
        """A temporary file beside ``path`` that close() renames over it."""
        context = atomic_write.atomic_output(path, make_folders=True, what=what)
        handle = context.__enter__()
        self._outputs.append((context, handle))
        return handle

    @staticmethod
    def _mkdir(path: Path) -> None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StudioError(f"cannot create the folder: {exc.strerror or exc}",
                              path.parent) from None

    def add(self, frame: int, image: np.ndarray) -> None:
        from PIL import Image

        if self.pattern is not None:
            out = frame_path(self.pattern, frame)
            safe_io.check_output(out, self.inputs, make_folders=True, what="frame")
            with atomic_write.atomic_output(out, make_folders=True, what="image") as handle:
                Image.fromarray(image).save(handle, format="PNG")
            self.written.append(out)
        if self._gif is not None:
            self._gif.add(image)
        if self._video is not None:
            self._video.send(np.ascontiguousarray(image))

    def close(self, step: int = 1) -> None:
        """Finish the GIF and the video and rename them into place.

        GIF writers merge consecutive identical frames (adding up their durations), so a held
        pose plays for the right time but counts as one frame. (``step`` is given to the
        constructor now: the GIF is written as the frames come.)"""
        try:
            if self._video is not None:
                self._video.close()
                self._video = None
            if self._gif is not None:
                self._gif.close()
                self._gif = None
        except BaseException:
            self.abort()
            raise
        while self._outputs:
            context, _ = self._outputs.pop(0)
            context.__exit__(None, None, None)

    def abort(self) -> None:
        """Stop without writing the GIF or video (their temporary files are removed); frames
        already written stay."""
        import contextlib

        if self._video is not None:
            with contextlib.suppress(Exception):
                self._video.close()
            self._video = None
        self._gif = None
        while self._outputs:
            context, _ = self._outputs.pop()
            with contextlib.suppress(StudioError):
                context.__exit__(StudioError, StudioError("aborted"), None)


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a project (or the bundled sample) to a PNG, or "
                                      "its animation to frames, a GIF or a video")
    p.add_argument("project", nargs="?", help="a .wrinkle project (default: the bundled sample)")
    p.add_argument("--technique", choices=("none", "t1", "t2", "strain", "flat"), default="t2")
    p.add_argument("--pose", default="neutral", help="key pose to show (default: neutral)")
    p.add_argument("--weight", type=finite_float, default=1.0, help="weight of that pose, 0..1")
    p.add_argument("--size", type=parse_size, default=(1280, 720), help="WxH (default 1280x720)")
    p.add_argument("--vertices", type=parse_vertices, help="resolution of the bundled sample")
    p.add_argument("--view", choices=("shaded", "heat", "normals", "uv"), default="shaded",
                   help="debug view (heat = wrinkle visibility)")
    p.add_argument("--wireframe", action="store_true", help="draw the triangle edges on top")
    p.add_argument("--blend", choices=("colour", "normal"), default="colour",
                   help="mix two shaded colours (the thesis) or the two normals (light once)")
    p.add_argument("--relief", choices=("off", "displace", "parallax"), default="off",
                   help="wrinkles in depth: displace the surface (tessellation, OpenGL 4.0; "
                        "shows in silhouette) or parallax mapping (cheaper, not in silhouette)")
    p.add_argument("--relief-depth", type=parse_depth, metavar="D",
                   help="depth of the deepest wrinkle in model units (default: 1.4%% of the "
                        "face's size, 0.03 for the sample face)")
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
        _aim(studio, args)
        image = studio.render(_settings(args, project), weights)
    with atomic_write.atomic_output(out, make_folders=True, what="image") as handle:
        Image.fromarray(image).save(handle, format="PNG")
    relief = "" if args.relief == "off" else f", relief {args.relief}"
    print(f"wrote {out} ({args.size[0]}x{args.size[1]}, {args.technique}{relief}, "
          f"pose {args.pose})")
    return 0


def _settings(args: argparse.Namespace, project: Project):
    from studio.render.renderer import RenderSettings

    depth = args.relief_depth
    if depth is None:
        depth = suggested_relief_depth(*project.mesh.bounds())
    return RenderSettings(technique=args.technique, view=args.view, wireframe=args.wireframe,
                          blend=args.blend, relief=args.relief, relief_depth=depth)


def _aim(studio, args: argparse.Namespace) -> None:
    if args.yaw is not None:
        studio.camera.yaw = args.yaw
    if args.pitch is not None:
        studio.camera.pitch = args.pitch


def check_animation_budget(count: int, size: tuple[int, int], gif: bool,
                           source: str | None = None) -> None:
    """Refuse, before any rendering, an animation longer than the frame budget or a GIF whose
    frames hold more pixels than the GIF budget (a 10⁹-frame timeline is a 22 GB GIF)."""
    hint = "render fewer frames with --frames START:END[:STEP]"
    budgets.FRAMES.check(count, "the animation", source, StudioError, hint)
    if gif:
        budgets.GIF_PIXELS.check(count * size[0] * size[1], "the GIF's pixels (frames × width "
                                 "× height)", source, StudioError, f"{hint} or a smaller --size")


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
    frames = range(start, end, step)
    check_animation_budget(len(frames), args.size, args.gif is not None, args.project)
    animation_weights(project, frames[:1])  # no keys: say so before opening a context
    writer = AnimationWriter(timeline.fps, args.output, args.gif, args.video, args.size,
                             step, [args.project])
    try:
        with OffscreenStudio(project, *args.size) as studio:
            _aim(studio, args)
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
    outputs = [str(p) for p in (writer.written[:1] if writer.written else [])]
    if writer.written:
        outputs = [f"{len(writer.written)} frames ({writer.written[0]} …)"]
    outputs += [str(p) for p in (writer.gif, writer.video) if p is not None]
    print(f"wrote {', '.join(outputs)} ({args.size[0]}x{args.size[1]}, {args.technique}, "
          f"frames {start}:{end}:{step} at {timeline.fps:g} fps)")
    return 0
