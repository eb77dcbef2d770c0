"""The robot's books with the ground: its skills, the reports it sent, the commands it ran.

Every status change of a skill the robot holds becomes a numbered :class:`Report`, kept
in :attr:`SkillLedger.unacked` until the ground acknowledges it, so an outage delays
reports but never loses or reorders them.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import replace
from typing import Protocol

from rosmc_server.core import SkillInstance, SkillStatus
from rosmc_server.core.robots.link import queue_hash, status_digest
from rosmc_server.core.robots.protocol import Ack, Report


class ReportOutputs(Protocol):
    """Where the ledger's reports go (the engine's outputs)."""

    def report(self, report: Report) -> None:
        """A new status report."""

    def changed(self) -> None:
        """The state changed and should be persisted."""


class SkillLedger:
    """The skills in the robot's order, and the reports the ground has not acknowledged.

    Args:
        clock: Seconds (the engine's clock), stamped on each report.
        outputs: Where new reports go.

    Attributes:
        queue: The synchronized skills in order.
        last_report_seq: The number of the newest report.
        unacked: Reports the ground has not acknowledged yet, oldest first.
    """

    def __init__(self, clock: Callable[[], float], outputs: ReportOutputs) -> None:
        self.clock = clock
        self.outputs = outputs
        self.queue: list[SkillInstance] = []
        self.last_report_seq = 0
        self.unacked: list[Report] = []

    def find(self, skill_id: str) -> SkillInstance | None:
        """The skill ``skill_id``, or None if the robot does not hold it."""
        return next((s for s in self.queue if s.id == skill_id), None)

    def status(self, skill_id: str) -> SkillStatus | None:
        """The status of skill ``skill_id``, or None if the robot does not hold it."""
        skill = self.find(skill_id)
        return None if skill is None else skill.status

    def set(
        self,
        skill_id: str,
        status: SkillStatus,
        text: str | None = None,
        started: float | None = None,
        finished: float | None = None,
        attempt: int | None = None,
    ) -> None:
        """Change a held skill's status (fields left None keep their value) and report it."""
        old = self.find(skill_id)
        assert old is not None
        new = replace(
            old,
            status=status,
            status_text=old.status_text if text is None else text,
            started=old.started if started is None else started,
            finished=old.finished if finished is None else finished,
            attempt=old.attempt if attempt is None else attempt,
        )
        if new == old:
            return
        self.queue = [new if s.id == new.id else s for s in self.queue]
        self.last_report_seq += 1
        report = Report(
            self.last_report_seq,
            self.clock(),
            new.id,
            new.status,
            new.attempt,
            new.status_text,
            new.started,
            new.finished,
        )
        self.unacked.append(report)
        self.outputs.report(report)
        self.outputs.changed()

    def acknowledged(self, seq: int) -> bool:
        """The ground has every report up to ``seq``; True if that dropped any kept."""
        before = len(self.unacked)
        self.unacked = [r for r in self.unacked if r.seq > seq]
        return len(self.unacked) != before

    def queue_hash(self) -> str:
        """Hash of the ids this robot holds, in order (the ground computes the same)."""
        return queue_hash(s.id for s in self.queue)

    def status_digest(self) -> str:
        """Digest of every held skill's status (the ground asks for the queue on a mismatch)."""
        return status_digest((s.id, int(s.status)) for s in self.queue)


KEPT_ACKS = 256
"""Answers kept to repeat when the ground resends a command it sent before."""


class CommandLog:
    """The numbered ground commands: each executed once, in order, its answer kept.

    Attributes:
        last_seq: The number of the last command executed.
        acks: The answers of the last :data:`KEPT_ACKS` commands, by number.
    """

    def __init__(self) -> None:
        self.last_seq = 0
        self.acks: OrderedDict[int, Ack] = OrderedDict()

    def answer(self, seq: int, execute: Callable[[], Ack], again: Callable[[], Ack]) -> Ack | None:
        """Execute command ``seq`` if it is the next one; None if an earlier one is missing.

        A command executed before gets its kept answer, or ``again()`` once that is gone.
        """
        if seq <= self.last_seq:
            return self.acks.get(seq) or again()
        if seq != self.last_seq + 1:
            return None  # an earlier command is missing; the ground resends in order
        ack = execute()
        self.last_seq = seq
        self.acks[seq] = ack
        while len(self.acks) > KEPT_ACKS:
            self.acks.popitem(last=False)
        return ack
