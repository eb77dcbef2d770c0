"""Every robot's skill executions over a recording, from the journaled status changes.

Which status each skill went through, and in which order, comes from the mission
events. *When* it did comes from the robot where the journal tells: the robot's
report (journaled just before the event it caused) or the skill's ``started`` and
``finished`` stamps. A robot out of radio range reports late; placing its work
where the ground heard of it would show barrier partners released minutes apart
and skills that took no time. Robot stamps are on the mission clock (sim time in
simulation); they become recording seconds through the (event stamp, log time)
pairs of the journal, and are never placed after the ground heard of them nor
before the robot's previous change. Without a robot stamp, the event's log time
counts.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from rosmc_server.core import MissionEvent, MissionState, SkillInstance, SkillStatus


@dataclass(frozen=True)
class Interval:
    """One stretch of a skill in one status on a robot.

    Attributes:
        agent: The robot.
        skill_id: The skill instance.
        skill: The skill's name in the library (``navigate_to``).
        label: What operators call it (its label, else its skill name).
        status: RUNNING, SYNCWAITING (waiting at ``barrier``) or PAUSED.
        start: Seconds since the recording started.
        end: Seconds since the recording started.
        outcome: The status that ended it (SUCCESS, FAILURE, IDLE_SYNCHRONIZED for a stop,
            RUNNING after a wait or pause...), or None if the recording (or the mission,
            replaced) ended first.
        attempt: The robot's attempt number.
        barrier: The barrier of the skill ("" if none).
    """

    agent: str
    skill_id: str
    skill: str
    label: str
    status: SkillStatus
    start: float
    end: float
    outcome: SkillStatus | None
    attempt: int = 1
    barrier: str = ""


@dataclass(frozen=True)
class BarrierRelease:
    """The moment the skills of a barrier started together.

    Attributes:
        barrier: The barrier id.
        time: Seconds since the recording started: the first member's start.
        members: ``(agent, skill_id)`` of every member.
    """

    barrier: str
    time: float
    members: tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class OperatorMark:
    """An operator's change on the time axis.

    Attributes:
        time: Seconds since the recording started.
        kind: "sync", "unsync" or "edit" (any other change the operator made).
        summary: The event's one-sentence summary.
    """

    time: float
    kind: str
    summary: str


@dataclass(frozen=True)
class Timeline:
    """Every robot's lane of intervals and the barrier releases between them.

    Attributes:
        lanes: Agent name to its intervals in time order, for every agent of the mission.
        releases: Barrier releases in time order.
        duration: Seconds from the recording's first to its last record.
        marks: The operator's changes in time order (see recording.overlays).
        outages: ``(agent, start, end)`` seconds while a robot's link was down.
        score: ``(seconds, score)`` as the simulator recorded it; empty without one.
    """

    lanes: dict[str, tuple[Interval, ...]]
    releases: tuple[BarrierRelease, ...]
    duration: float
    marks: tuple[OperatorMark, ...] = ()
    outages: tuple[tuple[str, float, float], ...] = ()
    score: tuple[tuple[float, float], ...] = ()

    @property
    def intervals(self) -> list[Interval]:
        """Every interval of every lane."""
        return [interval for lane in self.lanes.values() for interval in lane]


@dataclass(frozen=True)
class _Transition:
    agent: str
    skill: SkillInstance
    heard: float  # when the ground journaled it (recording seconds)
    robot_stamp: float | None  # when the robot did it (mission clock), if known
    barrier: str


class TimelineBuilder:
    """Collects status transitions while a history replays; :meth:`build` makes the timeline.

    Args:
        start: Log time (ns) of the recording's first record.
    """

    def __init__(self, start: int) -> None:
        self._start = start
        self._agents: dict[str, None] = {}
        self._reports: dict[str, tuple[int, int, float]] = {}
        self._clock: list[tuple[float, float]] = []  # (server's event stamp, recording second)
        self._robot_clock: list[tuple[float, float]] = []  # (robot's report stamp, second)
        self._steps: list[_Transition | float] = []  # a float: everything ends (replacement)
        self._barriers: dict[str, tuple[tuple[str, str], ...]] = {}

    def report(self, msg: Any, log_time: int | None = None) -> None:
        """A journaled ``rosmc/RobotReport``: the robot's own stamp of its next change."""
        stamp = msg.stamp.to_sec()
        self._reports[msg.skill_id] = (msg.status.value, msg.attempt, stamp)
        if log_time is not None and stamp > 0:
            self._robot_clock.append((stamp, self._seconds(log_time)))

    def reset(self, state: MissionState, log_time: int) -> None:
        """The history (re)started from a snapshot: skills active in it start now."""
        heard = self._seconds(log_time)
        self._steps.append(heard)
        self._agents.update(dict.fromkeys(state.agents))
        for skill in state.skills():
            if skill.status.is_active:
                self._steps.append(_Transition(skill.agent, skill, heard, None, ""))

    def event(self, before: MissionState, event: MissionEvent, log_time: int) -> None:
        """An event about to be applied to ``before``."""
        heard = self._seconds(log_time)
        if event.stamp > 0:
            self._clock.append((event.stamp, heard))
        for placed in event.change.put_skills:
            new = placed.skill
            self._agents.setdefault(new.agent)
            old = before.skill(new.id) if before.has_skill(new.id) else None
            report = self._reports.pop(new.id, None)
            if old is not None and (old.status, old.attempt) == (new.status, new.attempt):
                continue
            stamp = None
            if report is not None and report[0] == new.status and report[1] in (0, new.attempt):
                stamp = report[2]
            elif new.status.is_final and new.finished > 0:
                stamp = new.finished
            elif new.status.has_started and new.started > 0 and not _started(old):
                stamp = new.started
            barrier = before.barrier_of(new.id)
            if barrier is not None and barrier.id not in self._barriers:
                self._barriers[barrier.id] = tuple(
                    (before.locate(member)[0], member)
                    for member in barrier.skill_ids
                    if before.has_skill(member)
                )
            self._steps.append(
                _Transition(new.agent, new, heard, stamp, barrier.id if barrier else "")
            )

    def build(self, duration: float) -> Timeline:
        """The timeline of everything collected, ending at ``duration`` seconds."""
        to_seconds = _clock_map(self._robot_time_pairs())
        lanes: dict[str, list[Interval]] = {agent: [] for agent in self._agents}
        open_: dict[str, Interval] = {}
        latest: dict[str, float] = {}
        released: dict[str, float] = {}

        def close(skill_id: str, end: float, outcome: SkillStatus | None) -> None:
            interval = open_.pop(skill_id)
            lanes[interval.agent].append(replace(interval, end=end, outcome=outcome))

        for step in self._steps:
            if isinstance(step, float):
                for skill_id in list(open_):
                    close(skill_id, step, None)
                continue
            when = step.heard
            if step.robot_stamp is not None and to_seconds is not None:
                lowest = latest.get(step.agent, 0.0)
                when = min(max(to_seconds(step.robot_stamp), lowest), step.heard)
            latest[step.agent] = when
            skill = step.skill
            previous = open_.get(skill.id)
            if previous is not None:
                retried = previous.attempt != skill.attempt
                close(skill.id, when, SkillStatus.FAILURE if retried else skill.status)
            if skill.status.is_active:
                open_[skill.id] = Interval(
                    agent=skill.agent,
                    skill_id=skill.id,
                    skill=skill.skill,
                    label=skill.label or skill.skill,
                    status=skill.status,
                    start=when,
                    end=when,
                    outcome=None,
                    attempt=skill.attempt,
                    barrier=step.barrier,
                )
            if skill.status is SkillStatus.RUNNING and step.barrier:
                released[step.barrier] = min(released.get(step.barrier, when), when)
        for skill_id in list(open_):
            close(skill_id, max(duration, open_[skill_id].start), None)
        releases = sorted(
            (BarrierRelease(b, when, self._barriers[b]) for b, when in released.items()),
            key=lambda release: release.time,
        )
        return Timeline(
            {agent: tuple(sorted(lane, key=lambda i: i.start)) for agent, lane in lanes.items()},
            tuple(releases),
            duration,
        )

    def _seconds(self, log_time: int) -> float:
        return (log_time - self._start) / 1e9

    def _robot_time_pairs(self) -> list[tuple[float, float]]:
        """Pairs that map robot stamps to recording seconds.

        Normally the server stamps its events on the robots' clock (both sim time, or both
        wall time), and its events give the map. A server started before ``/use_sim_time``
        was set stamps in wall time while the robots report sim time: the two clocks are
        then far apart, and the robots' own reports (their stamp, when they were journaled)
        give the map instead, so such a recording still draws right.
        """
        if not self._robot_clock or not self._clock:
            return self._clock or sorted(self._robot_clock)
        robot = sorted(stamp for stamp, _ in self._robot_clock)[len(self._robot_clock) // 2]
        server = sorted(stamp for stamp, _ in self._clock)[len(self._clock) // 2]
        if abs(robot - server) > CLOCKS_APART:
            return sorted(self._robot_clock)
        return self._clock


CLOCKS_APART = 86_400.0
"""Seconds between the medians of server and robot stamps that mean two different clocks."""


def _started(skill: SkillInstance | None) -> bool:
    return skill is not None and skill.status.has_started


def _clock_map(pairs: list[tuple[float, float]]) -> Callable[[float], float] | None:
    """A function from mission-clock stamps to recording seconds; None without pairs.

    Pairs that would make the map go backwards are left out; outside the recorded
    stamps the map continues with the recording's average rate.
    """
    stamps: list[float] = []
    seconds: list[float] = []
    for stamp, second in pairs:
        if not stamps or (stamp >= stamps[-1] and second >= seconds[-1]):
            stamps.append(stamp)
            seconds.append(second)
    if not stamps:
        return None
    span = stamps[-1] - stamps[0]
    rate = (seconds[-1] - seconds[0]) / span if span > 0 else 1.0

    def to_seconds(stamp: float) -> float:
        index = bisect.bisect_right(stamps, stamp)
        if index == 0:
            return seconds[0] + (stamp - stamps[0]) * rate
        if index == len(stamps):
            return seconds[-1] + (stamp - stamps[-1]) * rate
        low, high = stamps[index - 1], stamps[index]
        fraction = (stamp - low) / (high - low) if high > low else 0.0
        return seconds[index - 1] + fraction * (seconds[index] - seconds[index - 1])

    return to_seconds
