"""The robot link's protocol: commands to a robot; acks, reports, signals, snapshots back.

Both ends speak it: the ground (:mod:`rosmc_server.ros.ground_link`) and the on-robot
executor (:mod:`rosmc_server.executor`). These mirror ``rosmc/RobotCommand``,
``RobotAck``, ``RobotReport``, ``BarrierSignal`` and ``ExecutorSnapshot``;
:mod:`rosmc_server.conversions.robot_link` converts.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from ..model.control import HoldCause
from ..model.model import SkillInstance, SkillStatus
from ..skills.policy import PolicyInForce
from .commands import CommandKind


@dataclass(frozen=True)
class BarrierInfo:
    """A barrier as a robot needs it: the members and their agents."""

    id: str
    members: tuple[tuple[str, str], ...]  # (skill id, agent)

    def agents_except(self, agent: str) -> tuple[str, ...]:
        """The other agents that must be ready."""
        return tuple(a for _, a in self.members if a != agent)


@dataclass(frozen=True)
class Command:
    """A numbered command from the ground."""

    seq: int
    kind: CommandKind
    skills: tuple[SkillInstance, ...] = ()
    skill_ids: tuple[str, ...] = ()
    barriers: tuple[BarrierInfo, ...] = ()
    argument: str = ""


class AckResult(enum.IntEnum):
    """Numbers match ``rosmc/RobotAck``."""

    ACCEPTED = 0
    PARTIAL = 1
    REJECTED = 2


@dataclass(frozen=True)
class Ack:
    """The answer to one command (kept, so a retransmission gets the same answer)."""

    seq: int
    result: AckResult
    error: str = ""
    accepted_ids: tuple[str, ...] = ()
    rejected_ids: tuple[str, ...] = ()
    rejection_reasons: tuple[str, ...] = ()
    queue_hash: str = ""


@dataclass(frozen=True)
class Report:
    """A numbered status change, stored until the ground acknowledges it."""

    seq: int
    stamp: float
    skill_id: str
    status: SkillStatus
    attempt: int
    status_text: str
    started: float
    finished: float


class SignalKind(enum.IntEnum):
    """Numbers match ``rosmc/BarrierSignal``."""

    READY = 0
    WITHDRAWN = 1
    RELEASED = 2
    CONFIRMED = 3


@dataclass(frozen=True)
class Signal:
    """Robot-to-robot barrier coordination."""

    agent: str
    barrier_id: str
    skill_id: str
    kind: SignalKind
    stamp: float


@dataclass(frozen=True)
class Snapshot:
    """The executor's whole state, sent periodically."""

    stamp: float
    last_command_seq: int
    last_report_seq: int
    queue_hash: str
    queue: tuple[SkillInstance, ...]
    state: str
    active_skill_id: str
    waiting_on: str
    policy: PolicyInForce | None  # the lost-link policy in force; None: as last said
    full: bool = True  # ``queue`` holds every skill; False: it is left out (the digest stands)
    status_digest: str = ""
    hold: HoldCause = HoldCause.NONE  # why the robot holds after its lost-link policy acted
    waiting_since: float = 0.0  # robot clock when its barrier wait began; 0: not waiting


class Mode(enum.Enum):
    """Whether the operator let the robot execute."""

    STOPPED = "stopped"
    STARTED = "started"
    PAUSED = "paused"
