"""Radio cuts across real hosts: no barrier member starts alone, no waiting work is lost.

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

import pytest
import rosmc.msg as wire

from rosmc_server import interface
from rosmc_server.core import SkillStatus
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.recording import read_journal
from tests.integration.barrier_cuts import (
    CutOutcome,
    every_radio_cut_during_release,
    partner_cut_before_arrival,
)
from tests.integration.executor_fixtures import journal_reports
from tests.integration.multihost_fixtures import LabSystem, lab_base_env
from tests.integration.netns import RadioLab, sweep, unavailable

pytestmark = [pytest.mark.integration, pytest.mark.slow]

ROBOTS = ("r1", "r2", "r3")
PAIR_CUT = 20.0  # seconds r2's radio is down (the two-robot case of docs/barriers.md)
ONE_RADIO_CUT = 30.0  # the same, longer: TCP's backoff has grown further
ALL_CUT = 15.0  # seconds every radio is down
# After the radios return, the members hear each other's next announcement (every 0.5 s,
# over the robots' UDP side channel) and start together: the issue's bound is 2 s.
TOGETHER = 2.0


@pytest.fixture(scope="module")
def team(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LabSystem]:
    """Master and server on the ground; r1..r3 on hosts of their own, default TCP settings.

    One lab for the module: each test plans skills of its own and leaves every radio up.
    """
    reason = unavailable()
    if reason:
        pytest.skip(reason)
    sweep()
    work = tmp_path_factory.mktemp("lab")
    with RadioLab(ROBOTS, subnet=(os.getpid() + 7) % 250) as lab:
        system = LabSystem(lab_base_env(work / "home"), work, lab=lab)
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
@pytest.mark.parametrize("outage", [PAIR_CUT, ONE_RADIO_CUT])
def test_a_partner_cut_off_before_it_arrives_does_not_start_alone(
    team: LabSystem, outage: float
) -> None:
    # r1 waits; r2's radio goes down 0.7 s before r2 arrives: it heard r1, r1 cannot hear it.
    lab, op = team.radio, team.operator()
    op("wait_links", list(ROBOTS), 60.0, timeout=70.0)
    op("start")
    pair = partner_cut_before_arrival(op, lab, "r1", "r2", outage=outage)
    check(pair, f"pair barrier, partner cut {outage:g} s before arrival")


@pytest.mark.timeout(240)
def test_no_member_starts_when_every_radio_is_cut_during_the_release(team: LabSystem) -> None:
    lab, op = team.radio, team.operator()
    op("wait_links", list(ROBOTS), 60.0, timeout=70.0)
    op("start")
    everyone = every_radio_cut_during_release(op, lab, ROBOTS, outage=ALL_CUT)
    check(everyone, "barrier of three, every radio cut during the release")


@pytest.mark.timeout(120)
def test_the_ground_sees_whom_a_member_waits_for_and_since_when_during_a_cut(
    team: LabSystem,
) -> None:
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
    # Since when, robot clock to robot clock (r1's host keeps its own): an age that grows.
    first = op("barrier_wait", "r1")
    assert first >= 0.0, first
    while time.time() < deadline and op("barrier_wait", "r1") <= first:
        time.sleep(0.2)
    assert op("barrier_wait", "r1") > first
    lab.restore(["r2"])


OUT_OF_CONTACT = 60.0  # seconds r3's radio is down while the operator sends it work


@pytest.mark.timeout(240)
def test_work_sent_to_a_robot_out_of_contact_arrives_once_in_order_after_the_cut(
    team: LabSystem,
) -> None:
    lab, op = team.radio, team.operator()
    op("wait_links", list(ROBOTS), 60.0, timeout=70.0)
    op("start")
    lab.cut(["r3"])
    cut = time.time()
    deadline = cut + 30.0
    while op("links", ["r3"])["r3"] != "DOWN":
        assert time.time() < deadline, "the ground never saw r3's link go down"
        time.sleep(0.2)
    sent = []
    for duration in (0.2, 0.3, 0.4):  # three sends, each answered at once, each waiting
        sent.append(op("add", "r3", "wait", {"duration": duration}))
        op.call("sync", "r3", timeout=30.0)
    # A send that waited on the robot could not end before its radio returns.
    assert time.time() < cut + OUT_OF_CONTACT, "the send waited on the robot"
    assert op("statuses")[sent[0]][0] == "IDLE"  # nothing reached the robot yet
    time.sleep(max(0.0, cut + OUT_OF_CONTACT - time.time()))
    restored = time.time()
    lab.restore(["r3"])
    try:
        op("wait_status", sent, "SUCCESS", 60.0, timeout=70.0)
    except AssertionError:
        print(team.log_tails(80, ["server", "r3"]))  # what the link did after the restore
        raise
    assert team.stop("server") == 0  # the module's last test: its journal is complete

    records = [
        r.message
        for r in read_journal(team.journal, [interface.ROBOT_COMMANDS_TOPIC]).records
        if r.message.agent == "r3" and set(r.message.skill_ids) & set(sent)
    ]
    uploads = [r for r in records if r.type == CommandKind.UPLOAD]
    delivered = [r for r in uploads if r.event == wire.CommandRecord.DELIVERED]
    assert [r.skill_ids for r in delivered] == [[skill] for skill in sent]  # once, in order
    assert all(r.held and r.delivered.to_sec() >= restored for r in delivered)
    reports = [r for r in journal_reports(team.journal) if r.skill_id in sent]
    started = dict.fromkeys(r.skill_id for r in reports if r.status.value == SkillStatus.RUNNING)
    finished = [r.skill_id for r in reports if r.status.value == SkillStatus.SUCCESS]
    assert list(started) == sent and finished == sent  # in order, each finished once
