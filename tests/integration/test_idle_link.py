"""What an idle robot says over its link: its digest, seldom; a change goes as reports.

A real rosmaster, mission server and executor; the test listens on the link's topics
beside the server. Bytes per second are a figure (``bench/bench_idle_link.py``); this
checks what makes them small.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest
import rosmc.msg as wire

from rosmc_server.core import SkillStatus
from tests.conftest import wait_until
from tests.integration.executor_fixtures import LinkEnd, Operator, RosmcSystem, policy_words

pytestmark = pytest.mark.integration

IDLE_SNAPSHOTS = 4  # looked at once the robot is idle
SNAPSHOT_PERIOD = 1.0  # the executor's default while its snapshot changes


def unstamped(msg: wire.ExecutorSnapshot) -> tuple[object, ...]:
    """What a snapshot says, but when it was sent and the round-trip echo."""
    return (
        msg.last_command_seq,
        msg.last_report_seq,
        msg.queue_hash,
        len(msg.queue),
        msg.state,
        msg.active_skill_id,
        msg.waiting_on,
        msg.queue_omitted,
        msg.status_digest,
    )


def test_an_idle_robot_repeats_its_digest_seldom_and_sends_a_change_as_reports(
    ros_master, tmp_path: Path
) -> None:
    system = RosmcSystem(ros_master.env, tmp_path / "system")
    operator: Operator | None = None
    try:
        system.start_server()
        system.start_executor("r1")
        op = operator = Operator()
        op.wait_links(["r1"])
        ground = LinkEnd("r1", "ground")  # hears what the robot sends the ground
        wait_until(ground.connected, 30.0, "the test's end of r1's link")
        ids = [op.add("r1", "wait", {"duration": 0.01}) for _ in range(5)]
        op.sync("r1")
        op.start("r1")
        op.wait_status(ids, SkillStatus.SUCCESS)

        # Idle: the same digest again and again, the queue and the policy left out.
        settled = len(ground.received("snapshot")) + 1  # the next may still show the end
        wait_until(
            lambda: len(ground.received("snapshot")) >= settled + IDLE_SNAPSHOTS,
            60.0,
            "snapshots of the idle robot",
        )
        idle = ground.received("snapshot")[settled : settled + IDLE_SNAPSHOTS]
        assert len({unstamped(m) for m in idle}) == 1, [unstamped(m) for m in idle]
        assert all(m.queue_omitted and not m.queue for m in idle)
        said = [m for m in idle if m.policy.kind != wire.LostLinkPolicy.UNSAID]
        assert len(said) <= 1, "the policy repeats only now and then"
        gaps = [b.stamp.to_sec() - a.stamp.to_sec() for a, b in itertools.pairwise(idle)]
        assert min(gaps) > 1.2 * SNAPSHOT_PERIOD, gaps  # a slow machine only lengthens them
        state = op.agent_state("r1")
        assert state.link.state == wire.LinkState.UP
        assert policy_words(state.lost_link).startswith("on link loss"), state  # the ground kept it

        # A change: the ground hears it as reports, and never needs the whole queue.
        heard = len(ground.received("snapshot"))
        added = op.add("r1", "wait", {"duration": 0.01})
        op.sync("r1")
        op.wait_status([added], SkillStatus.SUCCESS)
        reports = [r for r in ground.received("report") if r.skill_id == added]
        assert [r.status.value for r in reports][-1] == SkillStatus.SUCCESS
        wait_until(
            lambda: ground.received("snapshot")[-1].status_digest != idle[0].status_digest,
            30.0,
            "a snapshot with the new digest",
        )
        after = ground.received("snapshot")[heard:]
        assert all(m.queue_omitted for m in after), "no snapshot had to carry the queue"
        wait_until(
            lambda: op.agent_state("r1").link.state == wire.LinkState.UP, 30.0, "r1's link up"
        )
    finally:
        if operator is not None:
            operator.close()
        system.close()
