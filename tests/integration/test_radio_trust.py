"""Only the team speaks on the radio: forged datagrams and a hijack change nothing.

Real rosmaster, real mission server, real executors, real UDP: an attacker on the same
network reads the radio directory from the parameter server and sends what the issue's
attacks sent, then some. The barrier member under attack must not start before its
partner arrives, no executor may send its signals elsewhere for good, and every dropped
datagram shows in the robot's status (``rosmc status`` and both GUIs read it there).
"""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator
from io import BytesIO
from pathlib import Path

import pytest
import rosmc.msg as wire
import rospy

from rosmc_server import interface
from rosmc_server.conversions import agent_status_from_msg, time_to_msg
from rosmc_server.core import SkillStatus as S
from rosmc_server.core.robots.radio import DatagramKind, parse_endpoint
from rosmc_server.core.robots.radio_auth import SIGNATURE_BYTES, Sealer
from rosmc_server.core.robots.radio_key import RadioKey
from rosmc_server.text import format_agent_status
from tests.conftest import wait_until
from tests.integration.executor_fixtures import (
    Operator,
    RosmcSystem,
    assert_released_together,
    describe,
    send_datagrams,
    signal_datagram,
    team_key,
)


@pytest.fixture
def team(ros_master, tmp_path: Path) -> Iterator[tuple[RosmcSystem, Operator]]:
    """Server and the executors of r1 and r2, linked."""
    system = RosmcSystem(ros_master.env, tmp_path / "system")
    operator = Operator()
    try:
        system.start_server()
        for agent in ("r1", "r2"):
            system.start_executor(agent)
        operator.wait_links(("r1", "r2"))
        yield system, operator
    finally:
        operator.close()
        system.close()
        print(system.log_tails())


def signal(agent: str, barrier: str, skill: str, kind: int) -> wire.BarrierSignal:
    """A barrier signal stamped now."""
    return wire.BarrierSignal(
        agent=agent, barrier_id=barrier, skill_id=skill, kind=kind, stamp=time_to_msg(time.time())
    )


def unsigned(msg: wire.BarrierSignal) -> bytes:
    """The issue's forgery: the old, unsigned framing anyone could write."""
    buffer = BytesIO()
    msg.serialize(buffer)
    return b"RMC\x01\x02" + buffer.getvalue()


def dropped(op: Operator, agent: str) -> int:
    """Radio datagrams the server says were dropped on ``agent``'s link."""
    return int(op.agent_state(agent).link.radio_dropped)


def test_forged_datagrams_do_not_start_a_barrier_member_and_are_counted(
    team: tuple[RosmcSystem, Operator],
) -> None:
    system, op = team
    early = op.add("r1", "wait", {"duration": 0.1})
    busy = op.add("r2", "wait", {"duration": 1.0})
    late = op.add("r2", "wait", {"duration": 0.1})
    barrier = op.add_barrier([early, late])
    op.sync("r1")
    op.sync("r2")
    op.wait_mission(
        lambda m: all(m.skill(i).status is S.IDLE_SYNCHRONIZED for i in (early, busy, late)),
        60.0,
        "every skill on its robot",
    )
    # r1 alone starts: it waits at the barrier for as long as r2 is not started (a state
    # held, not one a poll on a busy machine could miss).
    op.start("r1")
    op.wait_status([early], S.SYNCWAITING)
    before = dropped(op, "r1")

    released = signal("r2", barrier, late, wire.BarrierSignal.RELEASED)
    genuine = signal_datagram(released)  # what r2 would send, with the team's key
    tampered = bytearray(genuine)
    tampered[-SIGNATURE_BYTES - 1] ^= 0x01  # the signal altered, its signature kept
    wrong_key = Sealer(RadioKey(bytes(32), Path("stolen.key")), "r2")
    forged = [
        unsigned(released),  # the attack, word for word
        signal_datagram(released, wrong_key),  # another deployment's (or a guessed) key
        genuine[:-3],  # truncated
        bytes(tampered),
        b"garbage",
    ]
    send_datagrams("r1", *forged)
    # The counter moves only once r1 has handled them all: then nothing may have started.
    wait_until(
        lambda: dropped(op, "r1") >= before + len(forged), 60.0, "r1 to count the forged datagrams"
    )
    state = op.mission()
    assert state.skill(early).status is S.SYNCWAITING, describe(state)
    assert state.skill(busy).status is S.IDLE_SYNCHRONIZED, describe(state)

    status_line = format_agent_status(agent_status_from_msg(op.agent_state("r1")))
    assert "forged radio datagrams dropped" in status_line, status_line

    # The barrier goes on as if nothing happened: both start together once r2 arrives.
    op.start("r2")
    op.wait_status([early, late], S.SUCCESS, timeout=60.0)
    system.stop("server")
    assert_released_together(system.journal, [early, late])


def test_a_hijack_of_the_directory_and_of_partners_addresses_changes_nothing(
    team: tuple[RosmcSystem, Operator],
) -> None:
    """The issue's deadlock: one socket claims to be r2 to r1 and r1 to r2, and the
    directory entries of both are overwritten with it."""
    system, op = team
    first = op.add("r1", "wait", {"duration": 3.0})
    member1 = op.add("r1", "wait", {"duration": 0.1})
    member2 = op.add("r2", "wait", {"duration": 0.1})
    barrier = op.add_barrier([member1, member2])
    op.sync("r1")
    op.sync("r2")
    op.wait_mission(
        lambda m: all(m.skill(i).status is S.IDLE_SYNCHRONIZED for i in (first, member1, member2)),
        60.0,
        "every skill on its robot",
    )
    before = dropped(op, "r1") + dropped(op, "r2")
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as attacker:
        attacker.bind(("127.0.0.1", 0))
        attacker.settimeout(0.2)
        trap = f"127.0.0.1:{attacker.getsockname()[1]}"
        stolen = Sealer(RadioKey(b"\x01" * 32, Path("stolen.key")), "r2")
        as_r1 = Sealer(RadioKey(b"\x01" * 32, Path("stolen.key")), "r1")
        for victim, claim, sealer in (("r1", "r2", stolen), ("r2", "r1", as_r1)):
            host, port = parse_endpoint(rospy.get_param(f"{interface.RADIO_DIRECTORY}/{victim}"))
            withdrawn = signal(claim, barrier, member1, wire.BarrierSignal.WITHDRAWN)
            attacker.sendto(signal_datagram(withdrawn, sealer), (host, port))
            attacker.sendto(unsigned(withdrawn), (host, port))
            attacker.sendto(sealer.seal(DatagramKind.BEACON), (host, port))
        for robot in ("r1", "r2"):  # anyone may write the parameter server
            rospy.set_param(f"{interface.RADIO_DIRECTORY}/{robot}", trap)
        op.start()
        op.wait_status([member1, member2], S.SUCCESS, timeout=90.0)
        wait_until(
            lambda: dropped(op, "r1") + dropped(op, "r2") >= before + 6,
            60.0,
            "both robots to count what the attacker sent",
        )
        heard = 0
        while True:  # what reached the trap: signed datagrams it cannot forge or reuse
            try:
                attacker.recvfrom(65535)
                heard += 1
            except TimeoutError:
                break
    system.stop("server")
    assert_released_together(system.journal, [member1, member2])
    assert team_key().secret != b"\x01" * 32
    # Each robot put its own directory entry right again.
    for robot in ("r1", "r2"):
        wait_until(
            lambda robot=robot: rospy.get_param(f"{interface.RADIO_DIRECTORY}/{robot}") != trap,
            60.0,
            f"{robot} to restore its directory entry",
        )
    print(f"datagrams that reached the trap (signed, of no use to it): {heard}")
