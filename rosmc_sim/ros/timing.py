"""Wall-clock helpers of the sim node: pacing against a real-time factor, and throttles.

The simulator is the clock source (it publishes ``/clock``), so it alone paces
itself by wall time; everything here takes the wall time as an argument, which
keeps it free of rospy and easy to reason about.
"""

from __future__ import annotations

import time
from collections.abc import Callable

MAX_LAG = 0.25  # wall seconds behind schedule before the pacer stops trying to catch up


class Throttle:
    """Says when something that should happen at most every ``period`` seconds is due."""

    def __init__(self, period: float) -> None:
        self.period = period
        self._next = float("-inf")

    def due(self, now: float) -> bool:
        """Whether the period has passed since the last time this answered yes."""
        if now < self._next:
            return False
        # Keep the phase when on time, but never build up a backlog of "due" answers.
        late = now - self._next > self.period
        self._next = now + self.period if late else self._next + self.period
        return True

    def reset(self) -> None:
        """Make the next :meth:`due` answer yes."""
        self._next = float("-inf")


class Pacer:
    """Keeps sim time at ``real_time_factor`` times wall time (0: as fast as possible).

    When the simulation cannot keep up, the pacer re-anchors rather than
    running a burst of unpaced steps to catch up.
    """

    def __init__(
        self,
        real_time_factor: float,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.real_time_factor = real_time_factor
        self._clock = clock
        self._sleep = sleep
        self._wall0 = clock()
        self._sim0 = 0.0
        self.started_wall = self._wall0

    def wait(self, sim_time: float) -> None:
        """Sleep until the wall clock reaches ``sim_time`` scaled by the factor."""
        if self.real_time_factor <= 0.0:
            return
        target = self._wall0 + (sim_time - self._sim0) / self.real_time_factor
        now = self._clock()
        if target > now:
            self._sleep(target - now)
        elif now - target > MAX_LAG:
            self._wall0, self._sim0 = now, sim_time

    def achieved(self, sim_time: float) -> float:
        """Sim seconds per wall second since the pacer was made."""
        wall = self._clock() - self.started_wall
        return sim_time / wall if wall > 0 else 0.0
