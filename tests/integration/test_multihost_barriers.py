"""Skill barriers under radio cuts across real hosts: no member starts alone.

The ground (master, server, operator) and three robots each run in a network namespace of
their own, every robot's executor talking to the server and to its partners over its
"radio" (a veth pair into a bridge on the ground), with the kernel's default TCP settings:
no ``tcp_rto_max_ms`` cap. The two cuts of docs/barriers.md that let a member start alone
before (a partner's radio cut just before it arrives; every radio cut as the last member
arrives) must leave every member waiting until the radios return, then start them all
within a round of the robots' own announcements, whatever TCP's backoff has grown to.

Needs root and network namespaces; skips, saying why, where they are refused.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.integration.barrier_cuts import (
    CutOutcome,
    every_radio_cut_during_release,
    partner_cut_before_arrival,
)
from tests.integration.multihost_fixtures import LabSystem, lab_base_env
from tests.integration.netns import RadioLab, sweep, unavailable

pytestmark = [pytest.mark.integration, pytest.mark.slow]

ROBOTS = ("r1", "r2", "r3")
PAIR_CUT = 20.0  # seconds r2's radio is down (the issue's two-robot case)
ALL_CUT = 15.0  # seconds every radio is down
# After the radios return, the members hear each other's next announcement (every 0.5 s,
# over the robots' UDP side channel) and start together: the issue's bound is 2 s.
TOGETHER = 2.0


@pytest.fixture
def team(tmp_path: Path) -> Iterator[LabSystem]:
    """Master and server on the ground; r1..r3 on hosts of their own, default TCP settings."""
    reason = unavailable()
    if reason:
        pytest.skip(reason)
    sweep()
    with RadioLab(ROBOTS, subnet=(os.getpid() + 7) % 250) as lab:
        system = LabSystem(lab_base_env(tmp_path / "home"), tmp_path, lab=lab)
        try:
            system.start_master()
            system.start_server("_link_timeout:=2.0")
            for agent in ROBOTS:
                system.start_executor(agent)
            yield system
        finally:
            system.close()
            print(system.log_tails())


def check(outcome: CutOutcome, what: str) -> None:
    print(
        f"{what}: first start {outcome.first_after_restore:+.3f} s after the restore, "
        f"last {outcome.last_after_restore:+.3f} s, skew {outcome.skew:.3f} s"
    )
    assert outcome.first_after_restore > 0, f"{what}: a member started during the cut"
    assert outcome.skew <= TOGETHER, f"{what}: members started apart: {outcome.starts}"


@pytest.mark.timeout(240)
def test_no_barrier_member_starts_alone_through_radio_cuts(team: LabSystem) -> None:
    lab, op = team.radio, team.operator()
    op("wait_links", list(ROBOTS), 60.0, timeout=70.0)
    op("start")

    # r1 waits; r2's radio goes down 0.7 s before r2 arrives (it heard r1, r1 cannot hear
    # it). While the radio is down, the ground sees what r1 waits for.
    pair = partner_cut_before_arrival(op, lab, "r1", "r2", outage=PAIR_CUT)
    check(pair, "pair barrier, partner cut before arrival")

    everyone = every_radio_cut_during_release(op, lab, ROBOTS, outage=ALL_CUT)
    check(everyone, "barrier of three, every radio cut during the release")


@pytest.mark.timeout(120)
def test_the_ground_sees_whom_a_member_waits_for_during_a_cut(team: LabSystem) -> None:
    lab, op = team.radio, team.operator()
    op("wait_links", ["r1", "r2"], 60.0, timeout=70.0)
    op("start")
    lab.cut(["r2"])
    member = op("add", "r1", "wait", {"duration": 0.1})
    partner = op("add", "r2", "wait", {"duration": 0.1})
    barrier = op("add_barrier", [member, partner])
    op("sync", "r1")
    op("wait_status", [member], "SYNCWAITING", 30.0)
    deadline = time.time() + 30.0
    waiting = ""
    while time.time() < deadline and barrier not in waiting:
        waiting = op("waiting_on", "r1")
        time.sleep(0.2)
    assert waiting.startswith(f"r2 at {barrier}"), waiting
    lab.restore(["r2"])
