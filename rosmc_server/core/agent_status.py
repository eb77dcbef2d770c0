"""What the mission server reports about each robot's live state, as a plain value.

Clients (the CLI, both GUIs, replay) receive it on ``/rosmc/agent_states``; it lives in
the core so that widgets and marker geometry can use it without importing rospy.
"""

from __future__ import annotations

from dataclasses import dataclass

from .control import ExecutorState
from .model import SkillStatus
from .params import Pose
from .vocabulary import counted
from .waiting import waiting_text


@dataclass(frozen=True)
class AgentStatus:
    """What the mission server reports about one agent's robot (``/rosmc/agent_states``).

    ``link`` is ``"up"``, ``"down"`` or ``"unknown"`` (never heard); times are seconds,
    -1 if unknown. ``battery`` (0..1), ``wifi_signal`` (dBm) and ``pose`` are None without
    telemetry. ``queue_hash`` is the synchronized queue as the ground sees it and
    ``robot_queue_hash`` as the robot last reported it (``hash_mismatch``: a repair is under
    way). ``policy`` is the lost-link policy the robot reports in force (and whether it
    triggered), as the robot words it; "" if the robot has not said. ``commands_waiting``
    commands wait for contact with the robot, the oldest for ``waiting_for`` seconds (-1:
    none waits). ``coverage_warning`` is the server's warning that the synchronized task ends
    out of coverage under a policy that would leave the robot there ("" if none).
    ``radio_dropped`` radio datagrams were dropped at either end of the robot's link since
    they started (unsigned, forged, replayed: never acted on; :attr:`radio_text`).
    """

    agent: str
    link: str = "unknown"
    last_heard: float = -1.0
    round_trip: float = -1.0
    commands_in_flight: int = 0
    hash_mismatch: bool = False
    queue_hash: str = ""
    robot_queue_hash: str = ""
    battery: float | None = None
    wifi_signal: float | None = None
    in_coverage: bool = False
    pose: Pose | None = None
    current_skill: str = ""
    current_status: SkillStatus | None = None
    executor_state: str = ""
    waiting_on: str = ""
    policy: str = ""
    commands_waiting: int = 0
    waiting_for: float = -1.0
    coverage_warning: str = ""
    radio_dropped: int = 0

    @property
    def executor(self) -> ExecutorState:
        """``executor_state`` as a state (UNKNOWN if not reported)."""
        return ExecutorState.of(self.executor_state)

    @property
    def waiting_text(self) -> str:
        """``2 commands waiting for contact 3 min``, or "" when nothing waits."""
        return waiting_text(self.commands_waiting, self.waiting_for)

    @property
    def radio_text(self) -> str:
        """``212 forged radio datagrams dropped``, or "" when none was."""
        if self.radio_dropped <= 0:
            return ""
        return f"{counted(self.radio_dropped, 'forged radio datagram')} dropped"
