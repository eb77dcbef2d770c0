"""The robot link's bookkeeping, free of ROS: sequence numbers, retransmission, liveness.

Both ends speak the same rules:

* Commands are numbered 1, 2, ... per agent. The robot executes a command only
  when its number is the next one (``last + 1``); an older number is a
  duplicate it acknowledges again without executing; a newer one waits until
  the missing commands arrive. The ground retransmits every unacknowledged
  command, oldest first, with exponential backoff.
* Reports go the other way under the same rules (:class:`InboundSequence`).
* Until the ground has heard a robot's snapshot it does not know where the
  robot's numbering stands, so it sends nothing (the commands wait in order).
  While the robot is out of contact (its link DOWN) new commands wait the same
  way, unnumbered, and only those already numbered are retransmitted
  (:mod:`rosmc_server.core.robots.waiting` has the rules for what waits).
"""

from __future__ import annotations

import enum
import hashlib
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Generic, TypeVar

Payload = TypeVar("Payload")


class LinkStatus(enum.StrEnum):
    """Ground view of a link: heard lately, silent too long, or never heard. Its values are
    the words the views print; ``conversions.agents`` maps them to ``rosmc/LinkState``'s
    numbers."""

    UNKNOWN = "unknown"
    UP = "up"
    DOWN = "down"


def queue_hash(skill_ids: Iterable[str]) -> str:
    """Short digest of a robot's synchronized queue: the ordered ids it holds."""
    digest = hashlib.sha1(usedforsecurity=False)
    for skill_id in skill_ids:
        digest.update(skill_id.encode("utf-8"))
        digest.update(b"\n")
    return digest.hexdigest()[:12]


def status_digest(statuses: Iterable[tuple[str, int]]) -> str:
    """Short digest of a robot's queue with each skill's status, in order.

    The robot's periodic snapshot carries it instead of the whole queue: the ground
    compares it with its own and asks for the queue only when they differ.
    """
    digest = hashlib.sha1(usedforsecurity=False)
    for skill_id, status in statuses:
        digest.update(f"{skill_id}\t{status}\n".encode())
    return digest.hexdigest()[:12]


@dataclass
class Outgoing(Generic[Payload]):
    """A command waiting for its acknowledgement."""

    payload: Payload
    seq: int = 0  # 0 until first transmitted
    attempts: int = 0
    first_sent: float = 0.0
    next_send: float = 0.0
    backoff: int = 0  # retransmissions since the last contact: the next delay doubles
    asked: float = 0.0  # when it was queued (the outbox's clock)
    held: bool = False  # queued while the robot was out of contact


@dataclass(frozen=True)
class LinkReport:
    """A snapshot of the link for display."""

    status: LinkStatus
    last_heard: float  # seconds ago, -1 if never
    round_trip: float  # seconds, -1 if unknown
    in_flight: int
    waiting: int = 0  # unacknowledged while the robot is out of contact
    waiting_for: float = -1.0  # seconds the oldest of them has waited, -1 if none


@dataclass
class Outbox(Generic[Payload]):
    """Ground side of one robot link: numbering, retransmission and liveness.

    ``timeout`` is how long the robot may stay silent before the link is DOWN;
    retransmissions start after ``first_retry`` seconds and back off up to
    ``max_retry``.
    """

    timeout: float = 3.0
    first_retry: float = 0.25
    max_retry: float = 5.0
    _pending: deque[Outgoing[Payload]] = field(default_factory=deque)
    _last_seq: int | None = None  # robot's numbering; None until a snapshot is heard
    _last_heard: float | None = None
    _rtt: float | None = None

    @property
    def synchronized(self) -> bool:
        """Whether the robot's command numbering is known (a snapshot was heard)."""
        return self._last_seq is not None

    def prepare(self, payload: Payload, now: float = 0.0) -> Outgoing[Payload]:
        """A command asked at ``now``, as it would wait in this outbox (not queued)."""
        return Outgoing(payload, asked=now, held=self.status(now) is not LinkStatus.UP)

    def enqueue(self, payload: Payload, now: float = 0.0) -> Outgoing[Payload]:
        """Queue a command asked at ``now``; it is sent by :meth:`due` in order."""
        item = self.prepare(payload, now)
        self._pending.append(item)
        return item

    def pending(self) -> Sequence[Outgoing[Payload]]:
        """Commands not yet acknowledged, oldest first."""
        return tuple(self._pending)

    def unsent(self) -> Sequence[Outgoing[Payload]]:
        """Commands never transmitted (so never numbered), oldest first.

        Only these may still be changed or withdrawn: the robot cannot have seen them, and
        no sequence number has been given out for them.
        """
        return tuple(item for item in self._pending if item.seq == 0 and item.attempts == 0)

    def withdraw(self, item: Outgoing[Payload]) -> None:
        """Drop an unsent command (superseded before it ever left)."""
        if item.seq or item.attempts:
            raise ValueError("a command already transmitted cannot be withdrawn")
        self._pending.remove(item)

    def due(self, now: float) -> list[Outgoing[Payload]]:
        """Commands to transmit now, oldest first; numbers them on first send.

        When one command is due, every later unacknowledged one goes with it,
        so the robot always receives a gap-free run. While the robot is out of
        contact only commands already numbered go (retransmissions); the others
        wait, unnumbered, until it is heard again.
        """
        if self._last_seq is None or not self._pending:
            return []
        held = self.status(now) is not LinkStatus.UP
        going = [item for item in self._pending if not (held and item.seq == 0)]
        if not any(item.next_send <= now for item in going):
            return []
        out = []
        for item in going:
            if item.seq == 0:
                self._last_seq += 1
                item.seq = self._last_seq
                item.first_sent = now
            delay = min(self.max_retry, self.first_retry * 2**item.backoff)
            item.attempts += 1
            item.backoff += 1
            item.next_send = now + delay
            out.append(item)
        return out

    def contact_returned(self, now: float) -> None:
        """The robot is back after a silence: retransmit at once, backing off from the start.

        The backoff grew while nothing could arrive; keeping it would hold the commands
        back for up to ``max_retry`` after contact returned.
        """
        self._resend_all(now)

    def _resend_all(self, now: float) -> None:
        """Make every unacknowledged command due at ``now``, backing off from the start."""
        for item in self._pending:
            item.backoff = 0
            item.next_send = min(item.next_send, now)

    def acknowledge(self, seq: int, now: float) -> Outgoing[Payload] | None:
        """The robot acknowledged command ``seq``; returns it the first time, else None.

        Acknowledgements are per command (not cumulative): each carries the
        robot's answer to that command, and a robot answers a retransmitted
        command with the answer it gave the first time.

        They are taken in order, as the robot gave them: an answer that arrives while
        an earlier command is still unanswered (its answer was lost, say in a
        reconnection of the link's topics) is early. It is not taken (None): the
        earlier commands and this one are due again at once, and the robot answers
        them again, in order. Taken early, it would be applied before the answer it
        depends on (an upload confirmed only after the uploads before it).
        """
        self.heard(now)
        if self.early(seq):
            self._resend_all(now)
            return None
        for item in self._pending:
            if item.seq == seq and seq > 0:
                self._pending.remove(item)
                if item.attempts == 1:  # only unambiguous samples update the round trip
                    self.round_trip_sample(now - item.first_sent)
                return item
        return None

    def early(self, seq: int) -> bool:
        """Whether an answer to ``seq`` is early: a command numbered before it is unanswered."""
        return seq > 0 and any(0 < item.seq < seq for item in self._pending)

    def round_trip_sample(self, seconds: float) -> None:
        """One measured round trip (a command's ack, or an echoed heartbeat); smoothed."""
        self._rtt = seconds if self._rtt is None else 0.8 * self._rtt + 0.2 * seconds

    def robot_numbering(self, last_executed: int, now: float) -> bool:
        """Learn where the robot's numbering stands from its snapshot.

        On first contact, or when the robot has lost its state (its number went
        back), pending commands are renumbered after the robot's; returns True then.
        """
        self.heard(now)
        if self._last_seq is not None and last_executed >= self._acked_floor():
            return False
        self._last_seq = last_executed
        for item in self._pending:
            item.seq = 0
            item.attempts = 0
            item.next_send = now
        return True

    def _acked_floor(self) -> int:
        """Highest number the robot must already have executed."""
        assert self._last_seq is not None
        unacked = [item.seq for item in self._pending if item.seq]
        return (min(unacked) - 1) if unacked else self._last_seq

    def heard(self, now: float) -> None:
        """Anything arrived from the robot."""
        self._last_heard = now

    def status(self, now: float) -> LinkStatus:
        """UNKNOWN until first heard, then UP or DOWN by ``timeout``."""
        if self._last_heard is None:
            return LinkStatus.UNKNOWN
        return LinkStatus.UP if now - self._last_heard <= self.timeout else LinkStatus.DOWN

    def waiting(self, now: float) -> Sequence[Outgoing[Payload]]:
        """Commands waiting for contact: every unacknowledged one while the link is not UP."""
        return () if self.status(now) is LinkStatus.UP else tuple(self._pending)

    def report(self, now: float) -> LinkReport:
        """The link's state for display."""
        waiting = self.waiting(now)
        return LinkReport(
            self.status(now),
            -1.0 if self._last_heard is None else now - self._last_heard,
            -1.0 if self._rtt is None else self._rtt,
            len(self._pending),
            len(waiting),
            max((now - item.asked for item in waiting), default=-1.0),
        )


class Arrival(enum.Enum):
    """What to do with a numbered message that arrived."""

    NEXT = "next"  # process it
    DUPLICATE = "duplicate"  # already processed: acknowledge again, do nothing
    EARLY = "early"  # a message before it is missing: drop, the sender resends in order


@dataclass
class InboundSequence:
    """Receiver side of a numbered stream: accepts each number once, in order."""

    last: int = 0

    def classify(self, seq: int) -> Arrival:
        """Classify an arriving message number."""
        if seq <= self.last:
            return Arrival.DUPLICATE
        return Arrival.NEXT if seq == self.last + 1 else Arrival.EARLY

    def accept(self, seq: int) -> None:
        """Mark ``seq`` processed (it must be the next one)."""
        if seq != self.last + 1:
            raise ValueError(f"message {seq} accepted out of order after {self.last}")
        self.last = seq
