"""The clock the mission server stamps with, and a warning when the robots' clock differs."""

from __future__ import annotations

import logging

import rospy

_log = logging.getLogger(__name__)

CLOCK_CHECK_PERIOD = 5.0  # seconds between looks at /use_sim_time


class ClockWatch:
    """Says which clock the server stamps with, and warns when the robots' clock differs.

    rospy picks sim or wall time once, when the node starts. A simulator that sets
    ``/use_sim_time`` after the server started (started separately, in the wrong order)
    leaves the server on wall time while the robots report sim time: the recording then
    holds both clocks (``rosmc timeline`` maps each on its own), and the operator should
    know at once.
    """

    def __init__(self) -> None:
        self.sim_time = bool(rospy.get_param("/use_sim_time", False))
        self._warned = False
        _log.info(
            "mission server clock: %s",
            "sim time (/clock)" if self.sim_time else "wall time (/use_sim_time is not set)",
        )

    def check(self) -> None:
        """Warn once if /use_sim_time was set after the server started."""
        if self.sim_time or self._warned:
            return
        try:
            now_sim = bool(rospy.get_param("/use_sim_time", False))
        except (OSError, KeyError):
            return
        if now_sim:
            self._warned = True
            _log.error(
                "/use_sim_time was set after the mission server started: the server stamps "
                "events in wall time while the robots report sim time. Start the simulator "
                "first (or both from one launch file, e.g. operator.launch sim:=true), or "
                "restart the server with _resume:=true."
            )
