"""What the executor tells operators about itself: its one-word state and its snapshot.

The snapshot is the robot's periodic word to the ground (:mod:`.pacing` decides when it
goes): the numbering on both sides of the link, the queue (or only its digest), what the
robot is doing and waiting for, and its lost-link policy. Read-only: nothing here changes
the engine.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from rosmc_server.core import SkillStatus
from rosmc_server.core.model.control import ExecutorState, HoldCause
from rosmc_server.core.robots.protocol import Mode, Snapshot

from . import queueing
from .active import ActiveSkill
from .barrier_wait import BarrierWaits
from .ledger import CommandLog, SkillLedger
from .lost_link import LostLinkGuard

S = SkillStatus


class Reporting(Protocol):
    """The parts of the engine a report reads."""

    @property
    def active(self) -> ActiveSkill | None:
        """The skill being worked on, if any."""

    @property
    def mode(self) -> Mode:
        """Started, paused or stopped."""

    @property
    def ledger(self) -> SkillLedger:
        """The robot's skills in order (and its reports)."""

    @property
    def commands(self) -> CommandLog:
        """The ground commands executed."""

    @property
    def lost_link(self) -> LostLinkGuard:
        """What the robot does on its own when out of contact."""

    @property
    def waits(self) -> BarrierWaits:
        """The barrier waits, told to and heard from the peers."""

    def hold(self) -> HoldCause:
        """Why the robot holds after its lost-link policy acted (NONE: it does not)."""

    @property
    def clock(self) -> Callable[[], float]:
        """Mission time."""


def executor_state(engine: Reporting) -> ExecutorState:
    """What the executor is doing now."""
    if engine.lost_link.contingency is not None:
        return ExecutorState.CONTINGENCY
    if engine.mode is not Mode.STARTED:
        return ExecutorState(engine.mode.value)
    if queueing.holding(engine.ledger.queue):
        return ExecutorState.HOLDING
    active = engine.active
    if active is None:
        return ExecutorState.IDLE
    return ExecutorState.WAITING if active.behavior is None else ExecutorState.RUNNING


def snapshot(engine: Reporting, full: bool) -> Snapshot:
    """The state for the periodic snapshot: the queue only if ``full``, its digest always."""
    active = engine.active
    waiting, since = "", 0.0
    if active is not None and active.at_barrier and active.barrier is not None:
        waiting = engine.waits.summary(active.barrier)
        if engine.ledger.status(active.skill_id) is S.SYNCWAITING:
            since = active.waiting_since
    return Snapshot(
        engine.clock(),
        engine.commands.last_seq,
        engine.ledger.last_report_seq,
        engine.ledger.queue_hash(),
        tuple(engine.ledger.queue) if full else (),
        executor_state(engine).value,
        active.skill_id if active else "",
        waiting,
        engine.lost_link.in_force(),
        full,
        engine.ledger.status_digest(),
        engine.hold(),
        since,
    )
