"""Peer-to-peer barrier resolution on one robot.

Each robot waiting at a barrier skill announces READY and keeps re-announcing
until released (messages may be lost). It starts as soon as it knows every
other member is ready, or hears that a member already started (RELEASED),
which can only happen once everybody was ready. A member that pauses, stops
or is unsynchronized while waiting sends WITHDRAWN.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .protocol import BarrierInfo, Signal, SignalKind


@dataclass
class BarrierBoard:
    """What one robot knows about its peers' barrier readiness."""

    agent: str
    barriers: dict[str, BarrierInfo] = field(default_factory=dict)
    _ready: dict[str, set[str]] = field(default_factory=dict)
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

    def hear(self, signal: Signal) -> None:
        """Record a peer's signal (own signals are ignored)."""
        if signal.agent == self.agent:
            return
        ready = self._ready.setdefault(signal.barrier_id, set())
        if signal.kind is SignalKind.WITHDRAWN:
            ready.discard(signal.agent)
        else:
            ready.add(signal.agent)
            if signal.kind is SignalKind.RELEASED:
                self._released.add(signal.barrier_id)

    def missing(self, barrier: BarrierInfo) -> tuple[str, ...]:
        """Members not known to be ready (empty once the barrier may release)."""
        if barrier.id in self._released:
            return ()
        ready = self._ready.get(barrier.id, set())
        return tuple(a for a in barrier.agents_except(self.agent) if a not in ready)

    def to_dict(self) -> dict[str, object]:
        """Peer readiness, for the executor's persisted state."""
        return {
            "ready": {b: sorted(agents) for b, agents in self._ready.items()},
            "released": sorted(self._released),
        }

    def load(self, data: dict[str, object]) -> None:
        """Restore peer readiness saved by :meth:`to_dict`."""
        ready = data.get("ready", {})
        released = data.get("released", [])
        assert isinstance(ready, dict) and isinstance(released, list)
        self._ready = {str(b): set(agents) for b, agents in ready.items()}
        self._released = {str(b) for b in released}
