"""The command GUI in its own window: ``rosmc_command [--ns /replay]``.

Makes the process a ROS node, wires a :class:`~.ros_bridge.RosBridge` to a
:class:`~.command_widget.CommandWidget` and shows it in a main window.
"""

from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rospy
from python_qt_binding.QtCore import QObject, QTimer, Signal
from python_qt_binding.QtWidgets import QApplication, QMainWindow, QWidget

from rosmc_server.ros.client import init_node

from .core.pending_backend import PendingBackend, follows_replay
from .core.station_layout import MISSION
from .core.view_state import ViewUpdate
from .qt.command_widget import CommandWidget
from .qt.replay_mode import ReplayHooks, ReplayMode, ReplaySteering
from .qt.startup_report import StartupReport
from .qt.station_menu import StationHooks, StationMenu
from .qt.window_layout import place_on_screen
from .ros_bridge import RosBridge


def _wiring(widget: CommandWidget, bridge: RosBridge) -> list[tuple[Any, Any]]:
    """Each bridge signal with the widget slot it feeds."""
    return [
        (bridge.updated, widget.on_updates),
        (bridge.library_ready, widget.on_library),
        (bridge.answered, widget.on_answer),
        (bridge.connection_changed, widget.on_connection),
        (bridge.server_restarted, widget.on_server_restarted),
        (bridge.journal_alert, widget.on_journal_alert),
        (bridge.selection_received, widget.on_remote_selection),
        (bridge.science_received, widget.science.show_science),
        (bridge.site_received, widget.site.show_site),
    ]


def connect(widget: CommandWidget, bridge: RosBridge) -> None:
    """Route the bridge's signals to the widget's slots (queued across threads)."""
    for signal_, slot in _wiring(widget, bridge):
        signal_.connect(slot)


def disconnect(widget: CommandWidget, bridge: RosBridge) -> None:
    """Stop routing the bridge's signals to the widget."""
    for signal_, slot in _wiring(widget, bridge):
        signal_.disconnect(slot)


def replay_hooks(widget: CommandWidget, timeout: float) -> ReplayHooks:
    """The ROS side of File > Open recording… for ``widget``."""

    def follow(prefix: str) -> RosBridge:
        bridge = RosBridge(prefix, timeout)
        bridge.start()
        return bridge

    return ReplayHooks(
        follow=follow,
        attach=lambda bridge: connect(widget, bridge),
        detach=lambda bridge: disconnect(widget, bridge),
        close=lambda bridge: bridge.close(),
        steer=_replay_link,
    )


def _replay_link(prefix: str) -> ReplaySteering:
    """The link that steers a replay (its recording modules load with the first replay)."""
    from .ros_replay import ReplayLink

    return ReplayLink(prefix)


class CommandWindow(QMainWindow):  # type: ignore[misc]
    """The standalone main window; asks about unsaved changes before it closes."""

    def __init__(self, widget: CommandWidget, title: str) -> None:
        super().__init__()
        self.widget = widget
        self.setWindowTitle(title)
        self.setCentralWidget(widget)
        place_on_screen(self)  # the right part of the screen; rviz takes the left

    def closeEvent(self, event: object) -> None:
        """Offer to save first; Cancel keeps the window open, Save until the save is done."""
        if self.widget.backend.read_only or self.widget.files.may_close(self.close):
            event.accept()  # type: ignore[attr-defined]
        else:
            event.ignore()  # type: ignore[attr-defined]


def freeze_after_reset(batch: Sequence[ViewUpdate]) -> None:
    """Once a whole mission has arrived, keep the cyclic garbage collector off it.

    A 10,000-skill mission is hundreds of thousands of objects; every full collection
    walked them all (65-160 ms measured, the window's longest stall). They live as long as the
    mission is shown and are freed by reference counting when it is replaced, so they
    are moved to the collector's permanent generation (``gc.freeze``).
    """
    if any(update.reset for update in batch):
        gc.freeze()


def build(
    prefix: str = "", parent: QWidget | None = None, timeout: float = 5.0
) -> tuple[CommandWidget, RosBridge]:
    """A command widget fed by a started bridge (the process must be a ROS node)."""
    bridge = RosBridge(prefix, timeout)
    widget = CommandWidget(bridge, parent)
    follow(widget, bridge, timeout)
    return widget, bridge


def follow(widget: CommandWidget, bridge: RosBridge, timeout: float = 5.0) -> None:
    """Feed ``widget`` (whose backend is ``bridge``) from the started bridge; add replays."""
    connect(widget, bridge)
    bridge.updated.connect(freeze_after_reset)
    bridge.start()
    widget.replay = ReplayMode(widget, replay_hooks(widget, timeout))


class NodeStart(QObject):  # type: ignore[misc]
    """Makes the process a ROS node on a thread; :attr:`ready` is emitted on the GUI thread.

    rospy waits at least 100 ms for its registration with the master (and as long as no
    master runs): the window is built and painted meanwhile.
    """

    ready = Signal()

    def __init__(self, name: str) -> None:
        super().__init__()
        self._thread = threading.Thread(target=self._run, args=(name,), daemon=True)
        self._thread.name = "rosmc-node-start"

    def start(self) -> None:
        """Start registering (connect :attr:`ready` first: it may come at once)."""
        self._thread.start()

    def _run(self, name: str) -> None:
        init_node(name)
        self.ready.emit()  # queued: this object lives on the GUI thread


class _Live:
    """The standalone window's bridge, once the node has started."""

    def __init__(self, widget: CommandWidget, prefix: str, report: StartupReport | None):
        self.widget, self.prefix, self.report = widget, prefix, report
        self.bridge: RosBridge | None = None
        self.station: Any = None  # the StationLink (rviz, the clock), once the node is up
        self.menu: StationMenu | None = None

    def on_node_ready(self) -> None:
        """Make the bridge, hand it what the window asked meanwhile, start following."""
        if self.report is not None:
            self.report.mark("node")
        pending = self.widget.backend
        self.bridge = bridge = RosBridge(self.prefix)
        if self.report is not None:
            self.report.follow(bridge.updated, self.widget.tasks)
        self.widget.set_backend(bridge)
        follow(self.widget, bridge)
        if self.menu is not None and not follows_replay(self.prefix):
            self.station = join_station(self.widget, self.menu)
        if isinstance(pending, PendingBackend):
            pending.hand_over(bridge)

    def close(self) -> None:
        """Stop following (if the node ever started)."""
        if self.bridge is not None:
            self.widget.replay.close()
            self.bridge.close()
        if self.station is not None:
            self.station.close()


def join_station(widget: CommandWidget, menu: StationMenu) -> Any:
    """Connect ``widget`` (following the live mission) to rviz; returns the StationLink.

    Show 3D view and the clock go through the link; Open recording… makes rviz show the
    replay, Return to live the live mission; rviz's Open command window brings the
    window to the front.
    """
    from .ros_station import StationLink

    station = StationLink()
    menu.hooks = station.hooks()
    menu.tick()
    widget.replay.show_source = station.show_source
    station.raise_requested.connect(lambda: bring_to_front(widget.window()))
    return station


def bring_to_front(window: QWidget) -> None:
    """Show ``window`` un-minimized, on top, with the keyboard focus."""
    window.showNormal()
    window.raise_()
    window.activateWindow()


def _not_yet() -> str:
    return "The 3D view opens once this window has joined the ROS graph."


def main(argv: Sequence[str] | None = None) -> int:
    """Open the command window; returns the exit code."""
    args = rospy.myargv(list(sys.argv if argv is None else argv))[1:]
    parser = argparse.ArgumentParser(prog="rosmc_command", description=__doc__)
    parser.add_argument(
        "--ns", default="", help="follow a replay served under this prefix, read-only (/replay)"
    )
    parser.add_argument(
        "--startup-report",
        type=Path,
        metavar="FILE",
        help="write when each start-up stage ended to FILE, as JSON lines (for benchmarks)",
    )
    options = parser.parse_args(args)
    report = StartupReport(options.startup_report) if options.startup_report else None
    if report is not None:
        report.mark("main")
    app = QApplication.instance() or QApplication([sys.argv[0]])
    node = NodeStart(f"rosmc_command_{os.getpid()}")
    widget = CommandWidget(PendingBackend(options.ns))
    live = _Live(widget, options.ns, report)
    node.ready.connect(live.on_node_ready)
    node.start()
    replay = follows_replay(options.ns)
    title = "ROSMC command" + (f" — following {options.ns} (read-only)" if replay else "")
    window = CommandWindow(widget, title)
    live.menu = StationMenu(widget, StationHooks(_not_yet, lambda: (None, MISSION)), window.close)
    if report is not None:
        report.watch(window)
    window.show()
    # Ctrl-C in the terminal closes the window (Qt otherwise never lets Python see it).
    signal.signal(signal.SIGINT, lambda *_: window.close())
    timer = QTimer()
    timer.timeout.connect(lambda: None)
    timer.start(200)
    try:
        return int(app.exec_())
    finally:
        live.close()
        rospy.signal_shutdown("command window closed")
