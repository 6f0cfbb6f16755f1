"""An animation to files, frame by frame: numbered PNGs, an animated GIF and/or a video (with
imageio-ffmpeg). Shared by ``wrinkle-studio render --frames/--gif/--video`` and File ▸ Export
Animation, so both check their outputs, stream and write atomically the same way."""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from studio.core.files import atomic_write, budgets, safe_io
from studio.core.files.errors import StudioError
from studio.core.files.input_checks import check_frame_pattern
from studio.core.project.model import Project


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
        from studio.core.files.gif_stream import GifStream

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


def check_animation_budget(count: int, size: tuple[int, int], gif: bool,
                           source: str | None = None) -> None:
    """Refuse, before any rendering, an animation longer than the frame budget or a GIF whose
    frames hold more pixels than the GIF budget (a 10⁹-frame timeline is a 22 GB GIF)."""
    hint = "render fewer frames with --frames START:END[:STEP]"
    budgets.FRAMES.check(count, "the animation", source, StudioError, hint)
    if gif:
        budgets.GIF_PIXELS.check(count * size[0] * size[1], "the GIF's pixels (frames × width "
                                 "× height)", source, StudioError, f"{hint} or a smaller --size")
