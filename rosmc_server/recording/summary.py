"""What a recording holds, in numbers: ``rosmc info FILE``.

One pass over a journal gives its duration, the robots, the operator's and the robots'
changes by kind, every robot's executed skills with their outcomes, the link outages (from
the recorded agent states) and the score over time (from the simulator's science state).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..core import SkillStatus
from ..core.model.model import Resolution, SkillInstance
from ..interface import (
    AGENT_STATES_TOPIC,
    EVENTS_TOPIC,
    MISSION_TOPIC,
    ROBOT_REPORTS_TOPIC,
    SCIENCE_TOPIC,
)
from .history import MissionHistory
from .reader import JournalResult, read_journal

LINK_DOWN = 2  # rosmc/LinkState.DOWN


@dataclass(frozen=True)
class Outage:
    """A time a robot's link was down, in seconds since the recording started."""

    agent: str
    start: float
    end: float | None  # None: still down when the recording ended

    def length(self, recording_end: float) -> float:
        """Seconds the link was down (up to the end of the recording)."""
        return (recording_end if self.end is None else self.end) - self.start


@dataclass(frozen=True)
class RobotOutcomes:
    """How a robot's skills ended, at the end of the recording."""

    agent: str
    succeeded: int = 0
    failed: int = 0  # failures nobody resolved
    retried: int = 0  # failures followed by a retry
    skipped: int = 0
    unfinished: int = 0  # synchronized and not finished when the recording ended
    blueprint: int = 0  # never synchronized
    attempts: int = 0  # executions the robot started (each retry is one more)


@dataclass(frozen=True)
class RecordingSummary:
    """Everything ``rosmc info`` prints about one journal."""

    path: Path
    size_bytes: int
    duration: float
    first_revision: int
    last_revision: int
    changes: dict[str, int]
    robots: list[RobotOutcomes]
    outages: list[Outage]
    score: list[tuple[float, float]]  # (seconds, score), as recorded; empty without a sim
    records: dict[str, int]
    problems: tuple[str, ...] = field(default=())

    @property
    def final_score(self) -> float | None:
        """The last recorded score, or None if the recording has no science state."""
        return self.score[-1][1] if self.score else None


def summarize(path: str | Path) -> RecordingSummary:
    """Read the journal at ``path`` once and summarize it."""
    result = read_journal(path)
    mission_topics = (MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC)
    history = MissionHistory(
        replace(result, records=tuple(r for r in result.records if r.topic in mission_topics))
    )
    revisions = history.revisions
    final = history.at_revision(revisions[-1].revision)
    changes = Counter(info.kind.name for info in revisions if info.kind is not None)
    return RecordingSummary(
        path=Path(path),
        size_bytes=result.size,
        duration=_span(result),
        first_revision=revisions[0].revision,
        last_revision=revisions[-1].revision,
        changes=dict(changes.most_common()),
        robots=[_outcomes(agent, final.task(agent)) for agent in final.agents],
        outages=link_outages(result, history),
        score=[
            (history.seconds(r.log_time), float(r.message.score))
            for r in result.records
            if r.topic == SCIENCE_TOPIC
        ],
        records=dict(Counter(r.topic for r in result.records)),
        problems=history.warnings + history.problems,
    )


def _outcomes(agent: str, task: Sequence[SkillInstance]) -> RobotOutcomes:
    counts: Counter[str] = Counter()
    for skill in task:
        counts["attempts"] += skill.status.has_started
        if skill.status is SkillStatus.SUCCESS:
            counts["succeeded"] += 1
        elif skill.status is SkillStatus.FAILURE:
            key = {Resolution.RETRIED: "retried", Resolution.SKIPPED: "skipped"}
            counts[key.get(skill.resolution, "failed")] += 1
        elif skill.status is SkillStatus.IDLE:
            counts["blueprint"] += 1
        else:
            counts["unfinished"] += 1
    return RobotOutcomes(agent, **counts)


def link_outages(result: JournalResult, history: MissionHistory) -> list[Outage]:
    """Every stretch a robot's link was DOWN in the recorded agent states, by start."""
    down_since: dict[str, float] = {}
    outages: list[Outage] = []
    for record in result.records:
        if record.topic != AGENT_STATES_TOPIC:
            continue
        now = history.seconds(record.log_time)
        for state in record.message.agents:
            down = state.link.state == LINK_DOWN
            if down and state.agent not in down_since:
                down_since[state.agent] = now
            elif not down and state.agent in down_since:
                outages.append(Outage(state.agent, down_since.pop(state.agent), now))
    outages += [Outage(agent, start, None) for agent, start in down_since.items()]
    return sorted(outages, key=lambda outage: (outage.start, outage.agent))


def _span(result: JournalResult) -> float:
    """Seconds from the first to the last record of any channel (what the timeline shows)."""
    times = [record.log_time for record in result.records]
    return (max(times) - min(times)) / 1e9 if times else 0.0
