"""Journal what the robots and the site did, beside the mission's changes.

A recording should show where the robots were and how the mission scored, not only what
the operators changed. The mission server journals, at low rates and never on an
operator's service path:

* ``/rosmc/agent_states`` when something an operator would notice changed (link, executor
  state, current skill, battery by a percent, pose by 10 cm, ...), at most at the rate the
  server publishes them (2 Hz by default);
* ``/tf``: the newest ``map -> <agent>/base_link`` transforms, :data:`TF_PERIOD` apart;
* ``/rosmc/sim/science`` and ``/rosmc/sim/world`` (latched by the simulator) when they change.

The journal writer serializes and writes each message at once without an fsync of its own.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable
from io import BytesIO
from typing import Any

import rosmc.msg as wire
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from .. import interface
from ..recording import JournalWriter

_log = logging.getLogger(__name__)

TF_PERIOD = 0.5  # seconds between journaled TF messages (2 Hz)
BATTERY_STEP = 0.01  # a battery change worth recording (1 %)
POSE_STEP = 0.1  # metres
WIFI_STEP = 1.0  # dBm


def state_key(state: wire.AgentState) -> tuple[Any, ...]:
    """What of an agent's state is worth a journal record when it changes (rounded)."""
    telemetry = state.telemetry
    pose = telemetry.pose
    return (
        state.link.state,
        state.link.commands_waiting,  # what waits for contact (its age is not worth a record)
        state.current_skill_id,
        state.current_status.value,
        state.executor_state,
        state.waiting_on,
        state.lost_link,
        state.hold,
        _step(telemetry.battery, BATTERY_STEP),
        _step(telemetry.wifi_signal, WIFI_STEP),
        telemetry.in_coverage,
        _step(pose.x, POSE_STEP),
        _step(pose.y, POSE_STEP),
        _step(pose.z, POSE_STEP),
    )


def _step(value: float, step: float) -> float | None:
    return None if math.isnan(value) else round(value / step)


class TelemetryRecorder:
    """Writes agent states, TF, science and world markers into the server's journal."""

    def __init__(self, journal: Callable[[], JournalWriter], robots: frozenset[str]) -> None:
        self._journal = journal
        self._frames = {interface.base_link(robot) for robot in robots}
        self._lock = threading.Lock()
        self._state_keys: dict[str, tuple[Any, ...]] = {}
        self._transforms: dict[str, Any] = {}  # child frame -> newest transform not journaled
        self._last: dict[str, bytes] = {}  # latched topics: the serialized message last written
        self._subscribers: list[rospy.Subscriber] = []
        self._timer: rospy.Timer | None = None

    def start(self) -> None:
        """Subscribe to TF and the simulator's topics; start the TF timer."""
        self._subscribers = [
            rospy.Subscriber(interface.TF_TOPIC, TFMessage, self._on_tf, queue_size=50),
            rospy.Subscriber(
                interface.SCIENCE_TOPIC,
                wire.ScienceState,
                lambda msg: self._on_latched(interface.SCIENCE_TOPIC, msg),
                queue_size=10,
            ),
            rospy.Subscriber(
                interface.WORLD_TOPIC,
                MarkerArray,
                lambda msg: self._on_latched(interface.WORLD_TOPIC, msg),
                queue_size=2,
            ),
        ]
        self._timer = rospy.Timer(rospy.Duration(TF_PERIOD), lambda _e: self.flush_tf())

    def stop(self) -> None:
        """Stop recording (before the journal closes)."""
        if self._timer is not None:
            self._timer.shutdown()
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers = []

    def agent_states(self, msg: wire.AgentStates) -> None:
        """Journal ``msg`` if any agent's state changed noticeably since the last record."""
        keys = {state.agent: state_key(state) for state in msg.agents}
        with self._lock:
            if keys == self._state_keys:
                return
            self._state_keys = keys
        self._write(interface.AGENT_STATES_TOPIC, msg)

    def flush_tf(self) -> None:
        """Journal the newest robot transforms heard since the last flush."""
        with self._lock:
            transforms, self._transforms = list(self._transforms.values()), {}
        if transforms:
            self._write(interface.TF_TOPIC, TFMessage(transforms=transforms))

    def _on_tf(self, msg: TFMessage) -> None:
        with self._lock:
            for transform in msg.transforms:
                child = transform.child_frame_id.lstrip("/")
                if child in self._frames and transform.header.frame_id == interface.MAP_FRAME:
                    self._transforms[child] = transform

    def _on_latched(self, topic: str, msg: Any) -> None:
        data = _serialized(msg)
        with self._lock:
            if self._last.get(topic) == data:
                return
            self._last[topic] = data
        self._write(topic, msg)

    def _write(self, topic: str, msg: Any) -> None:
        journal = self._journal()
        if journal.closed:
            return
        try:
            journal.append_telemetry(topic, msg, time.time_ns())
        except Exception:  # telemetry must never take the server down; the mission is safe
            _log.exception("cannot journal %s", topic)


def _serialized(msg: Any) -> bytes:
    buffer = BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()
