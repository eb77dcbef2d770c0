"""Peer-to-peer barrier resolution on one robot.

Each robot waiting at a barrier skill announces READY and keeps re-announcing
until released (messages may be lost). It starts as soon as it knows every
other member is ready, or hears that a member already started (RELEASED),
which can only happen once everybody was ready. A member that pauses, stops,
gives up waiting (its timeout) or is unsynchronized while waiting sends WITHDRAWN.
A member retried after failing before the release hands its place to the fresh
instance (:meth:`BarrierBoard.member_retried`), as the ground does.

Readiness is soft state: a READY counts for :data:`READY_LEASE` seconds (of
the hearing robot's clock) unless repeated, so a member that crashed or
restarted while waiting, and could not withdraw, does not stay "ready"
for ever. It is not persisted either: waiting peers repeat it anyway.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .protocol import BarrierInfo, Signal, SignalKind

READY_LEASE = 2.0  # seconds; waiting robots repeat READY every 0.5 s


@dataclass
class BarrierBoard:
    """What one robot knows about its peers' barrier readiness."""

    agent: str
    lease: float = READY_LEASE
    barriers: dict[str, BarrierInfo] = field(default_factory=dict)
    _ready: dict[str, dict[str, float]] = field(default_factory=dict)  # barrier: agent: heard
    _released: set[str] = field(default_factory=set)

    def replace(self, barriers: tuple[BarrierInfo, ...]) -> None:
        """The ground's complete set of barriers for this robot's skills."""
        self.barriers = {b.id: b for b in barriers}

    def barrier_of(self, skill_id: str) -> BarrierInfo | None:
        """The barrier this robot's skill belongs to, if any."""
        for barrier in self.barriers.values():
            if any(member == skill_id for member, _ in barrier.members):
                return barrier
        return None

    def released(self, barrier_id: str) -> None:
        """This robot released the barrier itself: it stays released for this robot."""
        self._released.add(barrier_id)

    def member_retried(self, failed_id: str, fresh_id: str) -> None:
        """A failed member is retried: before the release its fresh instance takes its place.

        The ground makes the same change and sends the new set; doing it here too keeps a
        fresh instance from starting alone should that set arrive after the retry.
        """
        barrier = self.barrier_of(failed_id)
        if barrier is None or barrier.id in self._released:
            return
        members = tuple(
            (fresh_id if skill_id == failed_id else skill_id, agent)
            for skill_id, agent in barrier.members
        )
        self.barriers[barrier.id] = BarrierInfo(barrier.id, members)

    def hear(self, signal: Signal, now: float) -> None:
        """Record a peer's signal heard at ``now`` (own signals are ignored)."""
        if signal.agent == self.agent:
            return
        ready = self._ready.setdefault(signal.barrier_id, {})
        if signal.kind is SignalKind.WITHDRAWN:
            ready.pop(signal.agent, None)
        else:
            ready[signal.agent] = now
            if signal.kind is SignalKind.RELEASED:
                self._released.add(signal.barrier_id)

    def missing(self, barrier: BarrierInfo, now: float) -> tuple[str, ...]:
        """Members not known to be ready at ``now`` (empty once the barrier may release)."""
        if barrier.id in self._released:
            return ()
        ready = self._ready.get(barrier.id, {})
        return tuple(
            a
            for a in barrier.agents_except(self.agent)
            if a not in ready or now - ready[a] > self.lease
        )

    def to_dict(self) -> dict[str, object]:
        """What the executor persists: the barriers known to have released."""
        return {"released": sorted(self._released)}

    def load(self, data: dict[str, object]) -> None:
        """Restore what :meth:`to_dict` saved (peers' readiness is heard afresh)."""
        released = data.get("released", [])
        assert isinstance(released, list)
        self._ready = {}
        self._released = {str(b) for b in released}
