"""Replaying a recording inside the command GUI: File > Open recording…, the bar, the way back.

:class:`ReplayMode` starts the replay's child processes (:mod:`.replay_process`), points
the window at the replay's prefix with a fresh read-only backend, and shows the timeline
bar (:mod:`.replay_bar`) above the task panel; rviz is told to show the replay too
(:attr:`ReplayMode.show_source`, which the window sets). "Return to live" (or the replay leaving on
its own) ends the children and points the window at the live mission again. The window's
live backend is only set aside meanwhile, so the way back needs no reconnection.

The ROS side comes in through :class:`ReplayHooks` (the standalone window and the rqt
plugin provide them), so this module stays free of ROS.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from python_qt_binding.QtCore import QObject, QTimer
from python_qt_binding.QtWidgets import QAction, QFileDialog

from rosmc_server.core import RosmcError

from ..core.station_layout import REPLAY
from ..replay_process import ReplayProcess
from ..replay_ticks import outline_of
from .replay_bar import ReplayBar, ShownStatus

if TYPE_CHECKING:
    from .command_widget import CommandWidget

FILTER = "Mission recordings (*.mcap);;All files (*)"
PREFIX = "/replay"
WATCH_MS = 500  # how often the replay's child process is looked at


class ReplaySteering(Protocol):
    """What the bar steers (the ROS link of :mod:`.ros_replay`)."""

    state_received: Any  # Signal(ShownStatus)
    refused: Any  # Signal(str)

    def pause(self) -> None:
        """Stop where it is."""

    def resume(self) -> None:
        """Play on."""

    def seek(self, seconds: float) -> None:
        """Move to ``seconds``."""

    def set_rate(self, rate: float) -> None:
        """Change the speed."""

    def close(self) -> None:
        """Stop following and steering."""


@dataclass(frozen=True)
class ReplayHooks:
    """The ROS side of a replay in the window.

    Attributes:
        follow: Make a started, read-only backend that follows the mission under a prefix.
        attach: Route a backend's signals to the window.
        detach: Stop routing a backend's signals to the window.
        close: Close a backend made by ``follow``.
        steer: Make the link that follows and steers the replay under a prefix.
    """

    follow: Callable[[str], Any]
    attach: Callable[[Any], None]
    detach: Callable[[Any], None]
    close: Callable[[Any], None]
    steer: Callable[[str], ReplaySteering]


class ReplayMode(QObject):  # type: ignore[misc]
    """The window's replay: File > Open recording…, the bar, and "Return to live".

    Args:
        widget: The command window's widget (its backend is the live one now).
        hooks: The ROS side (see :class:`ReplayHooks`).
        prefix: Where the replay publishes; rviz follows it (see :attr:`show_source`).
    """

    def __init__(self, widget: CommandWidget, hooks: ReplayHooks, prefix: str = PREFIX) -> None:
        super().__init__(widget)
        self._widget = widget
        self._hooks = hooks
        self.prefix = prefix
        self._live = widget.backend
        self.process: ReplayProcess | None = None
        self._backend: Any = None
        self._link: ReplaySteering | None = None
        self._ended_said = False
        self._live_science: Any = None  # the live score, shown again on the way back
        # Tells rviz which mission to show: the prefix, or "" for the live one again.
        self.show_source: Callable[[str], None] = lambda _prefix: None
        self.bar = ReplayBar()
        self.bar.hide()
        widget.layout().insertWidget(1, self.bar)  # under the banner, above the task panel
        self.open_action = QAction("Open &recording…", widget)
        self.open_action.setObjectName("open_recording")
        self.open_action.setToolTip("Replay a mission recording (.mcap) in this window and rviz")
        self.open_action.triggered.connect(self._on_open_action_triggered)
        menu = widget.menu_bar.actions()[0].menu()
        after = widget.actions_.file["open_server"]
        following = menu.actions()[menu.actions().index(after) + 1]
        menu.insertAction(following, self.open_action)
        self.bar.play_requested.connect(self._on_bar_play_requested)
        self.bar.rate_chosen.connect(lambda rate: self._steer("set_rate", rate))
        self.bar.seek_requested.connect(lambda seconds: self._steer("seek", seconds))
        self.bar.live_requested.connect(self.return_to_live)
        self._watch = QTimer(self)
        self._watch.setInterval(WATCH_MS)
        self._watch.timeout.connect(self._on_watch_timeout)

    @property
    def active(self) -> bool:
        """A replay is shown."""
        return self.process is not None

    def open(self, path: str) -> None:
        """Replay the recording at ``path`` here (a bad file changes nothing)."""
        try:
            outline = outline_of(path)
        except (RosmcError, OSError) as error:
            self._widget.messages.say(f"Cannot replay {path}: {error}", "error")
            return
        if self.active:
            self._leave_replay()
        self.process = ReplayProcess(path, self.prefix)
        self.process.start()
        self._link = self._hooks.steer(self.prefix)
        self._link.state_received.connect(self._on_link_state_received)
        self._link.refused.connect(lambda text: self._widget.messages.say(text, "warning"))
        self._backend = self._hooks.follow(self.prefix)
        if self._live is self._widget.backend:  # not from one replay to the next
            self._live_science = self._widget.science.science
        self._switch(self._live, self._backend)
        self._widget.science.show_replay_start()
        self._ended_said = False
        self.bar.set_outline(outline)
        self.bar.show()
        self._watch.start()
        self.show_source(self.prefix)
        self._widget.messages.say(
            f"Replaying {outline.path.name} ({outline.duration:.1f} s) here and in the 3D "
            "view, paused at the start.",
            "info",
        )

    def return_to_live(self) -> None:
        """End the replay and show the live mission again."""
        if not self.active:
            return
        self._leave_replay()
        self.show_source("")
        self._switch(None, self._live)
        self._widget.science.show_science(self._live_science)
        self._live.refresh()
        self.bar.hide()
        self._widget.messages.say("Back to the live mission.", "ok")

    def clock(self) -> tuple[float | None, str]:
        """The replayed time: where the replay is in its recording (None before it is heard)."""
        shown = self.bar.shown
        return (None if shown is None else shown.position_now()), REPLAY

    def close(self) -> None:
        """End the replay's processes (the window closes)."""
        if self.active:
            self._leave_replay()

    def _leave_replay(self) -> None:
        self._watch.stop()
        if self._link is not None:
            self._link.close()
            self._link = None
        if self._backend is not None:
            self._hooks.detach(self._backend)
            self._hooks.close(self._backend)
            self._backend = None
        if self.process is not None:
            self.process.stop()
            self.process = None

    def _switch(self, old: Any, new: Any) -> None:
        if old is not None:
            self._hooks.detach(old)
        self._hooks.attach(new)
        self._widget.set_backend(new)

    def _steer(self, name: str, *args: float) -> None:
        if self._link is not None:
            getattr(self._link, name)(*args)

    # -- slots ------------------------------------------------------------------------------
    def _on_open_action_triggered(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self._widget, "Open recording", "", FILTER)
        if path:
            self.open(path)

    def _on_bar_play_requested(self, play: bool) -> None:
        self._steer("resume" if play else "pause")

    def _on_link_state_received(self, shown: ShownStatus) -> None:
        if not self.active:
            return
        if self.bar.shown is None and self._backend is not None:
            self._backend.refresh()  # the replay is up: fetch its mission now, not on a retry
        self.bar.show_status(shown)
        ended = shown.status.ended
        if ended and not self._ended_said:
            self._widget.messages.say(
                "The replay has ended. Press Play to see it again, or Return to live.", "ok"
            )
        self._ended_said = ended

    def _on_watch_timeout(self) -> None:
        failure = self.process.failure() if self.process is not None else None
        if failure is not None:
            self._widget.messages.say(f"The replay stopped: {failure}", "error")
            self.return_to_live()
