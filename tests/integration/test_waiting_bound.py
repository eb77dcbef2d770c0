"""At the bound of waiting work, what keeps a robot safe still goes (real server, emulated cut).

r1 sits behind the link emulator, its radio cut. Fifty uploads wait for it: a fifty-first is
refused in one sentence, but a pause, a lost-link policy change and a resume are accepted
(they collapse with what waits: the latest wins) and, once the robot is heard, the uploads
and the last policy arrive in order. A skill sent, taken back and sent again during the cut
runs without a word of a cancelled upload.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
import rosmc.msg as wire
import rosmc.srv as srv
from rosmc.msg import ErrorCode

from rosmc_server.core import LostLinkKind, LostLinkPolicy, Transfer
from rosmc_server.core import SkillStatus as S
from rosmc_server.core.robots.waiting import MAX_WAITING
from rosmc_server.ros.client import MissionClient
from rosmc_server.text import format_tasks
from tests.conftest import wait_until
from tests.integration.executor_fixtures import (
    Operator,
    OperatorError,
    RosmcSystem,
    describe,
    policy_words,
)


@pytest.fixture
def cut_robot(ros_master, tmp_path: Path) -> Iterator[tuple[RosmcSystem, Operator]]:
    """Server, emulator and r1's executor behind it, r1's link DOWN."""
    system = RosmcSystem(ros_master.env, tmp_path / "system")
    operator = Operator()
    try:
        system.start_server("_link_timeout:=1.0")
        system.start_emulator(["r1"])
        system.start_executor("r1", True)
        operator.wait_links(["r1"])
        operator.blackout("r1", True)
        wait_until(
            lambda: operator.agent_state("r1").link.state == wire.LinkState.DOWN,
            30.0,
            "r1's link DOWN",
        )
        yield system, operator
    finally:
        operator.close()
        system.close()
        print(system.log_tails())


def test_at_the_bound_pause_policy_and_resume_are_accepted_and_uploads_are_not(
    cut_robot: tuple[RosmcSystem, Operator],
) -> None:
    _, op = cut_robot
    skills = [op.add("r1", "wait", {"duration": 0.01}) for _ in range(MAX_WAITING + 1)]
    for skill_id in skills[:MAX_WAITING]:
        op.change("synchronize", agent="r1", upto_id=skill_id)  # one upload each
    with pytest.raises(OperatorError) as refused:
        op.change("synchronize", agent="r1", upto_id=skills[-1])
    assert refused.value.code == ErrorCode.UNAVAILABLE
    assert f"already has {MAX_WAITING} uploads and take-backs waiting" in str(refused.value)
    assert op.mission().skill(skills[-1]).transfer is Transfer.NONE, "nothing half-applied"

    op.control("r1", srv.ControlRequest.PAUSE)
    with MissionClient(timeout=60.0) as client:
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=30.0))
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=45.0))
    op.control("r1", srv.ControlRequest.RESUME)  # cancels the waiting pause
    op.control("r1", srv.ControlRequest.STOP)
    link = op.agent_state("r1").link
    assert link.commands_waiting == MAX_WAITING + 2, "the uploads, the last policy, the stop"

    op.blackout("r1", False)
    op.wait_status(skills[:MAX_WAITING], S.IDLE_SYNCHRONIZED, timeout=90.0)
    op.wait_mission(
        lambda m: "hold after 45 s" in policy_words(op.agent_state("r1").lost_link),
        60.0,
        "the last policy",
    )
    assert op.agent_state("r1").link.commands_waiting == 0


def test_a_skill_taken_back_and_sent_again_during_a_cut_runs_and_says_nothing_cancelled(
    cut_robot: tuple[RosmcSystem, Operator],
) -> None:
    _, op = cut_robot
    skill_id = op.add("r1", "wait", {"duration": 0.01})
    op.sync("r1")
    op.unsync("r1", skill_id)
    state = op.mission()
    assert state.skill(skill_id).status_text == "upload cancelled by the operator"
    op.sync("r1")
    state = op.mission()
    assert state.skill(skill_id).transfer is Transfer.UPLOADING
    assert "cancelled" not in format_tasks(state), format_tasks(state)
    op.blackout("r1", False)
    op.wait_status([skill_id], S.IDLE_SYNCHRONIZED, timeout=90.0)
    op.start("r1")
    state = op.wait_status([skill_id], S.SUCCESS, timeout=60.0)
    skill = state.skill(skill_id)
    assert skill.transfer is Transfer.NONE and "cancelled" not in skill.status_text, describe(state)
