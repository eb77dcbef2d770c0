"""What the mission server reports about each robot, as a plain value (no rospy)."""

from __future__ import annotations

from dataclasses import dataclass

from ..core import Pose, SkillStatus


@dataclass(frozen=True)
class AgentStatus:
    """What the mission server reports about one agent's robot (``/rosmc/agent_states``).

    ``link`` is ``"up"``, ``"down"`` or ``"unknown"``; times are seconds, -1 if unknown.
    ``battery`` (0..1), ``wifi_signal`` (dBm) and ``pose`` are None without telemetry.
    """

    agent: str
    link: str = "unknown"
    last_heard: float = -1.0
    round_trip: float = -1.0
    commands_in_flight: int = 0
    hash_mismatch: bool = False
    battery: float | None = None
    wifi_signal: float | None = None
    in_coverage: bool = False
    pose: Pose | None = None
    current_skill: str = ""
    current_status: SkillStatus | None = None
    executor_state: str = ""
    waiting_on: str = ""
