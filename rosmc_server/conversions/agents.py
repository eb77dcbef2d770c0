"""Agent states (link, telemetry, executor) from messages, as core :class:`AgentStatus`.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core.
"""

from __future__ import annotations

import math

import rosmc.msg as wire

from ..core import AgentStatus, InvalidRequest, PolicyInForce, SkillStatus
from ..core.model.control import HoldCause
from ..core.robots.link import LinkStatus
from .policy import policy_in_force_from_msg
from .values import pose_from_msg

_LINK_STATES: dict[int, LinkStatus] = {
    wire.LinkState.UNKNOWN: LinkStatus.UNKNOWN,
    wire.LinkState.UP: LinkStatus.UP,
    wire.LinkState.DOWN: LinkStatus.DOWN,
}


def link_state_to_msg(status: LinkStatus) -> int:
    """A link's state as ``rosmc/LinkState.state``."""
    return next(number for number, known in _LINK_STATES.items() if known is status)


def agent_statuses_from_msg(msg: wire.AgentStates) -> dict[str, AgentStatus]:
    """``rosmc/AgentStates`` as one :class:`AgentStatus` per agent."""
    return {state.agent: agent_status_from_msg(state) for state in msg.agents}


def agent_status_from_msg(msg: wire.AgentState) -> AgentStatus:
    """``rosmc/AgentState`` as an :class:`AgentStatus`."""
    telemetry = msg.telemetry
    has_telemetry = bool(telemetry.frame_id) or not telemetry.stamp.is_zero()
    current = msg.current_skill_id
    return AgentStatus(
        agent=msg.agent,
        link=_LINK_STATES.get(msg.link.state, LinkStatus.UNKNOWN),
        last_heard=msg.link.last_heard,
        round_trip=msg.link.round_trip,
        commands_in_flight=msg.link.commands_in_flight,
        hash_mismatch=msg.link.hash_mismatch,
        # Journals recorded before these fields existed decode without them.
        commands_waiting=getattr(msg.link, "commands_waiting", 0),
        waiting_for=getattr(msg.link, "waiting_for", -1.0),
        queue_hash=msg.link.queue_hash,
        robot_queue_hash=msg.link.robot_queue_hash,
        battery=_finite(telemetry.battery),
        wifi_signal=_finite(telemetry.wifi_signal),
        in_coverage=telemetry.in_coverage,
        pose=pose_from_msg(telemetry.pose) if has_telemetry else None,
        current_skill=current,
        current_status=SkillStatus(msg.current_status.value) if current else None,
        executor_state=msg.executor_state,
        waiting_on=msg.waiting_on,
        lost_link=_policy(msg),
        coverage_warning=msg.coverage_warning,
        radio_dropped=getattr(msg.link, "radio_dropped", 0),
        hold=HoldCause.of(getattr(msg, "hold", "")),
        barrier_wait=getattr(msg, "barrier_wait", -1.0),
    )


def _policy(msg: wire.AgentState) -> PolicyInForce | None:
    """The policy in force; None if unsaid, or in a journal from before it was typed (which
    has only its words) or malformed (a display must not fail over it)."""
    try:
        return policy_in_force_from_msg(getattr(msg, "lost_link", None))
    except InvalidRequest:
        return None


def _finite(number: float) -> float | None:
    return float(number) if math.isfinite(number) else None
