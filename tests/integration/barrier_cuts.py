"""Radio cuts timed against a barrier, across real hosts: the scenarios of docs/barriers.md.

Shared by ``test_multihost_barriers.py`` (which asserts the outcome) and
``bench/bench_multihost.py`` (which reports the figures over repeated runs). Each scenario
plans fresh skills on a started team, times the cut from the member's own RUNNING stamp of
the skill before its barrier skill (all hosts share one kernel clock), and returns when
every member has finished.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

from tests.integration.netns import RadioLab
from tests.integration.remote_operator import RemoteOperator

AHEAD = 0.3  # seconds the early members run before their barrier skill
LATE = 4.0  # seconds the last member runs before its barrier skill


@dataclass(frozen=True)
class CutOutcome:
    """When the radios went down and came back, and when each member started."""

    cut: float
    restored: float
    starts: dict[str, float]  # agent -> its barrier skill's RUNNING stamp

    @property
    def skew(self) -> float:
        """Seconds between the first and the last member starting."""
        return max(self.starts.values()) - min(self.starts.values())

    @property
    def first_after_restore(self) -> float:
        """Seconds from the radios' return to the first start (negative: during the cut)."""
        return min(self.starts.values()) - self.restored

    @property
    def last_after_restore(self) -> float:
        """Seconds from the radios' return to the last start."""
        return max(self.starts.values()) - self.restored


def partner_cut_before_arrival(
    op: RemoteOperator, lab: RadioLab, waiting: str, late: str, outage: float, lead: float = 0.7
) -> CutOutcome:
    """``waiting`` waits at a pair barrier; ``late``'s radio goes down ``lead`` s before it arrives.

    ``late`` has heard ``waiting`` arrive; ``waiting`` cannot hear ``late`` arrive.
    """
    return _barrier_under_cut(op, lab, [waiting, late], [late], outage, lead)


def every_radio_cut_during_release(
    op: RemoteOperator, lab: RadioLab, agents: Sequence[str], outage: float, lead: float = 0.05
) -> CutOutcome:
    """Every member but the last waits; all radios go down as the last one arrives."""
    return _barrier_under_cut(op, lab, list(agents), list(agents), outage, lead)


def _barrier_under_cut(
    op: RemoteOperator,
    lab: RadioLab,
    agents: list[str],
    cut: list[str],
    outage: float,
    lead: float,
) -> CutOutcome:
    last = agents[-1]
    ahead = {a: op("add", a, "wait", {"duration": LATE if a == last else AHEAD}) for a in agents}
    members = {a: op("add", a, "wait", {"duration": 0.2}) for a in agents}
    op("add_barrier", list(members.values()))
    for agent in agents:
        op("sync", agent)
    arrival = op("wait_started", [ahead[last]], 30.0)[ahead[last]] + LATE
    time.sleep(max(0.0, arrival - lead - time.time()))
    return _cut_until_done(op, lab, cut, outage, members)


def cut_while_members_approach(
    op: RemoteOperator, lab: RadioLab, agents: Sequence[str], outage: float
) -> CutOutcome:
    """Every radio goes down while all members run towards the barrier."""
    ahead = [op("add", agent, "wait", {"duration": 1.5}) for agent in agents]
    members = {agent: op("add", agent, "wait", {"duration": 0.05}) for agent in agents}
    op("add_barrier", list(members.values()))
    for agent in agents:
        op("sync", agent)
    op("wait_started", ahead, 30.0)  # a stamp, kept: not a look at a passing RUNNING
    return _cut_until_done(op, lab, list(agents), outage, members)


def _cut_until_done(
    op: RemoteOperator, lab: RadioLab, cut: list[str], outage: float, members: dict[str, str]
) -> CutOutcome:
    """Cut the radios of ``cut`` for ``outage`` s, then wait for every member to finish."""
    lab.cut(cut)
    down = time.time()
    time.sleep(outage)
    restored = time.time()
    lab.restore(cut)
    op("wait_status", list(members.values()), "SUCCESS", 60.0, timeout=70.0)
    started = op("started")
    return CutOutcome(down, restored, {a: started[m] for a, m in members.items()})
