"""Peer-to-peer barrier resolution on one robot: no member starts alone.

The promise: a member starts only once it knows that every other member knows that all
members have arrived. Messages between robots may be lost or cut off for minutes, so the
robots agree in two steps, each repeated until the next one is reached:

1. A member waiting at the barrier skill announces **READY**.
2. A member that has heard every other member READY (or CONFIRMED) announces
   **CONFIRMED**: "I wait here, and I know all of us do".
3. A member starts once it has heard every other member CONFIRMED, or any member
   RELEASED (a RELEASED member started under this rule, so everyone had confirmed). It
   then announces **RELEASED**, and answers every later READY or CONFIRMED of that
   barrier with RELEASED again, so a partner that was cut off while the others started
   learns it as soon as it hears anything.

A member cut off before or while the others confirm keeps waiting, and so do its
partners (they lack its confirmation): nobody starts until contact returns, and then all
start within a round of announcements. Only a cut inside the last exchange (between one
member hearing the final CONFIRMED and the others hearing its RELEASED, one one-way
message delay) can let one member start before the rest; no protocol over a lossy link
avoids that window (the two generals' problem), this one narrows it to a message.

Signals are soft state: a READY or CONFIRMED counts for :data:`READY_LEASE` seconds (of
the hearing robot's clock) unless repeated, so a member that crashed or was cut off
while waiting does not stay counted for ever. A member that pauses, stops, gives up or
is unsynchronized while waiting announces **WITHDRAWN**. Older signals than the newest
heard from a member are ignored (datagrams may arrive out of order). A member retried
after failing before the release hands its place to the fresh instance
(:meth:`BarrierBoard.member_retried`), as the ground does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rosmc_server.core.robots.protocol import BarrierInfo, Signal, SignalKind

READY_LEASE = 2.0  # seconds; waiting robots repeat their signal every 0.5 s
REPLY_INTERVAL = 0.2  # seconds: at most one RELEASED answer per barrier this often


@dataclass(frozen=True)
class _Heard:
    """The newest signal of one member about one barrier."""

    kind: SignalKind
    stamp: float  # the sender's clock
    heard: float  # this robot's clock


@dataclass
class BarrierBoard:
    """What one robot knows about its peers' progress at its barriers."""

    agent: str
    lease: float = READY_LEASE
    barriers: dict[str, BarrierInfo] = field(default_factory=dict)
    _heard: dict[str, dict[str, _Heard]] = field(default_factory=dict)  # barrier: agent: ...
    _released: set[str] = field(default_factory=set)
    _mine: dict[str, str] = field(default_factory=dict)  # released here: barrier -> my skill
    _replied: dict[str, float] = field(default_factory=dict)  # barrier -> last answer

    def replace(self, barriers: tuple[BarrierInfo, ...]) -> None:
        """The ground's complete set of barriers for this robot's skills."""
        self.barriers = {b.id: b for b in barriers}

    def barrier_of(self, skill_id: str) -> BarrierInfo | None:
        """The barrier this robot's skill belongs to, if any."""
        for barrier in self.barriers.values():
            if any(member == skill_id for member, _ in barrier.members):
                return barrier
        return None

    def released(self, barrier_id: str, skill_id: str) -> None:
        """This robot started ``skill_id`` at the barrier: it stays released for this robot."""
        self._released.add(barrier_id)
        self._mine[barrier_id] = skill_id

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
        """Record a peer's signal heard at ``now`` (own and overtaken signals are ignored)."""
        if signal.agent == self.agent:
            return
        heard = self._heard.setdefault(signal.barrier_id, {})
        previous = heard.get(signal.agent)
        if previous is not None and signal.stamp < previous.stamp and self._live(previous, now):
            return  # a newer signal of the same member came first (datagrams may reorder)
        heard[signal.agent] = _Heard(signal.kind, signal.stamp, now)
        if signal.kind is SignalKind.RELEASED:
            self._released.add(signal.barrier_id)

    def reply(self, signal: Signal, now: float) -> Signal | None:
        """RELEASED for a peer still waiting at a barrier this robot has started, if due."""
        skill_id = self._mine.get(signal.barrier_id)
        if skill_id is None or signal.agent == self.agent:
            return None
        if signal.kind not in (SignalKind.READY, SignalKind.CONFIRMED):
            return None
        if now - self._replied.get(signal.barrier_id, -REPLY_INTERVAL) < REPLY_INTERVAL:
            return None
        self._replied[signal.barrier_id] = now
        return Signal(self.agent, signal.barrier_id, skill_id, SignalKind.RELEASED, now)

    # -- what this robot may do ----------------------------------------------------------
    def is_released(self, barrier: BarrierInfo) -> bool:
        """Whether some member (this one included) has started at the barrier."""
        return barrier.id in self._released

    def not_arrived(self, barrier: BarrierInfo, now: float) -> tuple[str, ...]:
        """Other members not currently known to wait at the barrier."""
        return self._lacking(barrier, now, (SignalKind.READY, SignalKind.CONFIRMED))

    def not_confirmed(self, barrier: BarrierInfo, now: float) -> tuple[str, ...]:
        """Other members not known to know that all have arrived."""
        return self._lacking(barrier, now, (SignalKind.CONFIRMED,))

    def _lacking(
        self, barrier: BarrierInfo, now: float, kinds: tuple[SignalKind, ...]
    ) -> tuple[str, ...]:
        """Other members whose newest live signal is none of ``kinds`` (none once released)."""
        if self.is_released(barrier):
            return ()
        heard = self._heard.get(barrier.id, {})
        lacking = []
        for agent in barrier.agents_except(self.agent):
            last = heard.get(agent)
            if last is None or last.kind not in kinds or not self._live(last, now):
                lacking.append(agent)
        return tuple(lacking)

    def announcement(self, barrier: BarrierInfo, now: float) -> SignalKind:
        """What this waiting robot tells its peers: CONFIRMED once all have arrived."""
        return SignalKind.READY if self.not_arrived(barrier, now) else SignalKind.CONFIRMED

    def may_start(self, barrier: BarrierInfo, now: float) -> bool:
        """Whether every other member is known to know that all have arrived."""
        return not self.not_confirmed(barrier, now)

    def waiting_summary(self, barrier: BarrierInfo, now: float) -> str:
        """Who this robot waits for, e.g. ``r2 at B3 (arrived, not yet confirmed)``."""
        absent = self.not_arrived(barrier, now)
        unconfirmed = [a for a in self.not_confirmed(barrier, now) if a not in absent]
        parts = [f"{', '.join(absent)} at {barrier.id}"] if absent else []
        if unconfirmed:
            parts.append(f"{', '.join(unconfirmed)} at {barrier.id} (arrived, not yet confirmed)")
        return "; ".join(parts)

    def waiting_text(self, barrier: BarrierInfo, now: float) -> str:
        """The waiting skill's status text: ``waiting on ...`` (see :meth:`waiting_summary`)."""
        summary = self.waiting_summary(barrier, now)
        return f"waiting on {summary}" if summary else ""

    def waiting_on(self, barrier: BarrierInfo, now: float) -> tuple[str, ...]:
        """The members this robot still waits for, absent or unconfirmed."""
        return self.not_confirmed(barrier, now)

    def _live(self, heard: _Heard, now: float) -> bool:
        return now - heard.heard <= self.lease

    # -- persistence ---------------------------------------------------------------------
    def to_dict(self) -> dict[str, object]:
        """What the executor persists: the barriers known to have released, and its own part."""
        return {"released": sorted(self._released), "mine": dict(sorted(self._mine.items()))}

    def load(self, data: dict[str, object]) -> None:
        """Restore what :meth:`to_dict` saved (peers' signals are heard afresh)."""
        released = data.get("released", [])
        mine = data.get("mine", {})
        if not isinstance(released, list) or not isinstance(mine, dict):
            raise ValueError("the saved barrier state is malformed")
        self._heard = {}
        self._released = {str(b) for b in released}
        self._mine = {str(b): str(s) for b, s in mine.items()}
