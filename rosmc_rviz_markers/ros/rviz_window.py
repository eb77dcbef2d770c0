"""The operator's rviz, kept by a small node: its place on the screen, what it shows, raising it.

``rviz_station -d CONFIG [--ns PREFIX]`` (what ``launch/rviz.launch`` starts) runs rviz as
its child:

* **Place**: rviz starts on the left part of the screen's available area, the command window
  takes the right part (:func:`~rosmc_rqt_command.core.station_layout.split_screen`); the
  config is copied with that window geometry.
* **Source**: without ``--ns`` it follows ``/rosmc/station/view_source`` (std_msgs/String,
  latched, published by the command window): when the operator opens a recording there,
  rviz is started again on the replay's topics (``PREFIX/rosmc/markers/...``, ``PREFIX/tf``,
  the replayed site), and on *Return to live* again on the live ones. rviz reads its topic
  names once, at start; a restart is the only way to change them without a C++ plugin.
* **Raise**: ``/rosmc/station/show_3d`` (std_msgs/Empty, the command window's *Show 3D
  view*) brings rviz's window to the front (with ``xdotool``).

When rviz exits by itself (closed, crashed), this node exits with its code, so roslaunch's
``respawn`` starts both again. When the replay rviz follows goes away without a word (its
command window crashed, taking the replay with it), rviz returns to the live mission.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import rosgraph
import rospy
from std_msgs.msg import Empty, String

from rosmc_rqt_command.core.station_layout import Rect, rviz_config_at, split_screen
from rosmc_server import interface
from rosmc_server.common.ros.graph_join import join_graph, node_running
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout

from .. import topics

_log = logging.getLogger(__name__)
GRACE = 5.0  # seconds rviz gets to leave after SIGTERM
PRESENCE_PERIOD = 1.0  # seconds between looks at whether the followed replay still runs
# What rviz subscribes that a replay publishes behind its prefix.
FOLLOWED = (
    *(topics.topic(topics.MARKERS_NS, "") + f"/{leaf}" for leaf in ("update", "update_full")),
    topics.topic(topics.MARKERS_NS, "") + "/feedback",
    topics.topic(topics.ICONS_TOPIC, ""),
    topics.topic(topics.CLOCK_TOPIC, ""),
    interface.TF_TOPIC,
    interface.WORLD_TOPIC,
)


def remaps(prefix: str) -> list[str]:
    """rviz's command-line remappings that show the mission under ``prefix``."""
    return [f"{name}:={interface.prefixed(name, prefix)}" for name in FOLLOWED if prefix]


def replay_running(prefix: str) -> bool:
    """Whether a running node publishes the replay's state under ``prefix``.

    A replay that ended without unregistering (killed) stays listed by the master; only
    a node that answers counts.
    """
    topic = interface.prefixed(interface.REPLAY_STATE_TOPIC, prefix)
    master = rosgraph.Master(rospy.get_name())
    try:
        publishers, _subscribers, _services = master.getSystemState()
    except (rosgraph.MasterError, OSError):
        return True  # the master does not answer: nothing is known to be gone
    nodes = [node for name, nodes in publishers if name == topic for node in nodes]
    return any(node_running(node, master) for node in nodes)


def screen_area() -> Rect | None:
    """The available area of the primary screen (None without a screen)."""
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        return None
    from python_qt_binding.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([sys.argv[0]])
    screen = app.primaryScreen()
    if screen is None:
        return None
    area = screen.availableGeometry()
    return Rect(area.x(), area.y(), area.width(), area.height())


class RvizWindow:
    """rviz as a child process that is started again on another source (see the module)."""

    def __init__(
        self,
        config: Path,
        name: str,
        prefix: str,
        replay_up: Callable[[str], bool] | None = None,
    ) -> None:
        self._config = config
        self._name = name
        self._wanted = prefix
        self._shown: str | None = None
        self._child: subprocess.Popen[bytes] | None = None
        self._wake = threading.Condition()
        self._stopping = False
        # Whether the replay under a prefix runs; None: the source is fixed (``--ns``).
        self._replay_up = replay_up
        self._replay_seen = False  # the followed replay was seen running since rviz started
        self._next_look = 0.0

    def want(self, prefix: str) -> None:
        """Show the mission under ``prefix`` ("" the live one) from now on (any thread)."""
        with self._wake:
            self._wanted = prefix
            self._wake.notify()

    def stop(self) -> None:
        """End rviz and :meth:`run` (any thread)."""
        with self._wake:
            self._stopping = True
            self._wake.notify()

    def run(self) -> int:
        """Keep rviz on the wanted source until it exits by itself or :meth:`stop`."""
        while True:
            with self._wake:
                self._wake.wait_for(self._due, timeout=0.5)
                stopping, wanted = self._stopping, self._wanted
            child = self._child
            if stopping:
                self._end_child()
                return 0
            if child is not None and child.poll() is not None and wanted == self._shown:
                _log.info("rviz exited with code %s", child.returncode)
                return int(child.returncode or 0)
            if wanted != self._shown:
                self._end_child()
                self._start(wanted)
            self._look_at_replay()

    def _look_at_replay(self) -> None:
        """Back to live once the followed replay, seen running, has gone without a word.

        Only a replay seen running counts as gone: rviz may be told to follow one before
        it has started.
        """
        shown, now = self._shown, time.monotonic()
        if not shown or self._replay_up is None or now < self._next_look:
            return
        self._next_look = now + PRESENCE_PERIOD
        if self._replay_up(shown):
            self._replay_seen = True
        elif self._replay_seen:
            _log.warning("the replay under %s is gone; rviz shows the live mission", shown)
            self.want("")

    def _due(self) -> bool:
        child = self._child
        exited = child is not None and child.poll() is not None
        return self._stopping or self._wanted != self._shown or exited

    def _start(self, prefix: str) -> None:
        rviz = shutil.which("rviz") or "rviz"
        args = [rviz, "-d", str(self._config), f"__name:={self._name}_view", *remaps(prefix)]
        _log.info("rviz shows %s", f"the replay under {prefix}" if prefix else "the live mission")
        self._child = subprocess.Popen(args, stdin=subprocess.DEVNULL)
        self._shown = prefix
        self._replay_seen = False

    def _end_child(self) -> None:
        child, self._child = self._child, None
        if child is None or child.poll() is not None:
            return
        child.terminate()
        try:
            child.wait(timeout=GRACE)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()

    def raise_window(self) -> None:
        """Bring rviz's window to the front (needs xdotool; without it nothing happens)."""
        child = self._child
        if child is None or shutil.which("xdotool") is None:
            return
        found = subprocess.run(
            ["xdotool", "search", "--onlyvisible", "--pid", str(child.pid)],
            capture_output=True,
            text=True,
            timeout=10,
            check=False,
        )
        for window in found.stdout.split():
            for command in ("windowmap", "windowraise", "windowactivate"):
                subprocess.run(
                    ["xdotool", command, window], capture_output=True, timeout=10, check=False
                )


def placed_config(config: Path) -> Path:
    """A copy of ``config`` whose window takes rviz's part of this screen (or ``config``)."""
    area = screen_area()
    if area is None:
        return config
    text = rviz_config_at(config.read_text(encoding="utf-8"), split_screen(area).rviz)
    handle, name = tempfile.mkstemp(prefix="rosmc-rviz-", suffix=".rviz")
    with os.fdopen(handle, "w", encoding="utf-8") as out:
        out.write(text)
    return Path(name)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``rviz_station``."""
    args = rospy.myargv(list(sys.argv if argv is None else argv))[1:]
    parser = argparse.ArgumentParser(prog="rviz_station", description=__doc__)
    parser.add_argument("-d", dest="config", type=Path, required=True, help="the rviz config")
    parser.add_argument("--ns", default="", help="show the mission under this prefix only")
    options = parser.parse_args(args)
    join_graph("rviz_operator", disable_signals=True)
    bridge_logging_to_rosout()
    config = placed_config(options.config)
    follows = not options.ns  # the operator's rviz follows the command window's source
    replay_up = replay_running if follows else None
    window = RvizWindow(config, rospy.get_name().lstrip("/"), options.ns, replay_up)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: window.stop())
    if follows:
        rospy.Subscriber(
            interface.VIEW_SOURCE_TOPIC, String, lambda msg: window.want(msg.data.strip())
        )
    rospy.Subscriber(interface.SHOW_3D_TOPIC, Empty, lambda _msg: window.raise_window())
    try:
        return window.run()
    finally:
        rospy.signal_shutdown("rviz closed")
        if config != options.config:
            with contextlib.suppress(OSError):
                config.unlink()
