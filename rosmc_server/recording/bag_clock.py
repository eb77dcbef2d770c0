"""The clock of a converted bag: the mission clock the recorded stamps use.

A journal logs every record at the server's wall-clock time, while what the records carry
is stamped on the mission clock: the simulator stamps ``/tf`` with sim time, the robots
stamp their reports and the server its events with the time of the ROS graph (sim time
under simulation). A bag whose times were the log times would hold two clocks: with
``rosbag play --clock`` and ``/use_sim_time`` every tf2 lookup but ``Time(0)`` would
extrapolate into the future. So a bag's time is the mission clock:

- a record that carries a stamp on that clock is written at its stamp (a ``/tf`` message at
  its newest transform's stamp), so the ``/clock`` that ``rosbag play --clock`` publishes
  matches the stamps tf2 looks up;
- every other record at its log time mapped onto that clock, piecewise linearly through
  the (log time, stamp) pairs of those records, and at the average rate beyond them (never
  before the clock's first nanosecond).

The stamps come from ``/tf`` (what tf2 needs), or in a recording without TF from the robots'
reports, or from the server's events; a recording with none of them keeps its log times.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from rosmc_server.interface import EVENTS_TOPIC, ROBOT_REPORTS_TOPIC, TF_TOPIC

from .reader import JournalRecord

LOG_TIME = "log time"
"""The clock of a recording without stamps: the server's wall clock when it journaled."""

CLOCK_SOURCES: tuple[tuple[str, Callable[[Any], int]], ...] = (
    (TF_TOPIC, lambda msg: max((t.header.stamp.to_nsec() for t in msg.transforms), default=0)),
    (ROBOT_REPORTS_TOPIC, lambda msg: int(msg.stamp.to_nsec())),
    (EVENTS_TOPIC, lambda msg: int(msg.stamp.to_nsec())),
)
"""Where the mission clock is read, in order of preference: the topic and its stamp (ns)."""


@dataclass(frozen=True)
class MissionClock:
    """Maps a recording's log times onto the clock its stamps use.

    Attributes:
        source: The topic whose stamps define the clock, or :data:`LOG_TIME`.
        log_times: Log times (ns) of the pairs, increasing.
        stamps: The matching stamps (ns), never decreasing.
    """

    source: str
    log_times: tuple[int, ...] = ()
    stamps: tuple[int, ...] = ()

    @classmethod
    def of(cls, records: Sequence[JournalRecord]) -> MissionClock:
        """The clock of ``records``: the first source of :data:`CLOCK_SOURCES` with stamps."""
        for topic, stamp_of in CLOCK_SOURCES:
            pairs = sorted(
                (record.log_time, stamp)
                for record in records
                if record.topic == topic and (stamp := stamp_of(record.message)) > 0
            )
            log_times: list[int] = []
            stamps: list[int] = []
            for log_time, stamp in pairs:  # pairs that would run the clock backwards are left out
                if not stamps or (stamp >= stamps[-1] and log_time > log_times[-1]):
                    log_times.append(log_time)
                    stamps.append(stamp)
            if stamps:
                return cls(topic, tuple(log_times), tuple(stamps))
        return cls(LOG_TIME)

    @property
    def rate(self) -> float:
        """Mission-clock seconds per log-time second over the pairs (1.0 with fewer than two)."""
        span = self.log_times[-1] - self.log_times[0] if self.log_times else 0
        return (self.stamps[-1] - self.stamps[0]) / span if span > 0 else 1.0

    def at(self, log_time: int) -> int:
        """The mission-clock time (ns, at least 1) of something journaled at ``log_time``."""
        if not self.stamps:
            return log_time
        index = bisect.bisect_right(self.log_times, log_time)
        if index == 0:
            mapped = self.stamps[0] - (self.log_times[0] - log_time) * self.rate
        elif index == len(self.log_times):
            mapped = self.stamps[-1] + (log_time - self.log_times[-1]) * self.rate
        else:
            low, high = self.log_times[index - 1], self.log_times[index]
            before, after = self.stamps[index - 1], self.stamps[index]
            mapped = before + (log_time - low) / (high - low) * (after - before)
        return max(int(mapped), 1)

    def time_of(self, record: JournalRecord) -> int:
        """The bag time (ns) of ``record``: its stamp on this clock, else its log time mapped."""
        for topic, stamp_of in CLOCK_SOURCES:
            if topic == self.source == record.topic:
                stamp = stamp_of(record.message)
                if stamp > 0:
                    return stamp
        return self.at(record.log_time)
