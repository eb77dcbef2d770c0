"""The timeline bar of a replay: play/pause, slower/faster, a slider with event ticks, the way back.

A plain Qt widget (no ROS): it shows a :class:`ShownStatus` and asks for changes through
its signals; :mod:`.replay_mode` connects them to the replay. The slider's ticks are the
recording's operator changes (blue), robot outcomes (green, red) and link outages (orange):
clicking near a tick moves the replay to it, clicking or dragging elsewhere moves it there.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

from python_qt_binding.QtCore import QPoint, QRect, QSize, Qt, QTimer, Signal
from python_qt_binding.QtGui import QColor, QPainter, QPen
from python_qt_binding.QtWidgets import (
    QFrame,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QToolTip,
    QVBoxLayout,
    QWidget,
)

from ..replay_ticks import RecordingOutline, ReplayTick, TickKind
from .labels import never_widen

if TYPE_CHECKING:  # the recording modules load when a replay starts, not with the window
    from rosmc_server.recording.playback import PlaybackStatus

TICK_COLOURS = {
    TickKind.OPERATOR: QColor("#1f5fbf"),
    TickKind.SUCCESS: QColor("#1e8a3a"),
    TickKind.FAILURE: QColor("#c0182b"),
    TickKind.OUTAGE: QColor("#e07b00"),
}
HIT = 4  # pixels either side of a tick that count as clicking it
MARGIN = 8  # pixels left and right of the track (the handle must fit)


@dataclass(frozen=True)
class ShownStatus:
    """A replay's status and the wall time (s) at which it held."""

    status: PlaybackStatus
    stamp: float

    def position_now(self) -> float:
        """Where the replay is by now (it advances while it plays)."""
        status = self.status
        if status.paused or status.ended:
            return status.position
        ahead = max(0.0, time.time() - self.stamp) * status.rate
        return min(status.duration, status.position + ahead)


class TickSlider(QWidget):  # type: ignore[misc]
    """A time slider with a tick per recorded event; emits where the operator moved it."""

    seek_requested = Signal(float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("replay_slider")
        self.setMouseTracking(True)
        self.setMinimumHeight(30)
        self.duration = 0.0
        self.position = 0.0
        self.ticks: tuple[ReplayTick, ...] = ()
        self.dragging = False

    def sizeHint(self) -> QSize:
        """Wide and low."""
        return QSize(600, 30)

    def set_outline(self, outline: RecordingOutline) -> None:
        """Show this recording's length and ticks."""
        self.duration, self.ticks = outline.duration, outline.ticks
        self.update()

    def set_position(self, seconds: float) -> None:
        """Move the handle (not while the operator drags it)."""
        if not self.dragging:
            self.position = seconds
            self.update()

    def x_of(self, seconds: float) -> int:
        """The x pixel of a time on the track."""
        span = max(1, int(self.width()) - 2 * MARGIN)
        share = seconds / self.duration if self.duration > 0 else 0.0
        return MARGIN + round(min(max(share, 0.0), 1.0) * span)

    def time_at(self, x: int) -> float:
        """The time under an x pixel (clamped to the recording)."""
        span = max(1, int(self.width()) - 2 * MARGIN)
        return min(max((x - MARGIN) / span, 0.0), 1.0) * self.duration

    def tick_at(self, x: int) -> ReplayTick | None:
        """The tick nearest to an x pixel, if one is within reach of it."""
        near = [(abs(self.x_of(t.time) - x), i) for i, t in enumerate(self.ticks)]
        distance, index = min(near, default=(HIT + 1, -1))
        return self.ticks[index] if distance <= HIT else None

    def paintEvent(self, _event: object) -> None:
        """The track, the ticks above it and the handle."""
        painter = QPainter(self)
        middle = self.height() // 2 + 4
        painter.fillRect(QRect(MARGIN, middle - 2, self.width() - 2 * MARGIN, 4), QColor("#b8b8b8"))
        played = self.x_of(self.position) - MARGIN
        painter.fillRect(QRect(MARGIN, middle - 2, played, 4), QColor("#5a5a5a"))
        for tick in self.ticks:
            painter.setPen(QPen(TICK_COLOURS[tick.kind], 2))
            x = self.x_of(tick.time)
            painter.drawLine(x, 2, x, middle - 4)
        x = self.x_of(self.position)
        painter.setPen(Qt.NoPen)
        painter.setBrush(QColor("#202020") if self.isEnabled() else QColor("#a0a0a0"))
        painter.drawRoundedRect(QRect(x - 4, middle - 9, 8, 18), 2, 2)
        painter.end()

    def mousePressEvent(self, event: object) -> None:
        """Near a tick: go to its event. Elsewhere: the handle follows the mouse."""
        x = event.pos().x()  # type: ignore[attr-defined]
        tick = self.tick_at(x)
        if tick is not None:
            self.position = tick.time
            self.update()
            self.seek_requested.emit(tick.time)
            return
        self.dragging = True
        self.position = self.time_at(x)
        self.update()

    def mouseMoveEvent(self, event: object) -> None:
        """Drag the handle; otherwise name the tick under the mouse."""
        pos: QPoint = event.pos()  # type: ignore[attr-defined]
        if self.dragging:
            self.position = self.time_at(pos.x())
            self.update()
            return
        tick = self.tick_at(pos.x())
        text = f"{tick.time:.2f} s  {tick.text}" if tick else f"{self.time_at(pos.x()):.2f} s"
        QToolTip.showText(self.mapToGlobal(pos), text, self)

    def mouseReleaseEvent(self, event: object) -> None:
        """The end of a drag (or a click off the ticks): go there."""
        if self.dragging:
            self.dragging = False
            self.position = self.time_at(event.pos().x())  # type: ignore[attr-defined]
            self.update()
            self.seek_requested.emit(self.position)


class ReplayBar(QFrame):  # type: ignore[misc]
    """Play/pause, rate, the tick slider, where the replay is, and "Return to live"."""

    play_requested = Signal(bool)  # True: play, False: pause
    rate_chosen = Signal(float)
    seek_requested = Signal(float)
    live_requested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("replay_bar")
        self.setFrameShape(QFrame.StyledPanel)
        self.setStyleSheet("#replay_bar { background:#eef3fb; }")
        self.title = never_widen(QLabel(), wrap=False)  # a long file name is cut, not the bar
        self.play_button = QPushButton("Play")
        self.play_button.setObjectName("replay_play")
        self.slower_button = QPushButton("Slower")
        self.slower_button.setObjectName("replay_slower")
        self.slower_button.setToolTip("Play half as fast")
        self.rate_label = QLabel("1x")
        self.rate_label.setObjectName("replay_rate")
        self.rate_label.setToolTip("Replay speed (times as fast as recorded)")
        self.faster_button = QPushButton("Faster")
        self.faster_button.setObjectName("replay_faster")
        self.faster_button.setToolTip("Play twice as fast")
        self.slider = TickSlider()
        self.slider.setToolTip("Drag to move the replay; click a tick to go to its event")
        self.time_label = QLabel()
        self.time_label.setObjectName("replay_time")
        self.end_label = QLabel("The replay has ended.")
        self.end_label.setObjectName("replay_end")
        self.end_label.setStyleSheet("QLabel { color:#8a0010; font-weight:bold; }")
        self.end_label.hide()
        self.live_button = QPushButton("Return to live")
        self.live_button.setObjectName("replay_live")
        self.live_button.setToolTip("Stop the replay and show the live mission again")
        # Two rows, so that the bar fits a window half a screen wide: what is replayed and
        # the way back above, the controls and the timeline below.
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 2, 6, 2)
        layout.setSpacing(2)
        top, controls = QHBoxLayout(), QHBoxLayout()
        top.addWidget(self.title, 1)
        for widget in (self.time_label, self.end_label, self.live_button):
            top.addWidget(widget)
        for widget in (self.play_button, self.slower_button, self.rate_label, self.faster_button):
            controls.addWidget(widget)
        controls.addWidget(self.slider, 1)
        layout.addLayout(top)
        layout.addLayout(controls)
        self.shown: ShownStatus | None = None
        self._timer = QTimer(self)
        self._timer.setInterval(100)
        self._timer.timeout.connect(self._on_timer_timeout)
        self.play_button.clicked.connect(self._on_play_button_clicked)
        self.slower_button.clicked.connect(lambda: self._on_rate_button_clicked(0.5))
        self.faster_button.clicked.connect(lambda: self._on_rate_button_clicked(2.0))
        self.slider.seek_requested.connect(self.seek_requested)
        self.live_button.clicked.connect(self.live_requested)
        self.set_outline(None)

    def set_outline(self, outline: RecordingOutline | None) -> None:
        """Show a new recording (None: nothing), paused at its start until its state comes."""
        self.shown = None
        self.end_label.hide()
        self.title.setText(f"Replay of <b>{outline.path.name}</b>" if outline else "")
        if outline is not None:
            self.slider.set_outline(outline)
        self.slider.set_position(0.0)
        self._enable(False)
        self.time_label.setText("starting…")

    def show_status(self, shown: ShownStatus) -> None:
        """Show where the replay is (newer than what is shown)."""
        from rosmc_server.recording.playback import MAX_RATE, MIN_RATE

        if self.shown is not None and shown.stamp < self.shown.stamp:
            return  # an answer overtaken by the state topic
        self.shown = shown
        status = shown.status
        self._enable(True)
        self.play_button.setText("Play" if status.paused or status.ended else "Pause")
        self.rate_label.setText(f"{status.rate:g}x")
        self.slower_button.setEnabled(status.rate / 2 >= MIN_RATE)
        self.faster_button.setEnabled(status.rate * 2 <= MAX_RATE)
        self.end_label.setVisible(status.ended)
        self.live_button.setDefault(status.ended)
        self._on_timer_timeout()
        if status.paused or status.ended:
            self._timer.stop()
        else:
            self._timer.start()

    def _enable(self, ready: bool) -> None:
        """Until the replay answers, only "Return to live" can act."""
        for widget in (self.play_button, self.slower_button, self.faster_button, self.slider):
            widget.setEnabled(ready)

    def _on_timer_timeout(self) -> None:
        if self.shown is None:
            return
        position = self.shown.position_now()
        status = self.shown.status
        self.slider.set_position(position)
        self.time_label.setText(f"{position:6.2f} / {status.duration:.2f} s")

    def _on_play_button_clicked(self) -> None:
        status = self.shown.status if self.shown else None
        self.play_requested.emit(status is None or status.paused or status.ended)

    def _on_rate_button_clicked(self, factor: float) -> None:
        if self.shown is not None:
            self.rate_chosen.emit(self.shown.status.rate * factor)
