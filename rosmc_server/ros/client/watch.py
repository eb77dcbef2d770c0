"""What a client hears from the mission server: mission events and agent states.

Subscribes:
    ``/rosmc/mission_events`` (rosmc/MissionEvent): one message per accepted change.
    ``/rosmc/agent_states`` (rosmc/AgentStates): every robot's link and telemetry.
"""

from __future__ import annotations

import logging
import queue
import threading
import time

import rosgraph
import rosmc.msg as wire
import rospy

from ... import interface
from ...conversions import agent_statuses_from_msg, event_from_msg
from ...core import AgentStatus, MissionEvent
from ..node_setup import init_node

_log = logging.getLogger(__name__)


def identify() -> None:
    """Make this process a node if the ROS master answers, so that services know the caller.

    Without a node, rospy calls services as ``/unnamed``, a name the mission server's
    operator allow-list (``~operators``) cannot tell apart from any other tool's.
    """
    if not rospy.core.is_initialized() and rosgraph.is_master_online():
        init_node()


class MissionWatch:
    """Queues mission events and keeps the latest agent states; call :func:`init_node` first.

    Args:
        events: Subscribe to the mission events.
        states: Subscribe to the agent states.
    """

    def __init__(self, events: bool = True, states: bool = True) -> None:
        self._events: queue.Queue[MissionEvent] = queue.Queue()
        self._states: dict[str, AgentStatus] | None = None
        self._states_new = False
        self._condition = threading.Condition()
        self._subscribers: list[rospy.Subscriber] = []
        if events:
            self._subscribers.append(
                rospy.Subscriber(
                    interface.EVENTS_TOPIC, wire.MissionEvent, self._on_event, queue_size=1000
                )
            )
        if states:
            self._subscribers.append(
                rospy.Subscriber(
                    interface.AGENT_STATES_TOPIC, wire.AgentStates, self._on_states, queue_size=1
                )
            )

    def close(self) -> None:
        """Unsubscribe."""
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers.clear()

    def wait_connected(self, timeout: float) -> bool:
        """Wait until a publisher is connected to every subscription; False on timeout."""
        deadline = time.monotonic() + timeout
        while not all(s.get_num_connections() > 0 for s in self._subscribers):
            if time.monotonic() >= deadline or rospy.is_shutdown():
                return False
            time.sleep(0.02)
        return True

    def next_event(self, timeout: float | None = None) -> MissionEvent | None:
        """The next mission event, waiting up to ``timeout`` seconds (None: no limit)."""
        try:
            return self._events.get(timeout=timeout)
        except queue.Empty:
            return None

    def wait_agent_states(self, timeout: float) -> dict[str, AgentStatus] | None:
        """The latest agent states, waiting up to ``timeout`` seconds for the first ones."""
        with self._condition:
            self._condition.wait_for(lambda: self._states is not None, timeout)
            return self._states

    def take_agent_states(self) -> dict[str, AgentStatus] | None:
        """The agent states received since the last call, or None if none arrived."""
        with self._condition:
            if not self._states_new:
                return None
            self._states_new = False
            return self._states

    def _on_event(self, msg: wire.MissionEvent) -> None:
        try:
            self._events.put(event_from_msg(msg))
        except Exception:  # a malformed event must not kill the subscriber thread
            _log.exception("cannot read mission event at revision %d", msg.revision)

    def _on_states(self, msg: wire.AgentStates) -> None:
        try:
            states = agent_statuses_from_msg(msg)
        except Exception:  # a malformed message must not kill the subscriber thread
            _log.exception("cannot read agent states")
            return
        with self._condition:
            self._states = states
            self._states_new = True
            self._condition.notify_all()
