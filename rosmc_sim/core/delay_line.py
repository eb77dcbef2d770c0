"""A one-way radio link model: latency, random loss and blackouts.

Messages pushed into a :class:`DelayLine` come out ``latency`` seconds later
(in the caller's clock, so sim time stretches a 20-minute Mars delay), in
order, unless lost: each is dropped with probability ``drop``, and nothing
gets through while the line is blacked out (a message in flight when the
blackout starts is lost too, as a radio signal would be).
"""

from __future__ import annotations

import heapq
import itertools
import random
from dataclasses import dataclass, field
from typing import Generic, TypeVar

Item = TypeVar("Item")


@dataclass
class LineStats:
    """What a line did, for telemetry and tests."""

    sent: int = 0
    delivered: int = 0
    dropped: int = 0
    blacked_out: int = 0


@dataclass
class DelayLine(Generic[Item]):
    """A lossy, delayed, order-preserving one-way channel."""

    latency: float = 0.0
    drop: float = 0.0
    blackout: bool = False
    rng: random.Random = field(default_factory=random.Random)
    stats: LineStats = field(default_factory=LineStats)
    _queue: list[tuple[float, int, Item]] = field(default_factory=list)
    _order: itertools.count[int] = field(default_factory=itertools.count)

    def push(self, item: Item, now: float) -> None:
        """Send ``item`` at time ``now``."""
        self.stats.sent += 1
        if self.blackout:
            self.stats.blacked_out += 1
            return
        if self.drop > 0 and self.rng.random() < self.drop:
            self.stats.dropped += 1
            return
        heapq.heappush(self._queue, (now + self.latency, next(self._order), item))

    def set_blackout(self, blackout: bool) -> None:
        """Start or end a blackout; starting one loses what is in flight."""
        if blackout and not self.blackout:
            self.stats.blacked_out += len(self._queue)
            self._queue.clear()
        self.blackout = blackout

    def due(self, now: float) -> list[Item]:
        """Items whose delivery time has come, in sending order."""
        out = []
        while self._queue and self._queue[0][0] <= now:
            out.append(heapq.heappop(self._queue)[2])
        self.stats.delivered += len(out)
        return out

    def in_flight(self) -> int:
        """Items sent and not yet delivered."""
        return len(self._queue)
