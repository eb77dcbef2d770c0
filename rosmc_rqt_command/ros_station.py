"""The command window's contact with the rest of the station: rviz, the clock, the view source.

ROS interface:
    Publishes ``/rosmc/station/show_3d`` (std_msgs/Empty: rviz, come to the front) and
    ``/rosmc/station/view_source`` (std_msgs/String, latched: "" live, or the replay's
    prefix, which rviz follows), only when this window opens a replay or returns to live:
    a second window that starts leaves rviz on the first one's replay. A window that
    crashes takes its replay with it, and rviz then returns to live by itself.
    Subscribes ``/rosmc/station/show_command`` (std_msgs/Empty: this window, to the front).
    Reads ``/use_sim_time``: with it the clock is the simulation's time, without it UTC.
"""

from __future__ import annotations

import logging
import os
import subprocess
import time

import rospy
from python_qt_binding.QtCore import QObject, Signal
from std_msgs.msg import Empty, String

from rosmc_server import interface
from rosmc_server.common.ros.graph_join import node_running

from .core.station_layout import MISSION, UTC
from .qt.station_menu import ClockReading, StationHooks

_log = logging.getLogger(__name__)
RVIZ_LAUNCH = ["roslaunch", "rosmc", "rviz.launch"]


class StationLink(QObject):  # type: ignore[misc]
    """Show 3D view, the clock and the view source (create on the GUI thread)."""

    raise_requested = Signal()  # someone asked for the command window (rviz's menu)

    def __init__(self) -> None:
        super().__init__()
        self._sim = bool(rospy.get_param("/use_sim_time", False))
        self._show_3d = rospy.Publisher(interface.SHOW_3D_TOPIC, Empty, queue_size=1)
        self._source = rospy.Publisher(
            interface.VIEW_SOURCE_TOPIC, String, queue_size=1, latch=True
        )
        self._started: subprocess.Popen[bytes] | None = None
        self._subscriber = rospy.Subscriber(
            interface.SHOW_COMMAND_TOPIC, Empty, lambda _msg: self.raise_requested.emit()
        )

    def hooks(self) -> StationHooks:
        """What the window's station menu calls."""
        return StationHooks(show_3d=self.show_3d, clock=self.clock)

    def show_3d(self) -> str:
        """Bring rviz to the front, or start it (returns what happened, in a sentence)."""
        if node_running(interface.RVIZ_NODE):
            self._show_3d.publish(Empty())
            return "The 3D view (rviz) is brought to the front."
        if self._started is not None and self._started.poll() is None:
            return "The 3D view (rviz) is starting."
        self._started = subprocess.Popen(
            RVIZ_LAUNCH,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env=dict(os.environ),
            start_new_session=True,  # it stays when this window closes
        )
        return "Starting the 3D view (rviz)."

    def show_source(self, prefix: str) -> None:
        """Make rviz show the mission under ``prefix`` ("" the live one)."""
        self._source.publish(String(data=prefix))

    def clock(self) -> ClockReading:
        """The simulation's time (or UTC without a simulation)."""
        if self._sim:
            now = rospy.get_time()
            return (now if now > 0 else None), MISSION
        return time.time() % 86400, UTC

    def close(self) -> None:
        """Stop listening (rviz started from here stays)."""
        self._subscriber.unregister()
        self._source.unregister()
        self._show_3d.unregister()
