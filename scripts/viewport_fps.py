"""Frames a second of the viewport while the user orbits, driven by real mouse events (issue #29:
at least 20 on a software renderer at 1728 × 972 on the ICT head).

Run it under a virtual screen: ``xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python
scripts/viewport_fps.py [project.wrinkle]`` (default: the bundled sample head). The window is
sized so that the viewport is ``--size`` device pixels, the middle button is pressed on the
viewport and the mouse moves a few pixels every ``--interval`` ms for ``--seconds``, as a hand
does; the frames the viewport finished in that time over the time give the rate. Then the button
is released and the full-size frame that follows is timed too. ``--play`` plays the timeline
instead and says how many of its frames were drawn and skipped. Settings are kept in a throwaway
folder, never the user's.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("project", nargs="?", type=Path, help="a .wrinkle project (default: sample)")
    p.add_argument("--size", default="1728x972", help="the viewport's size in pixels")
    p.add_argument("--seconds", type=float, default=6.0, help="how long to orbit")
    p.add_argument("--interval", type=float, default=8.0, help="ms between mouse moves")
    p.add_argument("--samples", type=int, default=4, help="anti-aliasing (0 off, 2, 4, 8)")
    p.add_argument("--full", action="store_true",
                   help="draw every frame at full size (turn off the reduced drawing)")
    p.add_argument("--play", action="store_true",
                   help="play the timeline for --seconds instead of orbiting: frames drawn a "
                        "second, and the animation's frames shown and skipped")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    os.environ["XDG_CONFIG_HOME"] = tempfile.mkdtemp(prefix="wrinkle-fps-settings-")
    from PySide6.QtCore import QElapsedTimer, QEventLoop, QPoint, Qt, QTimer
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QApplication

    from studio.app import configure_opengl

    configure_opengl()
    app = QApplication(sys.argv[:1])
    from studio.widgets.main_window import MainWindow

    if args.project is None:
        from studio.core.setup.sample_setup import sample_project

        project = sample_project()
    else:
        from studio.core.project.reader import load_project

        project = load_project(args.project)
    window = MainWindow(project)
    vp = window.viewport
    width, height = (int(v) for v in args.size.lower().split("x"))
    ratio = window.devicePixelRatioF()
    window.resize(1600, 1000)
    window.show()

    def settle(ms: int) -> None:
        loop = QEventLoop()
        QTimer.singleShot(ms, loop.quit)
        loop.exec()

    def wait_for_frame() -> None:
        drawn = vp.frames_rendered
        while vp.frames_rendered == drawn:
            app.processEvents(QEventLoop.ProcessEventsFlag.WaitForMoreEvents, 50)

    settle(500)
    for _ in range(3):  # the docks take their share: grow the window until the viewport fits
        window.resize(window.width() + round(width / ratio) - vp.width(),
                      window.height() + round(height / ratio) - vp.height())
        settle(300)
    window.timeline_panel.player.stop()
    vp.set_samples(args.samples)
    if hasattr(vp, "set_reduce_while_moving"):
        vp.set_reduce_while_moving(not args.full)
    vp.update()
    wait_for_frame()
    print(f"{vp.gl_description}; viewport {vp.pixel_size()[0]}x{vp.pixel_size()[1]}, "
          f"{args.samples} samples, {'full size' if args.full else 'reduced while moving'}")

    if args.play:
        return play(app, window, args.seconds, settle)
    centre = QPoint(vp.width() // 2, vp.height() // 2)
    QTest.mousePress(vp, Qt.MouseButton.MiddleButton, Qt.KeyboardModifier.NoModifier, centre)
    step = [0]

    def move() -> None:
        step[0] += 1
        dx = 3 * ((step[0] // 100) % 2 * -2 + 1)  # to and fro: 100 moves each way
        QTest.mouseMove(vp, QPoint(centre.x() + dx * (step[0] % 100), centre.y()))

    timer = QTimer()
    timer.timeout.connect(move)
    sizes: list[tuple[int, int]] = []
    vp.frameRendered.connect(lambda _ms: sizes.append(getattr(vp, "last_draw_size", (0, 0))))
    clock = QElapsedTimer()
    first = vp.frames_rendered
    clock.start()
    timer.start(round(args.interval))
    settle(round(args.seconds * 1000))
    timer.stop()
    frames = vp.frames_rendered - first
    seconds = clock.elapsed() / 1000.0
    print(f"orbiting: {frames} frames in {seconds:.2f} s = {frames / seconds:.1f} frames a second"
          f"; drawn at {sorted(set(sizes))}")
    start = time.perf_counter()
    QTest.mouseRelease(vp, Qt.MouseButton.MiddleButton, Qt.KeyboardModifier.NoModifier, centre)
    wait_for_frame()
    print(f"after release: a frame of {getattr(vp, 'last_draw_size', '?')} in "
          f"{(time.perf_counter() - start) * 1000:.0f} ms")
    window.doc.undo_stack.setClean()
    window.close()
    return 0


def play(app, window, seconds: float, settle) -> int:
    """Play from the start for ``seconds``: the viewport's frames a second, and how many of
    the animation's frames were shown and skipped to keep real time (Player)."""
    vp, player = window.viewport, window.timeline_panel.player
    fps = window.doc.project.timeline.fps
    first = vp.frames_rendered
    start = time.perf_counter()
    player.play()
    settle(round(seconds * 1000))
    player.stop()
    elapsed = time.perf_counter() - start
    frames = vp.frames_rendered - first
    print(f"playing at {fps:g} fps: {frames} frames drawn in {elapsed:.2f} s = "
          f"{frames / elapsed:.1f} a second; animation frames shown {player.frames_shown}, "
          f"skipped {player.frames_dropped}")
    window.doc.undo_stack.setClean()
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
