"""Real-time playback: the playhead follows the wall clock, not the number of timer ticks.

Why the clock: when a frame takes longer to draw than the frame rate allows, counting ticks would
play the animation in slow motion; reading the elapsed time instead skips the frames there was no
time to draw, so a 4-second animation always lasts 4 seconds.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QElapsedTimer, QObject, Qt, QTimer, Signal

from studio.widgets.document import Document


class Player(QObject):
    playingChanged = Signal(bool)

    def __init__(self, doc: Document, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.loop = True
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self._tick)
        self._clock = QElapsedTimer()
        self._anchor = 0.0  # the frame shown when the clock started
        self.frames_shown = 0
        self.frames_dropped = 0
        doc.projectReplaced.connect(self.stop)

    @property
    def playing(self) -> bool:
        return self._timer.isActive()

    def play(self) -> None:
        if self.playing:
            return
        timeline = self.doc.project.timeline
        frame = self.doc.frame
        if not timeline.start <= frame < timeline.end:
            frame = float(timeline.start)  # from the top, like any player at the end
            self.doc.show_frame(frame)
        self._anchor = round(frame)
        self._clock.start()
        self.frames_shown = self.frames_dropped = 0
        # tick at twice the frame rate: a late tick still shows its frame close to on time
        self._timer.start(max(1, int(500.0 / timeline.fps)))
        self.playingChanged.emit(True)

    def stop(self) -> None:
        if self.playing:
            self._timer.stop()
            self.playingChanged.emit(False)

    def toggle(self) -> None:
        self.stop() if self.playing else self.play()

    def _tick(self) -> None:
        timeline = self.doc.project.timeline
        start, end = timeline.start, timeline.end
        frame = self._anchor + math.floor(self._clock.elapsed() * timeline.fps / 1000.0)
        if frame > end:
            if not self.loop:
                self.doc.show_frame(end)
                self.stop()
                return
            length = end - start + 1
            frame = start + (frame - start) % length
        if frame == round(self.doc.frame):
            return
        step = (frame - round(self.doc.frame)) % (end - start + 1)
        self.frames_dropped += max(step - 1, 0)
        self.frames_shown += 1
        self.doc.show_frame(frame)
