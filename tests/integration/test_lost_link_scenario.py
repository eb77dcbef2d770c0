"""A rover whose synchronized task ends out of coverage, on the real simulated team.

With its library default (``return_to_link`` after 60 s idle without a link, wall seconds on
the robot's steady clock whatever the sim's speed) it drives
back to where it last had a link, the ground hears it again, and it holds; work the operator
sent while it was out of contact reaches it then. With ``continue`` (the old default) it
stays out. The team is this module's own: the second test leaves the
rover out of reach for good.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Iterator
from typing import Any

import pytest
import rospy

from rosmc_server.core import LostLinkKind, LostLinkPolicy, SkillStatus
from rosmc_server.core.model.control import HoldCause
from rosmc_server.ros.client import ControlCommand
from tests.conftest import wait_until
from tests.integration.scenario_fixtures import Operator, Team, TeamSettings

pytestmark = pytest.mark.integration

# The robot hears the ground (commands, report acks) about once a wall second, whatever the
# sim's speed: at 10x that is a position every 10 sim s, fine enough for "where it last had
# a link" to lie on its way out (at 50x the drive out fell between two contacts).
RTF = 10.0
ARM = "manipulator_rover"
COVERAGE = 12.0  # the test scenario's lander reach (m)
OUT = (17.0, 0.0)


def out_of_coverage_plan(op: Operator) -> str:
    """Send the rover 17 m out (5 m beyond the lander's reach); the skill's id."""
    far = op.client.add_skill(ARM, "navigate_to", {"target": {"x": OUT[0], "y": OUT[1]}})
    op.sync_and_start([ARM])
    return far.skill_id


def reached_out(telemetry: Any) -> bool:
    """The rover stands at the far spot, out of coverage."""
    return math.dist((telemetry.pose.x, telemetry.pose.y), OUT) < 0.3 and not telemetry.in_coverage


@pytest.fixture(scope="module")
def op(ros_master: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Operator]:
    """The operator of this module's team, its links up."""
    if not rospy.core.is_initialized():
        rospy.init_node("lost_link_tests", anonymous=True, disable_signals=True)
    settings = TeamSettings(real_time_factor=RTF)
    team = Team(dict(ros_master.env), tmp_path_factory.mktemp("team"), settings)
    operator: Operator | None = None
    try:
        team.start()
        operator = Operator()
        operator.wait_links_up(timeout=60.0)
        team.wait_emulator()
        yield operator
        assert not team.dead(), f"{team.dead()} died:\n{team.log_tails()}"
    finally:
        if operator is not None:
            operator.close()
        team.close()
        print(team.log_tails())


def test_by_default_a_rover_left_out_of_coverage_returns_to_its_link_and_holds(
    op: Operator,
) -> None:
    # The server gives each robot its library default when it first links.
    state = wait_until(
        lambda: (s := op.agent_state(ARM)) and "(library default)" in s.policy and s,
        30.0,
        "the robot reports its library default policy",
    )
    assert state.policy.startswith("on link loss: return to the last link position"), state
    far = out_of_coverage_plan(op)
    op.wait_link(ARM, "down", timeout=30.0)
    op.wait_robot(ARM, reached_out, "it reaches the far spot", timeout=60.0)

    # 60 wall seconds idle without a link later it drives back, and the ground hears it.
    op.wait_link(ARM, "up", timeout=120.0)
    op.wait_status([far], SkillStatus.SUCCESS, timeout=30.0)
    held = wait_until(
        lambda: (s := op.agent_state(ARM)) and "(done); holding" in s.policy and s,
        30.0,
        "the robot holds after its return",
    )
    assert held.executor_state == "paused", held
    assert held.hold is HoldCause.RETURN_POINT, held  # said as a field, not only in words
    where = re.search(r"returning to the last link position \((\S+), (\S+)\)", held.policy)
    assert where, held.policy
    goal = (float(where[1]), float(where[2]))
    assert math.hypot(*goal) < COVERAGE and goal[0] > 0.0, "where it had a link, not home"
    op.wait_robot(
        ARM,
        lambda t: t.in_coverage and math.dist((t.pose.x, t.pose.y), goal) < 0.3,
        "it stands at its last link position, in coverage",
    )
    assert op.agent_state(ARM).link == "up"  # type: ignore[union-attr]


def test_work_sent_while_out_of_contact_reaches_the_rover_when_its_default_brings_it_back(
    op: Operator,
) -> None:
    """The operator adapts the plan of a rover that is out of contact; nothing is refused."""
    c = op.client
    # From where the previous test left it, holding: out, then on slowly (80 sim seconds),
    # so the operator's changes below all happen while the rover is out of contact.
    c.add_skill(ARM, "navigate_to", {"target": {"x": OUT[0], "y": OUT[1]}})
    slow = {"target": {"x": OUT[0] + 4.0, "y": OUT[1]}, "speed": 0.05}
    far = c.add_skill(ARM, "navigate_to", slow).skill_id
    op.sync_and_start([ARM])
    op.wait_link(ARM, "down", timeout=30.0)
    home = c.add_skill(ARM, "navigate_to", {"target": {"x": 4.0, "y": 1.0}}).skill_id
    extra = c.add_skill(ARM, "navigate_to", {"target": {"x": 3.0, "y": -1.0}}).skill_id
    sent = c.synchronize(ARM)
    assert set(sent.skill_ids) == {home, extra}
    assert sent.note.startswith(f"queued for {ARM}: out of contact"), sent.note
    c.unsynchronize(ARM, extra)  # take one back while it waits
    c.set_lost_link_policy(ARM, LostLinkPolicy(LostLinkKind.HOLD, after=600.0))
    c.set_lost_link_policy(ARM, LostLinkPolicy())  # a second change replaces the first
    waiting = wait_until(  # one upload and one policy, shown with their age
        lambda: (s := op.agent_state(ARM)) is not None and s.commands_waiting == 2 and s,
        30.0,
        "two commands shown waiting",
    )
    assert waiting.link == "down" and "waiting for contact" in waiting.waiting_text

    # Its plan done, idle a minute without a link, the rover's library default drives it back
    # into coverage; what waited reaches it there, once and in order.
    op.wait_status([far], SkillStatus.SUCCESS, timeout=90.0)
    op.wait_link(ARM, "up", timeout=120.0)
    state = op.wait_stored(ARM)
    assert state.skill(home).status is SkillStatus.IDLE_SYNCHRONIZED
    assert state.skill(extra).is_editable, "the taken-back skill never went"
    wait_until(
        lambda: (s := op.agent_state(ARM)) and s.policy.startswith("on link loss: continue"),
        30.0,
        "the last policy in force",
    )
    assert op.agent_state(ARM).commands_waiting == 0  # type: ignore[union-attr]

    # The operator resumes the held rover: the skill that waited runs, the mission completes.
    c.control(ControlCommand.START, ARM)
    op.wait_status([home], SkillStatus.SUCCESS, timeout=60.0)
    c.delete_skills([extra])


def test_with_policy_continue_the_rover_stays_out(op: Operator) -> None:
    op.client.set_lost_link_policy(ARM, LostLinkPolicy())
    wait_until(
        lambda: (s := op.agent_state(ARM)) and s.policy == "on link loss: continue",
        30.0,
        "the robot takes the continue policy",
    )
    out_of_coverage_plan(op)
    op.wait_link(ARM, "down", timeout=30.0)
    op.wait_robot(ARM, reached_out, "it reaches the far spot", timeout=60.0)
    # Nothing happens: longer than the default's minute of idleness, in wall seconds (the
    # robot's link clock), ten times that in sim time.
    later = time.monotonic() + 75.0
    op.wait_robot(ARM, lambda t: time.monotonic() > later, "75 wall seconds", timeout=120.0)
    assert reached_out(op.where(ARM)), "the rover stayed where its plan ended"
    assert op.agent_state(ARM).link == "down"  # type: ignore[union-attr]
