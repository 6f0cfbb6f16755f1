"""An animation to files, frame by frame: numbered PNGs, an animated GIF and/or an MP4 (with
imageio-ffmpeg). Shared by ``wrinkle-studio render --frames/--gif/--video`` and File ▸ Export
Animation, so both write the same files the same way."""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from studio.core.errors import StudioError
from studio.core.project import Project


def frame_path(pattern: str, frame: int) -> Path:
    """``out/frame_%04d.png`` with the frame number filled in."""
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


def video_available() -> bool:
    return importlib.util.find_spec("imageio_ffmpeg") is not None


class AnimationWriter:
    """Frames one at a time into numbered PNGs, an animated GIF and/or an MP4."""

    def __init__(self, fps: float, pattern: str | None = None, gif: str | None = None,
                 video: str | None = None, size: tuple[int, int] = (0, 0)) -> None:
        self.fps, self.pattern = fps, pattern
        self.gif, self.video = (Path(gif) if gif else None), (Path(video) if video else None)
        self.written: list[Path] = []
        self._gif_frames: list = []
        self._video = None
        if self.video is not None:
            if not video_available():
                raise StudioError("--video needs imageio-ffmpeg (pip install imageio-ffmpeg)")
            import imageio_ffmpeg

            self._mkdir(self.video)
            w, h = size
            self._video = imageio_ffmpeg.write_frames(str(self.video), (w, h), fps=fps,
                                                      macro_block_size=1)
            self._video.send(None)
        for path in (self.gif,):
            if path is not None:
                self._mkdir(path)

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
            if not self.written:
                self._mkdir(out)
            try:
                Image.fromarray(image).save(out)
            except OSError as exc:
                raise StudioError(f"cannot write the image: {exc.strerror or exc}", out) from None
            self.written.append(out)
        if self.gif is not None:
            self._gif_frames.append(Image.fromarray(image).quantize(colors=255, dither=0))
        if self._video is not None:
            self._video.send(np.ascontiguousarray(image))

    def close(self, step: int = 1) -> None:
        """Finish the GIF (one frame per rendered frame, ``step`` frames apart) and the video.

        GIF writers merge consecutive identical frames (adding up their durations), so a held
        pose plays for the right time but counts as one frame."""
        if self._video is not None:
            self._video.close()
            self._video = None
        if self.gif is not None and self._gif_frames:
            first, *rest = self._gif_frames
            try:
                first.save(self.gif, save_all=True, append_images=rest, loop=0,
                           duration=max(round(1000.0 * step / self.fps), 10), disposal=1)
            except OSError as exc:
                raise StudioError(f"cannot write the GIF: {exc.strerror or exc}",
                                  self.gif) from None
            self._gif_frames = []
