"""The station in rviz: the mission clock over the lander, and *Open command window*.

The clock floats above the science score: the simulation's time since it started (in a
replay the replayed time; UTC without a simulation), a text marker on a topic of its own,
so that its tick every second costs one small message and never an interactive-marker
update. Just above it, the interactive marker ``station`` reads *[ command window ]*; a click
(or right click) opens its menu, whose *Open command window* brings the command window to
the front, or starts one when none is running. A read-only view (a replay) shows the clock
only: it has no menus.

ROS interface (behind ``~ns``):
    Publishes ``/rosmc/markers/clock`` (visualization_msgs/MarkerArray, latched: the clock)
    and ``/rosmc/station/show_command`` (std_msgs/Empty, never prefixed: the command window
    listens).
    Subscribes ``<ns>/rosmc/replay/state`` (rosmc/ReplayState) when the node follows a
    replay (``~ns`` set): the replayed time.
"""

from __future__ import annotations

import logging
import subprocess
import threading
import time
from collections.abc import Callable
from typing import Any

import rosmc.msg as wire
import rospy
from std_msgs.msg import ColorRGBA, Empty
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerControl,
    InteractiveMarkerFeedback,
    Marker,
    MarkerArray,
    MenuEntry,
)

from rosmc_rqt_command.core.station_layout import MISSION, REPLAY, UTC, clock_text
from rosmc_server import interface

from .. import topics
from .adapter import MarkerServer

_log = logging.getLogger(__name__)
STATION_MARKER = "station"
CLOCK_AT = (0.0, 0.0, 10.4)  # over the lander, above its score (8 m)
STATION_AT = (0.0, 0.0, 11.4)  # the menu's label, above the clock, below the server notes
CLOCK_TEXT = 0.8  # letter height (m), as the server notes
LABEL_TEXT = 0.6
LABEL = "[ command window ]"  # ASCII: rviz's font has no arrows
OPEN_COMMAND = 1  # the menu entry's id
OPEN_COMMAND_TITLE = "Open command window"
COMMAND_WINDOW = ["rosrun", "rosmc", "rosmc_command"]
TICK = 0.5  # seconds between looks at the clock (the text changes once a second)


class ReplayClock:
    """The replayed time, from the replay's latched state (None until it is heard)."""

    def __init__(self, prefix: str) -> None:
        self._state: Any = None
        self._subscriber = rospy.Subscriber(
            interface.prefixed(interface.REPLAY_STATE_TOPIC, prefix),
            wire.ReplayState,
            self._on_state,
        )

    def _on_state(self, msg: Any) -> None:
        self._state = msg

    def read(self) -> tuple[float | None, str]:
        """Where the replay is in its recording now."""
        state = self._state
        if state is None:
            return None, REPLAY
        position = float(state.position)
        if not state.paused:
            ahead = max(0.0, time.time() - state.stamp.to_sec()) * float(state.rate)
            position = min(float(state.duration), position + ahead)
        return position, REPLAY

    def close(self) -> None:
        """Stop listening."""
        self._subscriber.unregister()


def live_clock() -> tuple[float | None, str]:
    """The simulation's time (UTC without a simulation)."""
    if rospy.get_param("/use_sim_time", False):
        now = rospy.get_time()
        return (now if now > 0 else None), MISSION
    return time.time() % 86400, UTC


def clock_marker(text: str) -> Marker:
    """The clock's text marker."""
    marker = Marker(type=Marker.TEXT_VIEW_FACING, action=Marker.ADD, text=text, ns="clock")
    marker.header.frame_id = interface.MAP_FRAME
    marker.pose.position.x, marker.pose.position.y, marker.pose.position.z = CLOCK_AT
    marker.pose.orientation.w = 1.0
    marker.scale.z = CLOCK_TEXT
    marker.color = ColorRGBA(0.85, 0.92, 1.0, 1.0)
    return marker


def station_marker() -> InteractiveMarker:
    """The station marker: a label whose menu opens the command window."""
    marker = InteractiveMarker()
    marker.header.frame_id = interface.MAP_FRAME
    marker.name = STATION_MARKER
    marker.description = ""
    marker.scale = 1.0
    marker.pose.position.x, marker.pose.position.y, marker.pose.position.z = STATION_AT
    marker.pose.orientation.w = 1.0
    label = Marker(type=Marker.TEXT_VIEW_FACING, text=LABEL)
    label.scale.z = LABEL_TEXT
    label.color = ColorRGBA(0.55, 0.75, 1.0, 1.0)
    control = InteractiveMarkerControl(
        name="menu", interaction_mode=InteractiveMarkerControl.MENU, always_visible=True
    )
    control.orientation.w = 1.0
    control.markers.append(label)
    marker.controls.append(control)
    marker.menu_entries.append(
        MenuEntry(
            id=OPEN_COMMAND,
            parent_id=0,
            title=OPEN_COMMAND_TITLE,
            command="",
            command_type=MenuEntry.FEEDBACK,
        )
    )
    return marker


class StationLayer:
    """Keeps the station marker's clock current and answers its menu (see the module)."""

    def __init__(
        self, server: MarkerServer, lock: threading.Lock, prefix: str, menu: bool = True
    ) -> None:
        self._server, self._lock = server, lock
        self._menu = menu  # a read-only view (a replay) has no menus at all
        self._replay = ReplayClock(prefix) if prefix else None
        self._clock: Callable[[], tuple[float | None, str]] = (
            self._replay.read if self._replay is not None else live_clock
        )
        self._show = rospy.Publisher(interface.SHOW_COMMAND_TOPIC, Empty, queue_size=1)
        self._clock_pub = rospy.Publisher(
            topics.topic(topics.CLOCK_TOPIC, prefix), MarkerArray, queue_size=1, latch=True
        )
        self._started: subprocess.Popen[bytes] | None = None
        self._shown = ""
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rosmc-station", daemon=True)

    def start(self) -> None:
        """Show the marker and keep its clock going."""
        self._thread.start()

    def close(self) -> None:
        """Stop the clock."""
        self._stop.set()
        if self._replay is not None:
            self._replay.close()

    def _run(self) -> None:
        if self._menu:
            with self._lock:
                self._server.insert(station_marker())
                self._server.apply()
        while not self._stop.is_set():
            text = clock_text(*self._clock())
            if text != self._shown:
                self._clock_pub.publish(MarkerArray(markers=[clock_marker(text)]))
                self._shown = text
            self._stop.wait(TICK)

    def on_feedback(self, feedback: InteractiveMarkerFeedback) -> None:
        """The station marker's menu: *Open command window*."""
        chosen = feedback.event_type == InteractiveMarkerFeedback.MENU_SELECT
        if chosen and feedback.menu_entry_id == OPEN_COMMAND:
            self.open_command_window()

    def open_command_window(self) -> None:
        """Bring the command window to the front, or start one if none listens."""
        if self._show.get_num_connections() > 0:
            _log.info("bringing the command window to the front")
            self._show.publish(Empty())
            return
        if self._started is not None and self._started.poll() is None:
            return  # the one started here is still coming up
        _log.info("no command window runs: starting one")
        self._started = subprocess.Popen(
            COMMAND_WINDOW,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,  # it stays when the marker node stops
        )
