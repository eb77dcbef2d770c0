"""The ground takes a robot's answers to commands in order, even when one is lost.

A real mission server; the test plays the robot's end of the link (:class:`LinkEnd`).
An answer is lost when the ground connects a robot's topics afresh (after a radio cut)
while the robot is answering: the ground then hears the answers to later commands before
the lost one, which the robot gives again when the command is retransmitted.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import rosmc.msg as wire

from rosmc_server.core import SkillStatus, Transfer
from rosmc_server.core.robots.link import queue_hash
from tests.conftest import RosMaster, wait_until
from tests.integration.executor_fixtures import LinkEnd, Operator, RosmcSystem

pytestmark = pytest.mark.integration

AGENT = "r3"
SETTLE = 30.0  # seconds the answers may take to settle on a busy machine


@pytest.fixture
def ground(ros_master: RosMaster, tmp_path: Path) -> Iterator[tuple[RosmcSystem, Operator]]:
    """The mission server (a long link timeout: the test's robot speaks seldom) and an operator."""
    system = RosmcSystem(ros_master.env, tmp_path / "system")
    system.start_server("_link_timeout:=600.0")
    operator = Operator()
    try:
        yield system, operator
    finally:
        operator.close()
        system.close()
        print(system.log_tails(40, ["server"]))


def answer(robot: LinkEnd, command: wire.RobotCommand, held: list[str]) -> None:
    """Accept an upload, as a robot now holding ``held`` answers it."""
    robot.publish(
        "ack",
        wire.RobotAck(
            agent=AGENT,
            seq=command.seq,
            result=wire.RobotAck.ACCEPTED,
            accepted_ids=[skill.id for skill in command.skills],
            queue_hash=queue_hash(held),
        ),
    )


def test_an_answer_heard_before_an_earlier_lost_one_waits_for_it(
    ground: tuple[RosmcSystem, Operator],
) -> None:
    _, op = ground
    robot = LinkEnd(AGENT, "robot")
    wait_until(robot.connected, 30.0, f"the server's link to {AGENT}")
    robot.publish("snapshot", wire.ExecutorSnapshot(agent=AGENT, queue_hash=queue_hash([])))
    wait_until(lambda: robot.received("report_ack"), 30.0, "the server to learn the numbering")
    skills = []
    for duration in (0.2, 0.3, 0.4):  # three uploads: commands 1, 2 and 3
        skills.append(op.add(AGENT, "wait", {"duration": duration}))
        op.sync(AGENT)
    uploads = [robot.wait_heard("command", lambda c, seq=seq: c.seq == seq) for seq in (1, 2, 3)]
    assert [[s.id for s in c.skills] for c in uploads] == [[s] for s in skills]
    # The robot executed all three; its answer to 1 is lost, those to 2 and 3 arrive.
    answer(robot, uploads[1], skills[:2])
    answer(robot, uploads[2], skills)
    time.sleep(0.5)  # (nothing to wait on: the ground must not take them yet)
    answer(robot, uploads[0], skills[:1])  # the robot's answer to a retransmission of 1
    # The robot answers every retransmission again, with the answer it gave first.
    deadline = time.monotonic() + SETTLE
    answered = len(robot.received("command"))

    def synchronized() -> bool:
        mission = op.mission()
        return all(
            mission.skill(s).status is SkillStatus.IDLE_SYNCHRONIZED
            and mission.skill(s).transfer is Transfer.NONE
            for s in skills
        )

    while not synchronized():
        assert time.monotonic() < deadline, (
            "uploads answered out of order stayed unconfirmed: "
            + ", ".join(f"{s} {op.mission().skill(s).transfer.name}" for s in skills)
        )
        heard = robot.received("command")
        for command in heard[answered:]:
            answer(robot, command, skills[: command.seq])
        answered = len(heard)
        time.sleep(0.1)
