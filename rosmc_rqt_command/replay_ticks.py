"""The marks on a replay's timeline bar: operator changes, robot outcomes and link outages.

Read from the recording itself (the same overlays ``rosmc timeline`` draws), so the bar
can show them before the replay has published anything.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

from rosmc_server.core import SkillStatus

if TYPE_CHECKING:  # the reader is imported when a recording is opened, not at the start
    from rosmc_server.recording.history import MissionHistory


class TickKind(Enum):
    """What a tick marks (its colour on the bar)."""

    OPERATOR = "operator change"
    SUCCESS = "skill succeeded"
    FAILURE = "skill failed"
    OUTAGE = "link lost"


@dataclass(frozen=True)
class ReplayTick:
    """One event on the timeline.

    Attributes:
        time: Seconds since the recording started.
        kind: What happened.
        text: One line for the tooltip and the messages (``science_rover: sample failed``).
    """

    time: float
    kind: TickKind
    text: str


@dataclass(frozen=True)
class RecordingOutline:
    """What the bar needs to know of a recording before it plays."""

    path: Path
    duration: float
    ticks: tuple[ReplayTick, ...]


_OUTCOMES = {SkillStatus.SUCCESS: TickKind.SUCCESS, SkillStatus.FAILURE: TickKind.FAILURE}


def outline_of(path: str | Path) -> RecordingOutline:
    """Read the recording at ``path``: its length and every tick, in time order.

    Raises:
        RosmcError: The file is not a readable recording (the reader's error).
    """
    from rosmc_server.recording.overlays import timeline_with_overlays

    history, timeline = timeline_with_overlays(path)
    ticks = [
        ReplayTick(mark.time, TickKind.OPERATOR, f"operator: {mark.summary}")
        for mark in timeline.marks
    ]
    for interval in timeline.intervals:
        kind = _OUTCOMES.get(interval.outcome) if interval.outcome else None
        if kind is not None and interval.outcome is not None:
            verb = "succeeded" if kind is TickKind.SUCCESS else "failed"
            text = f"{interval.agent}: {interval.label} {verb}"
            shown = _shown_at(history, interval.skill_id, interval.outcome, interval.end)
            ticks.append(ReplayTick(shown, kind, text))
    ticks += [
        ReplayTick(start, TickKind.OUTAGE, f"{agent}: link lost")
        for agent, start, _end in timeline.outages
    ]
    ticks.sort(key=lambda tick: tick.time)
    return RecordingOutline(Path(path), history.duration, tuple(ticks))


SHOWN_WITHIN = 10.0  # seconds after a robot's stamp in which the recording shows the outcome


def _shown_at(history: MissionHistory, skill_id: str, outcome: SkillStatus, after: float) -> float:
    """When the recording first shows ``skill_id`` with ``outcome``, from ``after`` on.

    ``after`` is the robot's own stamp of the outcome; the ground learns it a little later
    (its report travels), and a click on the tick must show it.
    """
    for info in history.revisions:
        seconds = history.seconds(info.log_time)
        if seconds < after:
            continue
        if seconds > after + SHOWN_WITHIN:
            break
        state = history.at_revision(info.revision)
        if state.has_skill(skill_id) and state.skill(skill_id).status is outcome:
            return seconds
    return after
