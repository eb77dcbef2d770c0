"""The server's estimate of radio coverage, and its warning per robot.

Feeds a :class:`~rosmc_server.core.robots.radio_map.RadioMap` with the robots' telemetry (the
server's agent-state publisher hands each message on) and the radio model's prediction,
and says per robot whether its synchronized task ends out of coverage under a lost-link
policy that would leave it there (``rosmc/AgentState.coverage_warning``).

Subscribes ``/rosmc/sim/coverage`` (rosmc/CoverageGrid, latched; only with the simulator).
"""

from __future__ import annotations

import threading

import rosmc.msg as wire
import rospy

from .. import interface
from ..conversions.coverage import prediction_from_msg, reading_from_telemetry
from ..core import Library, MissionState, PolicyInForce
from ..core.robots.radio_map import RadioMap, coverage_warning


class CoverageWatch:
    """The ground's radio map and the task-ends-out-of-coverage check."""

    def __init__(self, library: Library) -> None:
        self._library = library
        self._lock = threading.Lock()
        self._radio = RadioMap()
        self._subscriber = rospy.Subscriber(
            interface.COVERAGE_MODEL_TOPIC, wire.CoverageGrid, self._on_model, queue_size=1
        )

    def _on_model(self, msg: wire.CoverageGrid) -> None:
        prediction = prediction_from_msg(msg)
        with self._lock:
            self._radio.prediction = prediction

    def telemetry(self, msg: wire.Telemetry) -> None:
        """A robot's telemetry: its signal where it is."""
        reading = reading_from_telemetry(msg)
        with self._lock:
            self._radio.add(reading)

    def warning(self, state: MissionState, agent: str, in_force: PolicyInForce | None) -> str:
        """The warning about ``agent``'s task under the policy it reports ("" if none)."""
        default = self._library.default_policy(agent)
        policy = in_force.policy if in_force is not None else None
        with self._lock:
            return coverage_warning(state.task(agent), self._radio, policy, default)
