"""The engine's part in barrier waits: what to tell the peers, when to start, when to give up.

The rules of the protocol are the :class:`~.barriers.BarrierBoard`'s; this module keeps the
per-wait bookkeeping (what this robot last announced, and when it last CONFIRMED) and turns
the board's answers into signals for the peers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from rosmc_server.core.robots.protocol import BarrierInfo, Signal, SignalKind

from .barriers import BarrierBoard

ANNOUNCE_PERIOD = 0.5  # seconds between re-announcements (READY or CONFIRMED) while waiting


@dataclass
class Announcements:
    """What a robot waiting at a barrier last told its peers, and when."""

    last: float = 0.0
    kind: SignalKind | None = None
    last_confirmed: float = float("-inf")


class BarrierWaits:
    """Announces this robot's barrier waits and decides when a wait ends.

    Args:
        agent: This robot.
        board: What it knows of its peers.
        clock: Seconds (the engine's clock).
        send: Where signals for the peers go.
    """

    def __init__(
        self,
        agent: str,
        board: BarrierBoard,
        clock: Callable[[], float],
        send: Callable[[Signal], None],
    ) -> None:
        self.agent = agent
        self.board = board
        self.clock = clock
        self.send = send

    def hear(self, signal: Signal) -> None:
        """A peer's signal: recorded, and answered with RELEASED if this robot started there."""
        now = self.clock()
        self.board.hear(signal, now)
        answer = self.board.reply(signal, now)
        if answer is not None:
            self.send(answer)

    def announce(
        self, skill_id: str, barrier: BarrierInfo, told: Announcements, kind: SignalKind
    ) -> None:
        """Send ``kind`` about ``skill_id`` at ``barrier`` and remember it in ``told``."""
        now = self.clock()
        told.last, told.kind = now, kind
        if kind is SignalKind.CONFIRMED:
            told.last_confirmed = now
        self.send(Signal(self.agent, barrier.id, skill_id, kind, now))

    def announce_wait(self, skill_id: str, barrier: BarrierInfo, told: Announcements) -> None:
        """Tell the peers this robot waits: READY, or CONFIRMED once all have arrived."""
        self.announce(skill_id, barrier, told, self.board.announcement(barrier, self.clock()))

    def reannounce_due(self, told: Announcements) -> bool:
        """Whether the periodic repetition is due (signals may be lost)."""
        return self.clock() - told.last >= ANNOUNCE_PERIOD

    def try_release(self, skill_id: str, barrier: BarrierInfo, told: Announcements) -> bool:
        """True if the robot may start now (RELEASED is sent); else announce any change.

        Who it still waits for is in the snapshot (``waiting_on``): a report per peer
        arrival would cost n^2 reports over the ground link for an n-robot barrier.
        """
        now = self.clock()
        if not self.board.may_start(barrier, now):
            if self.board.announcement(barrier, now) is not told.kind:
                self.announce_wait(skill_id, barrier, told)  # at once, not next round
            return False
        self.board.released(barrier.id, skill_id)
        self.announce(skill_id, barrier, told, SignalKind.RELEASED)
        return True

    def may_give_up(self, told: Announcements) -> bool:
        """Whether the wait may time out: not while a partner may count this robot confirmed.

        A partner holding a CONFIRMED of this robot (for up to a lease) may start on it;
        failing now would leave that partner running alone.
        """
        return self.clock() - told.last_confirmed > self.board.lease

    def give_up(
        self, skill_id: str, barrier: BarrierInfo, told: Announcements, timeout: float
    ) -> str:
        """Withdraw from the wait; the failed skill's status text."""
        missing = ", ".join(self.board.waiting_on(barrier, self.clock()))
        self.announce(skill_id, barrier, told, SignalKind.WITHDRAWN)
        text = f"timed out after {timeout:g} s waiting at barrier '{barrier.id}'"
        return text + (f" for {missing}" if missing else "")

    def text(self, barrier: BarrierInfo) -> str:
        """The waiting skill's status text."""
        return self.board.waiting_text(barrier, self.clock())

    def summary(self, barrier: BarrierInfo) -> str:
        """Whom the robot waits for, for its snapshot."""
        return self.board.waiting_summary(barrier, self.clock())
