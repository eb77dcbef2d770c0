"""The executor's snapshot pacing: changes go every period, an idle robot's seldom and short."""

from __future__ import annotations

import itertools
from dataclasses import replace

from rosmc_server.core import LostLinkKind, LostLinkPolicy, PolicyInForce
from rosmc_server.executor.core import Snapshot
from rosmc_server.executor.core.pacing import SnapshotPacer

POLICY = PolicyInForce(LostLinkPolicy(LostLinkKind.HOLD, 30.0), library_default=True)
IDLE = Snapshot(0.0, 4, 9, "abc", (), "idle", "", "", POLICY, False, "d1")


def run(pacer: SnapshotPacer, states: dict[float, Snapshot], until: float) -> list[Snapshot]:
    """What goes out when the loop asks as the pacer says, the robot in ``states``
    (from each time on) and the ground's report acks saying its timeout."""
    sent: list[Snapshot] = []
    now = 0.0
    while now <= until:
        state = states[max(t for t in states if t <= now)]
        out = pacer.due(replace(state, stamp=now), now)
        if out is not None:
            sent.append(out)
        now = round(pacer.next_check(now), 6)
    return sent


def test_an_idle_robot_sends_twice_within_the_ground_timeout_and_its_policy_seldom() -> None:
    pacer = SnapshotPacer(period=1.0, idle_period=5.0, policy_repeat=30.0, ground_timeout=3.0)
    sent = run(pacer, {0.0: replace(IDLE, full=True), 0.5: IDLE}, 70.0)
    stamps = [s.stamp for s in sent]
    assert stamps[:4] == [0.0, 1.0, 2.5, 4.0]  # the full one, then a digest every 1.5 s
    assert all(b - a == 1.5 for a, b in itertools.pairwise(stamps[1:]))
    said = [s.stamp for s in sent if s.policy is not None]
    assert said == [0.0, 31.0, 61.0]  # in the whole snapshot, then again after 30 s
    assert all(s.policy in (None, POLICY) for s in sent)


def test_changes_go_every_period_and_a_changed_policy_at_once() -> None:
    pacer = SnapshotPacer(period=1.0, idle_period=5.0, ground_timeout=20.0)
    running = replace(IDLE, state="running", active_skill_id="s1")
    held = replace(IDLE, policy=PolicyInForce(LostLinkPolicy(LostLinkKind.HOLD, 10.0)))
    states = {0.0: IDLE, 3.0: running, 4.0: replace(running, last_report_seq=10), 6.0: held}
    sent = run(pacer, states, 12.0)
    assert [s.stamp for s in sent] == [0.0, 3.0, 4.0, 6.0, 11.0]  # unchanged: every 5 s
    assert [s.state for s in sent] == ["idle", "running", "running", "idle", "idle"]
    assert sent[3].policy == held.policy and sent[4].policy is None


def test_before_the_ground_says_its_timeout_every_period_goes() -> None:
    pacer = SnapshotPacer(period=1.0, idle_period=5.0)
    assert [s.stamp for s in run(pacer, {0.0: IDLE}, 4.0)] == [0.0, 1.0, 2.0, 3.0, 4.0]
