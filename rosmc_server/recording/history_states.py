"""The mission at a revision of a history, built from the nearest snapshot before it.

Part of :mod:`.history`. A journal holds a full snapshot every few hundred changes; a
state is rebuilt from the nearest one at or before the revision asked for (or from a
state built before, kept every :data:`CHECKPOINT_EVERY` revisions) and the events
after it, so a lookup costs one snapshot and a few hundred events, however long the
recording is. Snapshots recorded with the installed ``rosmc/Mission`` definition are
read from their bytes straight into core objects (:mod:`~..conversions.unpacking`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import genpy
import rosmc.msg as wire

from rosmc_server.conversions import event_from_msg, mission_from_msg
from rosmc_server.conversions.unpacking import UNPACKED_MISSION_MD5, mission_from_bytes
from rosmc_server.core import MissionContent, MissionState, NotFound, RosmcError
from rosmc_server.core.live.updates import apply_event
from rosmc_server.recording.lazy import JournalRecord

CHECKPOINT_EVERY = 256
"""Revisions between two states kept while rebuilding (bounds the replay per lookup)."""


@dataclass
class Step:
    """How to reach one revision: from a snapshot, or by applying its event."""

    revision: int
    event: JournalRecord | None = None
    """The event to apply on the revision before (None: start from ``snapshot``)."""
    snapshot: JournalRecord | None = None
    """A snapshot of this very revision (for a step with an event: a periodic one)."""
    content: MissionContent | None = field(default=None, repr=False)
    """The content at this revision, once built (kept every few hundred steps)."""


class StateBuilder:
    """Rebuilds the mission at any step of ``steps`` (a revision each, oldest first).

    Args:
        steps: The history's steps; the first starts from a snapshot.
        problem: Called with a sentence for an event found not to apply.
    """

    def __init__(self, steps: Sequence[Step], problem: Callable[[str], None]) -> None:
        self._steps = steps
        self._problem = problem
        self._last: tuple[int, MissionState] | None = None  # the last state built
        self._broken: dict[int, str] = {}  # step -> why it cannot be rebuilt

    def state(self, index: int) -> MissionState:
        """The mission at step ``index`` (a copy the caller may keep).

        Raises:
            NotFound: An event on the way does not apply: the revision cannot be rebuilt.
        """
        if index in self._broken:
            raise NotFound(self._broken[index])
        start = self._start(index)
        last = self._last
        if last is not None and start <= last[0] <= index and self._sound(last[0], index):
            start, state = last  # sequential lookups apply only the new events
        else:
            state = MissionState(self._content(start), self._steps[start].revision)
        for number in range(start + 1, index + 1):
            step = self._steps[number]
            if step.event is None:  # the mission restarts from this snapshot
                state = MissionState(self._content(number), step.revision)
                continue
            try:
                apply_event(state, event_from_msg(step.event.message), describe=False)
            except RosmcError as err:
                self._break(number, str(err))
                self._last = None
                if index in self._broken:
                    raise NotFound(self._broken[index]) from err
                return self.state(index)  # from the snapshot after the broken steps
            if number % CHECKPOINT_EVERY == 0 and step.content is None:
                step.content = state.content()
        self._last = (index, state)
        return MissionState(state.content(), state.revision)

    def _sound(self, first: int, last: int) -> bool:
        """Whether no step after ``first`` up to ``last`` is known not to rebuild."""
        return not any(first < broken <= last for broken in self._broken)

    def _start(self, index: int) -> int:
        """The nearest step at or before ``index`` to build from."""
        start = index
        steps = self._steps
        while start > 0 and steps[start].content is None and steps[start].snapshot is None:
            start -= 1
        return start

    def _content(self, index: int) -> MissionContent:
        step = self._steps[index]
        if step.content is None:
            assert step.snapshot is not None, "a history starts from a snapshot"
            step.content = snapshot_content(step.snapshot)
        return step.content

    def _break(self, number: int, reason: str) -> None:
        """The event of step ``number`` does not apply: it and the steps up to the next
        snapshot cannot be rebuilt."""
        revision = self._steps[number].revision
        self._problem(f"revision {revision} does not apply ({reason}); skipped")
        end = number
        while end < len(self._steps) and (end == number or self._steps[end].snapshot is None):
            self._broken[end] = (
                f"revision {self._steps[end].revision} cannot be rebuilt (revision "
                f"{revision} does not apply: {reason})"
            )
            end += 1


def snapshot_content(record: JournalRecord) -> MissionContent:
    """The content of a recorded ``rosmc/Mission`` snapshot."""
    data = record.raw(wire.Mission)
    if data is not None and wire.Mission._md5sum == UNPACKED_MISSION_MD5:
        try:
            return mission_from_bytes(data)[0]
        except (genpy.DeserializationError, RosmcError):
            pass  # as genpy reads it, below (and fails as it does)
    return mission_from_msg(record.message)[0]
