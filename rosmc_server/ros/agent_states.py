"""The aggregated state of every agent, published at a steady rate.

Publishes ``/rosmc/agent_states`` (rosmc/AgentStates); subscribes
``/<agent>/telemetry`` (rosmc/Telemetry) for every agent of the library, and through
:class:`~.coverage_watch.CoverageWatch` the radio model ``/rosmc/sim/coverage``.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import rosmc.msg as wire
import rospy

from .. import interface
from ..conversions.agents import link_state_to_msg
from ..conversions.policy import policy_in_force_from_msg
from ..core import InvalidRequest, PolicyInForce, SkillStatus
from ..core.rules.advice import waiting_on_unsynced
from .agent_link import AgentLink
from .coverage_watch import CoverageWatch
from .server_host import ServerHost


class AgentStatePublisher:
    """Merges telemetry, link state and mission progress per agent."""

    def __init__(
        self,
        server: ServerHost,
        rate: float,
        on_published: Callable[[wire.AgentStates], None] | None = None,
    ) -> None:
        self._server = server
        self._period = 1.0 / rate if rate > 0 else 0.5
        self._on_published = on_published  # the journal's recorder
        self._telemetry: dict[str, wire.Telemetry] = {}
        self._telemetry_lock = threading.Lock()
        self._publisher = rospy.Publisher(
            interface.AGENT_STATES_TOPIC, wire.AgentStates, queue_size=10
        )
        self._subscribers = [
            rospy.Subscriber(
                interface.TELEMETRY_TOPIC.format(agent=agent.name),
                wire.Telemetry,
                self._on_telemetry,
                callback_args=agent.name,
                queue_size=10,
            )
            for agent in server.library.agents
        ]
        self._timer: rospy.Timer | None = None
        self._coverage = CoverageWatch(server.library)

    def start(self) -> None:
        """Start publishing at the configured rate."""
        self._timer = rospy.Timer(rospy.Duration(self._period), lambda _event: self.publish())

    def _on_telemetry(self, msg: wire.Telemetry, agent: str) -> None:
        with self._telemetry_lock:
            self._telemetry[agent] = msg
        self._coverage.telemetry(msg)

    def build(self) -> wire.AgentStates:
        """The current state of every dynamic agent."""
        server = self._server
        out = wire.AgentStates(stamp=rospy.Time.now())
        with server.locked():
            out.revision = server.mission.revision
            out.journal_alert = server.journal_alert
            for agent in server.library.dynamic_agents:
                out.agents.append(self._agent_state(agent))
        return out

    def publish(self) -> None:
        """Publish one AgentStates message."""
        if not rospy.is_shutdown():
            msg = self.build()
            self._publisher.publish(msg)
            if self._on_published is not None:
                self._on_published(msg)

    def _agent_state(self, agent: str) -> wire.AgentState:
        server = self._server
        report, link = server.link.details(agent)
        with self._telemetry_lock:
            telemetry = self._telemetry.get(agent) or wire.Telemetry(
                agent=agent, battery=math.nan, wifi_signal=math.nan
            )
        state = wire.AgentState(agent=agent, telemetry=telemetry)
        state.link = wire.LinkState(
            state=link_state_to_msg(report.status),
            last_heard=report.last_heard,
            round_trip=report.round_trip,
            commands_in_flight=report.in_flight,
            queue_hash=server.link.expected_hash(agent),
            robot_queue_hash=link.robot_hash,
            hash_mismatch=link.mismatch,
            commands_waiting=report.waiting,
            waiting_for=report.waiting_for,
            radio_dropped=server.link.radio_dropped(agent),
        )
        current = next(
            (
                s
                for s in server.mission.state.task(agent)
                if s.status is not SkillStatus.IDLE and not s.is_settled
            ),
            None,
        )
        if current is not None:
            state.current_skill_id = current.id
            state.current_status = wire.SkillStatus(int(current.status))
        if link.snapshot is not None:
            state.executor_state = link.snapshot.state
            state.waiting_on = link.snapshot.waiting_on
            state.lost_link = link.snapshot.policy
            state.hold = link.snapshot.hold
            state.barrier_wait = barrier_wait(link, report.last_heard)
        else:
            state.barrier_wait = -1.0
        in_force = _in_force(agent, state.lost_link)
        state.coverage_warning = self._coverage.warning(server.mission.state, agent, in_force)
        unsynced = waiting_on_unsynced(server.mission.state, agent)
        if unsynced and not state.waiting_on:
            # The robot cannot know: its partners' skills are still on the ground.
            state.waiting_on = f"{', '.join(unsynced)} (not synchronized)"
        return state


def barrier_wait(link: AgentLink, last_heard: float) -> float:
    """Seconds ``link``'s robot has waited at its barrier (-1: it does not wait at one).

    Robot clock to robot clock (the newest message's stamp and the wait's start), then the
    seconds since it was last heard: no clock is assumed equal to the ground's.
    """
    since = link.snapshot.waiting_since if link.snapshot is not None else 0.0
    if since <= 0.0:
        return -1.0
    return max(0.0, link.newest_stamp - since) + max(0.0, last_heard)


def _in_force(agent: str, msg: wire.LostLinkPolicy) -> PolicyInForce | None:
    """The policy ``agent``'s robot reports; None if it has not said, or said nonsense."""
    try:
        return policy_in_force_from_msg(msg)
    except InvalidRequest as error:
        rospy.logwarn_throttle(60.0, f"{agent}: its lost-link policy is unreadable: {error}")
        return None
