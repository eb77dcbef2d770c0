"""What the mission server reports about each robot's live state, as a plain value.

Clients (the CLI, both GUIs, replay) receive it on ``/rosmc/agent_states``; it lives in
the core so that widgets and marker geometry can use it without importing rospy.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ..model.control import ExecutorState, HoldCause
from ..model.model import SkillStatus
from ..skills.params import Pose
from ..skills.policy import PolicyInForce
from ..views.vocabulary import counted
from .link import LinkStatus
from .waiting import waiting_text

AGES = ("last_heard", "waiting_for", "barrier_wait")
"""The fields of :class:`AgentStatus` that are ages in seconds, growing with the clock."""


@dataclass(frozen=True)
class AgentStatus:
    """What the mission server reports about one agent's robot (``/rosmc/agent_states``).

    ``link`` is a :class:`LinkStatus` (its words, ``"up"``..., are taken too); times are seconds,
    -1 if unknown. ``battery`` (0..1), ``wifi_signal`` (dBm) and ``pose`` are None without
    telemetry. ``queue_hash`` is the synchronized queue as the ground sees it and
    ``robot_queue_hash`` as the robot last reported it (``hash_mismatch``: a repair is under
    way). ``lost_link`` is the lost-link policy the robot reports in force (whether it is
    the library's default, what it did); None if the robot has not said (:attr:`policy`
    words it). ``commands_waiting`` commands wait for contact with the robot, the oldest for
    ``waiting_for`` seconds (-1: none waits). ``coverage_warning`` is the server's warning
    that the synchronized task ends out of coverage under a policy that would leave the
    robot there ("" if none).
    ``radio_dropped`` radio datagrams were dropped at either end of the robot's link since
    they started (unsigned, forged, replayed: never acted on; :attr:`radio_text`).
    ``hold`` says why the robot holds after its lost-link policy acted (NONE: it does not):
    it starts no new work and its barrier partners wait until the operator resumes it.
    ``barrier_wait`` is how long the robot has waited at its barrier (-1: it does not).
    """

    agent: str
    link: LinkStatus = LinkStatus.UNKNOWN
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
    lost_link: PolicyInForce | None = None
    commands_waiting: int = 0
    waiting_for: float = -1.0
    coverage_warning: str = ""
    radio_dropped: int = 0
    hold: HoldCause = HoldCause.NONE
    barrier_wait: float = -1.0

    def __post_init__(self) -> None:
        # Its words ("up", ...) are accepted and kept as the enum: one comparison everywhere.
        object.__setattr__(self, "link", LinkStatus(self.link))

    def news_since(self, old: AgentStatus | None) -> bool:
        """Whether this status says something ``old`` did not, at the resolution shown.

        ``last_heard`` and ``waiting_for`` are ages that grow with the clock: they count
        only when their whole seconds change. So a robot heard twice a second, or one never
        heard, has no news until something about it changes, and one out of contact has
        news once a second (the seconds its link has been down).
        """
        if old is None:
            return True
        ages = {name: getattr(old, name) for name in AGES}
        if dataclasses.replace(self, **ages) != old:
            return True
        return any(math.floor(getattr(self, name)) != math.floor(age) for name, age in ages.items())

    @property
    def executor(self) -> ExecutorState:
        """``executor_state`` as a state (UNKNOWN if not reported)."""
        return ExecutorState.of(self.executor_state)

    @property
    def policy(self) -> str:
        """The policy in force in one line (``on link loss: hold after 30 s``), "" if unsaid."""
        return self.lost_link.describe() if self.lost_link is not None else ""

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
