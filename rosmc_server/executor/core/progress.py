"""Progress texts of running skills, paced for the radio.

A skill may say how it is doing on every step (a drive's metres to go, an action's
feedback at tens of hertz). Each text that reaches the ground is a numbered report
over the robot's radio and a journaled mission event, so the engine takes at most one
text per :data:`PROGRESS_PERIOD`: the newest one, so what operators read is never stale
by more than that, and the last text a skill says before it finishes is never lost.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

PROGRESS_PERIOD = 1.0
"""Seconds (of the pace clock) between two progress texts handed out."""


class ProgressBox:
    """Progress texts put by skills from any thread, taken by the engine at a pace.

    Args:
        clock: Seconds to pace by (wall time on a robot: the radio's time).
    """

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self._box: deque[tuple[str, str]] = deque()  # appends and pops are atomic
        self._newest: tuple[str, str] | None = None
        self._taken_at = -math.inf

    def put(self, skill_id: str, text: str) -> None:
        """A skill's new progress text (callable from any thread)."""
        self._box.append((skill_id, text))

    def take(self, flush: bool = False) -> tuple[str, str] | None:
        """The newest (skill id, text) if one is waiting and due (or ``flush``), else None."""
        while self._box:
            self._newest = self._box.popleft()
        if self._newest is None:
            return None
        now = self._clock()
        if not flush and now - self._taken_at < PROGRESS_PERIOD:
            return None
        newest, self._newest, self._taken_at = self._newest, None, now
        return newest
