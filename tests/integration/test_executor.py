"""The mission executor with a real rosmaster, mission server, executors and link emulator.

Robots run the basic skills (``wait``: timed; ``probe``: fails when asked;
``count``: steps on the executor's ticks; all honour pause and cancel) from
``tests/data/test_team.yaml``. The operator is this process, calling the
server's services; some tests play the ground or a robot on the link topics
themselves to send what a correct peer never would.
"""

from __future__ import annotations

import itertools
import json
import math
import signal
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import pytest
import rosmc.msg as wire
import rosmc.srv as srv
import rospy
from rosmc.msg import ErrorCode

from rosmc_server import interface
from rosmc_server.conversions import time_to_msg
from rosmc_server.core import (
    LostLinkKind,
    LostLinkPolicy,
    Resolution,
    SkillInstance,
    SkillStatus,
    Transfer,
)
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.link import queue_hash, status_digest
from rosmc_server.recording import read_journal
from rosmc_server.ros.client import MissionClient
from tests.conftest import wait_until
from tests.integration.executor_fixtures import (
    LinkEnd,
    Operator,
    OperatorError,
    RosmcSystem,
    Transition,
    assert_released_together,
    command_msg,
    describe,
    journal_reports,
    journal_timelines,
    policy_words,
    send_datagrams,
    signal_datagram,
)

pytestmark = pytest.mark.integration

S = SkillStatus
K = CommandKind
AGENTS = ("r1", "r2", "r3")
BARRIER_ROUNDS = 12

# Status changes the ground may show for a skill, as (status, transfer) pairs.
_U = Transfer.UPLOADING
_N = Transfer.NONE
_R = Transfer.REMOVING
LEGAL: dict[tuple[SkillStatus, Transfer], set[tuple[SkillStatus, Transfer]]] = {
    (S.IDLE, _N): {(S.IDLE, _U)},
    (S.IDLE, _U): {(S.IDLE_SYNCHRONIZED, _N), (S.IDLE, _N)},
    (S.IDLE_SYNCHRONIZED, _N): {
        (S.IDLE_SYNCHRONIZED, _R),
        (S.SYNCWAITING, _N),
        (S.RUNNING, _N),
        (S.FAILURE, _N),
    },
    (S.IDLE_SYNCHRONIZED, _R): {(S.IDLE, _N), (S.IDLE_SYNCHRONIZED, _N)},
    (S.SYNCWAITING, _N): {
        (S.RUNNING, _N),
        (S.PAUSED, _N),
        (S.IDLE_SYNCHRONIZED, _N),
        (S.FAILURE, _N),  # gave up waiting (its timeout)
    },
    (S.RUNNING, _N): {(S.PAUSED, _N), (S.SUCCESS, _N), (S.FAILURE, _N), (S.IDLE_SYNCHRONIZED, _N)},
    (S.PAUSED, _N): {(S.RUNNING, _N), (S.SYNCWAITING, _N), (S.IDLE_SYNCHRONIZED, _N)},
    (S.SUCCESS, _N): set(),
    (S.FAILURE, _N): set(),
}

Start = Callable[..., tuple[RosmcSystem, Operator]]


@pytest.fixture
def rosmc(ros_master, tmp_path: Path) -> Iterator[Start]:
    """``rosmc(agents=AGENTS, emulated=(), server=True, server_params=())``: a running system.

    Starts the mission server (journal in ``tmp_path``), the link emulator for the
    ``emulated`` agents and one executor per agent, and waits until the server hears
    every executor. Everything stops when the test ends.
    """
    systems: list[RosmcSystem] = []
    operators: list[Operator] = []

    def start(
        agents: Sequence[str] = AGENTS,
        emulated: Sequence[str] = (),
        server: bool = True,
        server_params: Sequence[str] = (),
    ) -> tuple[RosmcSystem, Operator]:
        system = RosmcSystem(ros_master.env, tmp_path / f"system{len(systems)}")
        systems.append(system)
        if server:
            system.start_server(*server_params)
        if emulated:
            system.start_emulator(emulated)
        for agent in agents:
            system.start_executor(agent, agent in emulated)
        operator = Operator()
        operators.append(operator)
        if server:
            operator.wait_links(agents)
        return system, operator

    yield start
    for operator in operators:
        operator.close()
    for system in systems:
        system.close()
        print(system.log_tails())


def timeline(lines: dict[str, list[Transition]], skill_id: str) -> list[tuple[SkillStatus, int]]:
    return [(t.status, t.transfer) for t in lines[skill_id]]


def assert_legal(lines: dict[str, list[Transition]], skill_id: str) -> None:
    """Every step of a skill's journaled history is a legal transition."""
    steps = timeline(lines, skill_id)
    assert steps[0] in ((S.IDLE, _N), (S.IDLE_SYNCHRONIZED, _N)), steps  # added, or a retry
    for before, after in itertools.pairwise(steps):
        key = (before[0], Transfer(before[1]))
        assert (after[0], Transfer(after[1])) in LEGAL[key], f"{skill_id}: {before} -> {after}"


def happy(barrier: bool) -> list[tuple[SkillStatus, Transfer]]:
    """IDLE -> uploading -> IDLE_SYNCHRONIZED -> [SYNCWAITING] -> RUNNING -> SUCCESS."""
    waiting = [(S.SYNCWAITING, _N)] if barrier else []
    return [
        (S.IDLE, _N),
        (S.IDLE, _U),
        (S.IDLE_SYNCHRONIZED, _N),
        *waiting,
        (S.RUNNING, _N),
        (S.SUCCESS, _N),
    ]


def wait_all_synced(op: Operator, ids: Sequence[str]) -> None:
    op.wait_status(ids, S.IDLE_SYNCHRONIZED)


# -- whole missions -------------------------------------------------------------------
def test_three_robots_two_barriers_run_to_completion_in_a_legal_order(rosmc: Start) -> None:
    system, op = rosmc()
    r1 = [
        op.add("r1", "wait", {"duration": 0.2}),
        op.add("r1", "wait", {"duration": 0.1}),
        op.add("r1", "count", {"steps": 2, "period": 0.05}),
        op.add("r1", "wait", {"duration": 0.1}),
    ]
    r2 = [
        op.add("r2", "wait", {"duration": 0.4}),
        op.add("r2", "wait", {"duration": 0.1}),
        op.add("r2", "probe", {"duration": 0.1, "fail": False}),
    ]
    r3 = [
        op.add("r3", "count", {"steps": 3, "period": 0.1}),
        op.add("r3", "wait", {"duration": 0.1}),
    ]
    barriers = [(r1[1], r2[1]), (r1[3], r3[1])]
    for members in barriers:
        op.add_barrier(members)
    for agent in AGENTS:
        op.sync(agent)
    everything = r1 + r2 + r3
    wait_all_synced(op, everything)
    op.start()
    op.wait_status(everything, S.SUCCESS, timeout=60.0)

    assert system.stop("server") == 0  # a clean stop closes the journal
    lines = journal_timelines(system.journal)
    in_barrier = {member for members in barriers for member in members}
    for skill_id in everything:
        assert timeline(lines, skill_id) == happy(skill_id in in_barrier), skill_id
    for members in barriers:
        assert_released_together(system.journal, members)
    # Every robot's reports reached the journal once each, numbered without gaps.
    for agent in AGENTS:
        seqs = [r.seq for r in journal_reports(system.journal) if r.agent == agent]
        assert seqs == list(range(1, len(seqs) + 1)), (agent, seqs)


def test_team_send_is_one_change_for_every_robot_or_none(rosmc: Start) -> None:
    """SynchronizeTeam: a refusal for one robot sends nobody; accepted, one revision and event."""
    system, op = rosmc()
    r1 = [op.add("r1", "wait", {"duration": 0.1}), op.add("r1", "wait", {"duration": 0.1})]
    r2 = [op.add("r2", "wait", {"duration": 0.3}), op.add("r2", "wait", {"duration": 0.1})]
    op.add_barrier([r1[1], r2[1]])
    before = op.mission()
    refusals = [
        (["r1", "r2"], ["", r1[0]], ErrorCode.RULE),  # r1's skill as r2's stop
        (["r1", "ufo"], [], ErrorCode.NOT_FOUND),
        (["r1", "r1"], [], ErrorCode.INVALID),
        (["r1", "r2"], [r1[0]], ErrorCode.INVALID),  # one stop for two robots
        (["r1", "r3"], [], ErrorCode.RULE),  # r3 has nothing planned
    ]
    for agents, uptos, code in refusals:
        with pytest.raises(OperatorError) as refused:
            op.call(
                "synchronize_team", base_revision=before.revision, agents=agents, upto_ids=uptos
            )
        assert refused.value.code == code, (agents, uptos, refused.value)
        assert "\n" not in refused.value.message
        after = op.mission()
        assert after.revision == before.revision, (agents, uptos)
        assert describe(after) == describe(before), (agents, uptos)
    seen = len(op.events)
    response = op.call("synchronize_team", base_revision=before.revision, agents=[], upto_ids=[])
    assert response.revision == before.revision + 1
    assert list(response.agents) == ["r1", "r2"]
    assert list(response.skill_ids) == r1 + r2
    assert response.note == ""  # both barrier members go: nobody waits for ever
    wait_until(lambda: len(op.events) > seen, 30.0, "the team's event")
    (_, event), *_ = op.events.since(seen)
    assert (event.revision, event.kind, event.agent) == (
        response.revision,
        wire.MissionEvent.SYNC_REQUESTED,
        "",
    )
    assert [p.skill.id for p in event.put_skills] == r1 + r2
    wait_all_synced(op, r1 + r2)  # each robot got and confirmed its own upload
    op.start()
    op.wait_status(r1 + r2, S.SUCCESS, timeout=60.0)
    system.stop("server")
    lines = journal_timelines(system.journal)
    for skill_id in (r1[1], r2[1]):
        assert timeline(lines, skill_id) == happy(barrier=True), skill_id


def test_barriers_release_their_members_together_over_repeated_runs(rosmc: Start) -> None:
    """Every round, nobody starts before the last member arrives (bench_executor: the skew)."""
    system, op = rosmc()
    op.start()
    rounds = []
    for _ in range(BARRIER_ROUNDS):
        for index, agent in enumerate(AGENTS):  # the robots arrive 0.1 s apart
            op.add(agent, "wait", {"duration": 0.05 + 0.1 * index})
        members = [op.add(agent, "wait", {"duration": 0.05}) for agent in AGENTS]
        op.add_barrier(members)
        for agent in AGENTS:
            op.sync(agent)
        op.wait_status(members, S.SUCCESS)
        rounds.append(members)
    system.stop("server")
    lines = journal_timelines(system.journal)
    for skill_id in itertools.chain.from_iterable(rounds):  # uploaded to started robots
        assert timeline(lines, skill_id) == happy(barrier=True), skill_id
    for members in rounds:
        assert_released_together(system.journal, members)


# -- the ground link ---------------------------------------------------------------------
def test_skills_complete_during_a_blackout_and_report_in_order_after_it(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",), emulated=("r1",), server_params=("_link_timeout:=1.0",))
    robot_side = LinkEnd("r1", "ground", robot_names=True)  # hears r1 behind the emulator
    wait_until(robot_side.connected, 30.0, "r1's side of the link")
    ids = [op.add("r1", "wait", {"duration": 1.0}) for _ in range(3)]
    op.sync("r1")
    wait_all_synced(op, ids)
    op.start("r1")
    op.events.wait_went(ids[0], S.RUNNING)  # the event, not a look that could miss the state
    op.blackout("r1", True)
    robot_side.wait_heard("report", lambda r: r.skill_id == ids[2] and r.status.value == S.SUCCESS)
    wait_until(
        lambda: op.agent_state("r1").link.state == wire.LinkState.DOWN, 30.0, "the link DOWN"
    )
    robot_side.close()
    during = op.mission()
    assert during.skill(ids[2]).status is S.IDLE_SYNCHRONIZED, describe(during)
    assert op.agent_state("r1").link.state == wire.LinkState.DOWN
    restored = time.time()
    op.blackout("r1", False)
    op.wait_status(ids, S.SUCCESS, timeout=45.0)
    print(f"reports delivered {time.time() - restored:.2f} s after the link came back")

    system.stop("server")
    lines = journal_timelines(system.journal)
    for skill_id in ids:
        assert timeline(lines, skill_id) == happy(barrier=False)
    success = [next(t.revision for t in lines[i] if t.status is S.SUCCESS) for i in ids]
    assert success == sorted(success)
    finished = {r.skill_id: r.finished for r in journal_reports(system.journal) if r.finished}
    assert all(finished[i] < restored for i in ids), "the robot finished them during the outage"


# -- operator workflows ---------------------------------------------------------------------
def test_unsync_while_running_keeps_the_running_skill(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",))
    first, *later = [op.add("r1", "wait", {"duration": d}) for d in (3.0, 0.1, 0.1)]
    op.sync("r1")
    wait_all_synced(op, [first, *later])
    op.start("r1")
    op.events.wait_went(first, S.RUNNING)
    assert op.unsync("r1") == later
    op.wait_mission(
        lambda m: all(m.skill(i).status is S.IDLE and not m.skill(i).transfer for i in later),
        30.0,
        "the later skills to return to the blueprint",
    )
    # Its SUCCESS event: the mission may show it before the event reaches this subscriber.
    op.events.wait_went(first, S.SUCCESS)
    # The running skill went on to its end: never stopped, never sent back.
    assert op.events.statuses(first)[-2:] == [S.RUNNING, S.SUCCESS], op.events.statuses(first)
    time.sleep(0.5)  # the later skills stay in the blueprint: nothing to wait on
    state = op.mission()
    assert [state.skill(i).status for i in later] == [S.IDLE, S.IDLE]
    assert all(state.skill(i).started == 0.0 for i in later)
    link = op.agent_state("r1").link
    assert link.queue_hash == link.robot_queue_hash == queue_hash([first])
    system.stop("server")
    lines = journal_timelines(system.journal)
    for skill_id in later:
        assert_legal(lines, skill_id)
        assert S.RUNNING not in [t.status for t in lines[skill_id]]


def test_stop_edit_resync_start(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",))
    long, short = op.add("r1", "wait", {"duration": 30.0}), op.add("r1", "wait", {"duration": 0.1})
    op.sync("r1")
    wait_all_synced(op, [long, short])
    op.start("r1")
    op.wait_status([long], S.RUNNING)
    op.control("r1", srv.ControlRequest.STOP)
    state = op.wait_status([long], S.IDLE_SYNCHRONIZED)
    assert state.skill(long).status_text == "stopped by the operator"
    with pytest.raises(OperatorError) as refused:
        op.edit(long, {"duration": 0.2})  # still on the robot
    assert refused.value.code == ErrorCode.RULE
    assert op.unsync("r1") == [long, short]
    op.wait_status([long, short], S.IDLE)
    op.edit(long, {"duration": 0.2})
    op.sync("r1")
    wait_all_synced(op, [long, short])
    op.start("r1")
    state = op.wait_status([long, short], S.SUCCESS)
    ran = state.skill(long)
    assert ran.params["duration"] == 0.2
    assert ran.finished - ran.started < 15.0  # the edited 0.2 s ran, not the stopped 30 s
    system.stop("server")
    lines = journal_timelines(system.journal)
    assert_legal(lines, long)
    assert [t.status for t in lines[long]].count(S.RUNNING) == 2


def test_pause_and_resume_at_a_barrier(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1", "r2"))
    early = op.add("r1", "wait", {"duration": 0.1})
    busy = op.add("r2", "wait", {"duration": 4.0})
    late = op.add("r2", "wait", {"duration": 0.1})
    op.add_barrier([early, late])
    op.sync("r1")
    op.sync("r2")
    wait_all_synced(op, [early, busy, late])
    op.start()
    state = op.wait_status([early], S.SYNCWAITING)
    assert state.skill(early).status_text.startswith("waiting on r2 at ")
    op.control("r1", srv.ControlRequest.PAUSE)
    op.wait_status([early], S.PAUSED)
    op.control("r1", srv.ControlRequest.RESUME)
    state = op.wait_mission(lambda m: m.skill(early).status is not S.PAUSED, 30.0, "r1 to resume")
    assert state.skill(early).status is S.SYNCWAITING, describe(state)
    assert state.skill(busy).status is S.RUNNING  # the peer has not arrived yet
    op.wait_status([early, late], S.SUCCESS, timeout=45.0)
    system.stop("server")
    lines = journal_timelines(system.journal)
    assert [t.status for t in lines[early]][2:] == [
        S.IDLE_SYNCHRONIZED,
        S.SYNCWAITING,
        S.PAUSED,
        S.SYNCWAITING,
        S.RUNNING,
        S.SUCCESS,
    ]
    assert_released_together(system.journal, [early, late])


def failed_at_the_barrier(op: Operator) -> tuple[str, str, str]:
    """r1's member gives up waiting (its 1 s timeout) before r2 arrives; r2 then waits for r1.

    Returns (r1's failed member, r2's waiting member, the barrier).
    """
    member = op.add("r1", "wait", {"duration": 0.2}, timeout=1.0)
    partner = op.add("r2", "wait", {"duration": 0.2})
    barrier = op.add_barrier([member, partner])
    op.sync("r1")
    op.sync("r2")
    wait_all_synced(op, [member, partner])
    op.start("r1")
    state = op.wait_status([member], S.FAILURE)
    assert state.skill(member).status_text == (
        f"timed out after 1 s waiting at barrier '{barrier}' for r2"
    )
    op.start("r2")
    state = op.wait_status([partner], S.SYNCWAITING)
    assert state.skill(partner).status_text.startswith("waiting on r1 at ")
    time.sleep(0.5)  # r1 holds at its failure: r2 keeps waiting
    assert op.mission().skill(partner).status is S.SYNCWAITING
    return member, partner, barrier


def test_a_member_that_failed_at_its_barrier_is_retried_and_starts_with_its_partner(
    rosmc: Start,
) -> None:
    system, op = rosmc(agents=("r1", "r2"))
    member, partner, barrier = failed_at_the_barrier(op)
    mark = len(op.events)
    fresh = op.retry_skill(member)
    state = op.wait_status([fresh, partner], S.SUCCESS)
    assert state.barrier(barrier).skill_ids == (fresh, partner)
    retried = next(m for _, m in op.events.since(mark) if m.kind == wire.MissionEvent.SKILL_RETRIED)
    assert f"barrier '{barrier}' now waits for '{fresh}'" in retried.summary
    system.stop("server")
    lines = journal_timelines(system.journal)
    assert timeline(lines, fresh) == [
        (S.IDLE_SYNCHRONIZED, _N),
        (S.SYNCWAITING, _N),
        (S.RUNNING, _N),
        (S.SUCCESS, _N),
    ]
    assert [t.status for t in lines[partner]][-3:] == [S.SYNCWAITING, S.RUNNING, S.SUCCESS]
    for skill_id in (member, fresh, partner):
        assert_legal(lines, skill_id)
    assert_released_together(system.journal, [fresh, partner])


def test_skipping_a_member_that_failed_at_its_barrier_lets_its_partner_go_on(
    rosmc: Start,
) -> None:
    _, op = rosmc(agents=("r1", "r2"))
    member, partner, _ = failed_at_the_barrier(op)
    op.skip_skill(member)
    state = op.wait_status([partner], S.SUCCESS)
    assert state.barriers == ()
    assert state.skill(member).resolution is Resolution.SKIPPED


def test_failure_retry_skip_and_a_retry_that_succeeds(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1", "r2"))
    # r1: a failure retried as is (fails again), then skipped.
    probe = op.add("r1", "probe", {"duration": 0.1, "fail": True})
    after = op.add("r1", "wait", {"duration": 0.1})
    # r2: a failure retried after the operator fixed the fresh instance's parameters.
    probe2 = op.add("r2", "probe", {"duration": 0.1, "fail": True})
    after2 = op.add("r2", "wait", {"duration": 0.1})
    op.sync("r1")
    op.sync("r2")
    wait_all_synced(op, [probe, after, probe2, after2])
    op.start()
    state = op.wait_status([probe, probe2], S.FAILURE)
    assert state.skill(probe).status_text == "the probe failed as its parameters asked"
    time.sleep(0.5)  # the robot holds: what follows does not start
    assert op.mission().skill(after).status is S.IDLE_SYNCHRONIZED
    with pytest.raises(OperatorError) as refused:
        op.edit(probe, {"fail": False})
    assert refused.value.code == ErrorCode.RULE

    fresh = op.retry_skill(probe)
    state = op.wait_status([fresh], S.FAILURE)
    again = state.skill(fresh)
    assert again.attempt == 2 and again.id != probe
    assert state.skill(probe).resolution is Resolution.RETRIED
    assert [s.id for s in state.task("r1")] == [probe, fresh, after]
    op.skip_skill(fresh)
    op.wait_status([after], S.SUCCESS)

    op.control("r2", srv.ControlRequest.STOP)  # so the fresh instance waits on the robot
    fresh2 = op.retry_skill(probe2)
    op.wait_status([fresh2], S.IDLE_SYNCHRONIZED)
    assert op.unsync("r2", fresh2) == [fresh2, after2]
    op.wait_status([fresh2, after2], S.IDLE)
    op.edit(fresh2, {"fail": False})
    op.sync("r2")
    wait_all_synced(op, [fresh2, after2])
    op.start("r2")
    state = op.wait_status([fresh2, after2], S.SUCCESS)
    assert state.skill(fresh2).attempt == 2
    assert state.skill(fresh2).status_text == "probe done"
    system.stop("server")
    lines = journal_timelines(system.journal)
    for skill_id in (probe, fresh, after, probe2, fresh2, after2):
        assert_legal(lines, skill_id)


def test_executor_restart_mid_mission_keeps_the_queue(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",))
    # The middle skill runs long enough to be killed mid-run on a busy machine too.
    ids = [op.add("r1", "wait", {"duration": d}) for d in (0.1, 8.0, 0.1)]
    op.sync("r1")
    wait_all_synced(op, ids)
    op.start("r1")
    op.events.wait_went(ids[1], S.RUNNING)
    system.stop("r1", signal.SIGKILL)
    system.start_executor("r1")
    # The robot's snapshot may show the skill back on the shelf before its report says why.
    state = op.wait_mission(
        lambda m: m.skill(ids[1]).status_text == "interrupted by an executor restart",
        60.0,
        "the restart's report",
    )
    assert state.skill(ids[1]).status is S.IDLE_SYNCHRONIZED
    assert state.skill(ids[0]).status is S.SUCCESS
    assert state.skill(ids[2]).status is S.IDLE_SYNCHRONIZED
    op.wait_links(["r1"])
    restarted = time.time()
    link = op.agent_state("r1")
    assert link.link.robot_queue_hash == link.link.queue_hash == queue_hash(ids)
    assert link.executor_state == "stopped"  # a restarted robot waits for the operator
    op.start("r1")
    state = op.wait_status(ids, S.SUCCESS)
    assert state.skill(ids[1]).started >= restarted  # run again from its beginning
    system.stop("server")
    assert "repairing" not in system.log("server").read_text()
    assert_legal(journal_timelines(system.journal), ids[1])


def test_an_executor_that_lost_its_state_does_not_run_finished_skills_again(
    rosmc: Start,
) -> None:
    system, op = rosmc(agents=("r1",))
    done = [op.add("r1", "wait", {"duration": 0.1}) for _ in range(2)]
    op.sync("r1")
    wait_all_synced(op, done)
    op.start("r1")
    op.wait_status(done, S.SUCCESS)
    system.stop("r1", signal.SIGKILL)
    system.state_file("r1").unlink()  # a new disk
    system.start_executor("r1")
    op.wait_links(["r1"])
    wait_until(
        lambda: op.agent_state("r1").link.robot_queue_hash == queue_hash(done),
        45.0,
        "the ground to repair the robot's queue",
    )
    more = op.add("r1", "wait", {"duration": 0.1})
    op.sync("r1")
    op.start("r1")
    state = op.wait_status([more], S.SUCCESS)
    assert [s.status for s in state.task("r1")] == [S.SUCCESS] * 3
    system.stop("server")
    runs = {
        (r.skill_id, r.started)
        for r in journal_reports(system.journal)
        if r.status.value == S.RUNNING
    }
    assert sorted(skill_id for skill_id, _ in runs) == sorted([*done, more])  # each ran once


def test_a_new_mission_after_a_finished_one(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",))
    done = op.add("r1", "wait", {"duration": 0.1})
    op.sync("r1")
    op.start("r1")
    op.wait_status([done], S.SUCCESS)
    op.change("new_mission", keep_markers=True)
    wait_until(
        lambda: op.agent_state("r1").link.robot_queue_hash == queue_hash([]),
        30.0,
        "the robot to drop the old mission",
    )
    fresh = op.add("r1", "wait", {"duration": 0.1})
    op.sync("r1")
    op.wait_status([fresh], S.SUCCESS)
    snapshots = LinkEnd("r1", "ground")  # hears what the server hears
    wait_until(lambda: len(snapshots.received("snapshot")) >= 3, 30.0, "three more snapshots")
    snapshots.close()  # the hashes agreed on each of them: no repair goes on
    link = op.agent_state("r1").link
    assert (link.robot_queue_hash, link.hash_mismatch) == (queue_hash([fresh]), False)
    assert link.commands_in_flight == 0
    system.stop("server")
    assert system.log("server").read_text().count("repairing") <= 1
    assert timeline(journal_timelines(system.journal), fresh) == happy(barrier=False)


# -- timeouts and automatic retries ---------------------------------------------------------
def test_timeout_and_automatic_retries(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1", "r2"))
    slow = op.add("r1", "wait", {"duration": 30.0}, timeout=0.3)
    flaky = op.add("r2", "probe", {"duration": 0.1, "fail": True}, max_retries=2)
    op.sync("r1")
    op.sync("r2")
    wait_all_synced(op, [slow, flaky])
    op.start()
    state = op.wait_status([slow, flaky], S.FAILURE)
    assert state.skill(slow).status_text == "timed out after 0.3 s"
    assert state.skill(slow).finished - state.skill(slow).started < 15.0  # not its 30 s
    assert state.skill(flaky).attempt == 3
    system.stop("server")
    attempts = [
        (r.status.value, r.attempt, r.status_text)
        for r in journal_reports(system.journal)
        if r.skill_id == flaky
    ]
    assert attempts == [
        (S.RUNNING, 1, ""),
        (S.RUNNING, 2, "retry 1 of 2"),
        (S.RUNNING, 3, "retry 2 of 2"),
        (S.FAILURE, 3, "the probe failed as its parameters asked"),
    ]


# -- bad input -------------------------------------------------------------------------------
def test_an_upload_with_a_skill_the_robot_lacks_is_refused_with_the_reason(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",))
    ok = op.add("r1", "wait", {"duration": 0.1})
    lacking = op.add("r1", "teleport")
    later = op.add("r1", "wait", {"duration": 0.1})
    op.sync("r1")
    state = op.wait_mission(
        lambda m: all(not m.skill(i).transfer for i in (ok, lacking, later)), 30.0, "the answer"
    )
    assert state.skill(ok).status is S.IDLE_SYNCHRONIZED
    for skill_id in (lacking, later):
        skill = state.skill(skill_id)
        assert skill.status is S.IDLE  # back in the blueprint
        assert skill.status_text == "r1 does not implement skill 'teleport'"
    op.change("delete_skills", skill_ids=[lacking])
    op.sync("r1")
    op.start("r1")
    op.wait_status([ok, later], S.SUCCESS)
    system.stop("server")


def wait_skill(skill_id: str, agent: str = "r1", **params: object) -> SkillInstance:
    return SkillInstance(skill_id, agent, "wait", "wait", params or {"duration": 0.1})


def test_bad_commands_over_the_link_are_refused_clearly(rosmc: Start) -> None:
    system, _ = rosmc(agents=("r1",), server=False)
    ground = LinkEnd("r1", "ground")
    ground.wait_heard("snapshot", lambda m: True, timeout=60.0)  # the executor is up
    wait_until(ground.connected, 30.0, "the link topics to connect")

    def send(seq: int, kind: CommandKind, **fields: object) -> wire.RobotAck:
        ground.publish("command", command_msg("r1", seq, kind, **fields))  # type: ignore[arg-type]
        return ground.wait_heard("ack", lambda a: a.seq == seq and a not in answered)

    answered: list[wire.RobotAck] = []
    teleport = SkillInstance("t1", "r1", "teleport", "teleport", {})
    first = send(1, K.UPLOAD, skills=[teleport])
    answered.append(first)
    assert first.result == wire.RobotAck.REJECTED
    assert list(first.rejection_reasons) == ["r1 does not implement skill 'teleport'"]

    typed = send(2, K.UPLOAD, skills=[wait_skill("w1", duration="ten")])
    answered.append(typed)
    assert list(typed.rejection_reasons) == ["parameter 'duration' of skill 'wait' must be float"]

    # A duplicate gets the first answer again and is not executed again.
    duplicate = send(1, K.UPLOAD, skills=[wait_skill("w-dup")])
    answered.append(duplicate)
    assert (duplicate.result, list(duplicate.rejection_reasons)) == (
        first.result,
        list(first.rejection_reasons),
    )
    # An early command waits for the one before it (the ground resends in order).
    ground.publish("command", command_msg("r1", 4, K.START))
    time.sleep(0.5)  # no answer comes
    assert not [a for a in ground.received("ack") if a.seq == 4]
    answered.append(send(3, K.UPLOAD, skills=[wait_skill("w3")]))
    assert answered[-1].result == wire.RobotAck.ACCEPTED
    answered.append(send(4, K.START))
    ground.wait_heard("report", lambda r: r.skill_id == "w3" and r.status.value == S.SUCCESS)

    # Commands the robot cannot read are refused, and the link goes on.
    bad_type = command_msg("r1", 5, K.START)
    bad_type.type = 99
    ground.publish("command", bad_type)
    unreadable = ground.wait_heard("ack", lambda a: a.seq == 5)
    assert unreadable.result == wire.RobotAck.REJECTED
    assert "unknown command type 99" in unreadable.error
    bad_param = command_msg("r1", 6, K.UPLOAD, skills=[wait_skill("w6")])
    bad_param.skills[0].parameters[0].type = 42
    ground.publish("command", bad_param)
    unreadable = ground.wait_heard("ack", lambda a: a.seq == 6)
    assert unreadable.result == wire.RobotAck.REJECTED
    assert "parameter 'duration' has unknown type number 42" in unreadable.error
    lopsided = wire.Barrier(id="B", skill_ids=["w7", "x"], agents=["r1"])
    unreadable = send(7, K.BARRIERS, barriers=[lopsided])
    assert unreadable.result == wire.RobotAck.REJECTED
    assert "lists 1 agents for 2 skills" in unreadable.error

    # Messages for other robots are none of this robot's business.
    ground.publish("command", command_msg("r2", 8, K.UPLOAD, skills=[wait_skill("x", "r2")]))
    ground.publish("report_ack", wire.ReportAck(agent="r2", seq=1000))
    # Nor are stray datagrams on its radio: an unknown signal kind, garbage, a cut-off one.
    stray = wire.BarrierSignal(agent="r9", barrier_id="B", skill_id="x", kind=9)
    send_datagrams("r1", signal_datagram(stray), b"garbage", signal_datagram(stray)[:-3])

    last = send(8, K.UPLOAD, skills=[wait_skill("w8")])
    assert last.result == wire.RobotAck.ACCEPTED
    report = ground.wait_heard("report", lambda r: r.skill_id == "w8" and r.status.value == 5)
    assert report.seq > 2  # w3's reports were not dropped by the stray report ack
    snapshot = ground.wait_heard("snapshot", lambda s: s.last_command_seq == 8)
    assert snapshot.queue_omitted and not snapshot.queue  # the digest stands in for it
    ground.publish("report_ack", wire.ReportAck(agent="r1", seq=0, want_full=True))
    full = ground.wait_heard("snapshot", lambda s: s.last_command_seq == 8 and not s.queue_omitted)
    assert [s.id for s in full.queue] == ["w3", "w8"]
    statuses = [(s.id, s.status.value) for s in full.queue]
    assert full.status_digest == status_digest(statuses)
    # A digest-only snapshot of the same queue carries the same digest (one taken while w8
    # still ran carries that moment's).
    ground.wait_heard(
        "snapshot",
        lambda s: (
            s.queue_omitted and s.last_command_seq == 8 and s.status_digest == full.status_digest
        ),
    )
    assert system.alive("r1")
    ground.close()


def test_lost_link_policy_hold_on_a_silent_link(rosmc: Start) -> None:
    """The test is the ground: it goes silent (no commands, no report acks)."""
    system, _ = rosmc(agents=("r1",), server=False)
    ground = LinkEnd("r1", "ground")
    ground.wait_heard("snapshot", lambda m: True, timeout=60.0)
    wait_until(ground.connected, 30.0, "the link topics to connect")
    options = json.dumps({"lost_link": {"policy": "hold", "after": 1.0}})
    commands = [
        command_msg("r1", 1, K.SET_OPTIONS, argument=options),
        command_msg("r1", 2, K.UPLOAD, skills=[wait_skill("long", duration=30.0)]),
        command_msg("r1", 3, K.START),
    ]
    for command in commands:
        ground.publish("command", command)
    ground.wait_heard("ack", lambda a: a.seq == 3)
    last_contact = time.monotonic()
    ground.wait_heard("report", lambda r: r.status.value == S.RUNNING)
    held = ground.wait_heard("report", lambda r: r.status.value == S.PAUSED, timeout=30.0)
    assert time.monotonic() - last_contact >= 0.9  # the robot heard command 3 a bit earlier
    assert held.status_text == "held after 1 s without ground contact"
    # The ground is back and acknowledges as its heartbeat does, again and again: one ack
    # followed by silence would trigger the policy anew a second later, possibly before the
    # robot's next snapshot showed the contact.
    deadline = time.monotonic() + 60.0
    while not [
        s for s in ground.received("snapshot") if "ground contact is back" in policy_words(s.policy)
    ]:
        assert time.monotonic() < deadline, "the robot never said that ground contact is back"
        ground.publish("report_ack", wire.ReportAck(agent="r1", seq=held.seq))
        time.sleep(0.2)
    snapshot = ground.wait_heard(
        "snapshot", lambda s: "ground contact is back" in policy_words(s.policy)
    )
    assert snapshot.state == "paused"
    assert policy_words(snapshot.policy).startswith("on link loss: hold after 1 s; held after 1 s")
    ground.publish("command", command_msg("r1", 4, K.RESUME))
    resumed = ground.wait_heard("report", lambda r: r.seq > held.seq)
    assert (resumed.skill_id, resumed.status.value) == ("long", S.RUNNING)
    assert system.alive("r1")
    ground.close()


def test_the_server_survives_bad_reports(rosmc: Start) -> None:
    """A fake r3 reports on a skill the server does not know, out of order and twice."""
    system, op = rosmc(agents=())
    robot = LinkEnd("r3", "robot")
    wait_until(robot.connected, 30.0, "the server's link to r3")
    revision = op.mission().revision

    def snapshot() -> wire.ExecutorSnapshot:
        return wire.ExecutorSnapshot(agent="r3", queue_hash=queue_hash([]), state="idle")

    def report(seq: int, status: int = S.RUNNING, skill_id: str = "ghost") -> None:
        robot.publish(
            "report",
            wire.RobotReport(
                agent="r3",
                seq=seq,
                stamp=time_to_msg(time.time()),
                skill_id=skill_id,
                status=wire.SkillStatus(status),
                attempt=1,
            ),
        )

    def acked() -> list[int]:
        return [a.seq for a in robot.received("report_ack")]

    robot.publish("snapshot", snapshot())
    wait_until(lambda: 0 in acked(), 30.0, "the server to learn r3's numbering")
    report(2)  # early: report 1 is missing
    report(1)  # a skill the server does not know
    report(1)  # again
    report(2, status=42)  # a status that does not exist
    wait_until(lambda: acked()[-1:] == [2], 30.0, "the server to acknowledge report 2")
    assert acked().count(1) >= 2  # the duplicate was acknowledged again
    assert op.mission().revision == revision  # nothing applied
    assert system.alive("server")
    assert op.agent_state("r3").link.state == wire.LinkState.UP
    robot.close()
    system.stop("server")
    log = system.log("server").read_text()
    assert "ghost" in log and "unknown status 42" in log
    assert "Traceback" not in log
    journaled = [(r.seq, r.skill_id) for r in journal_reports(system.journal)]
    assert journaled == [(1, "ghost"), (2, "ghost")]  # the audit trail has both, once


def test_lost_link_policy_hold_set_by_the_operator(rosmc: Start) -> None:
    system, op = rosmc(agents=("r1",), emulated=("r1",))
    robot_side = LinkEnd("r1", "ground", robot_names=True)  # hears r1 behind the emulator
    wait_until(robot_side.connected, 30.0, "r1's side of the link")
    with MissionClient(timeout=60.0) as client:
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=1.0))
    op.wait_mission(
        lambda m: "hold after 1 s" in policy_words(op.agent_state("r1").lost_link),
        30.0,
        "the policy to be in force",
    )
    long = op.add("r1", "wait", {"duration": 30.0})
    op.sync("r1")
    wait_all_synced(op, [long])
    op.start("r1")
    op.wait_status([long], S.RUNNING)
    op.blackout("r1", True)
    robot_side.wait_heard("report", lambda r: r.skill_id == long and r.status.value == S.PAUSED)
    robot_side.close()
    op.blackout("r1", False)
    state = op.wait_status([long], S.PAUSED)
    assert state.skill(long).status_text == "held after 1 s without ground contact"
    wait_until(
        lambda: "ground contact is back" in policy_words(op.agent_state("r1").lost_link),
        30.0,
        "the robot to say so",
    )
    assert op.mission().skill(long).status is S.PAUSED  # the operator decides when to go on
    op.control("r1", srv.ControlRequest.RESUME)
    op.wait_status([long], S.RUNNING)
    system.stop("server")


def test_a_snapshot_overtaken_by_newer_reports_does_not_stall_the_report_stream(
    rosmc: Start,
) -> None:
    """A snapshot processed after a newer report must not look like a robot restart."""
    _system, op = rosmc(agents=())
    robot = LinkEnd("r3", "robot")
    wait_until(robot.connected, 30.0, "the server's link to r3")
    robot.publish("snapshot", wire.ExecutorSnapshot(agent="r3", queue_hash=queue_hash([])))
    wait_until(lambda: robot.received("report_ack"), 30.0, "the server to learn r3's numbering")
    a, b = op.add("r3", "wait", {"duration": 1.0}), op.add("r3", "wait", {"duration": 1.0})
    op.sync("r3")
    upload = robot.wait_heard("command", lambda c: c.type == wire.RobotCommand.UPLOAD)
    robot.publish(
        "ack",
        wire.RobotAck(
            agent="r3", seq=upload.seq, accepted_ids=[a, b], queue_hash=queue_hash([a, b])
        ),
    )
    op.wait_status([a, b], S.IDLE_SYNCHRONIZED)
    began = time.time()

    def report(seq: int, skill_id: str, status: int, at: float) -> None:
        robot.publish(
            "report",
            wire.RobotReport(
                agent="r3",
                seq=seq,
                stamp=time_to_msg(at),
                skill_id=skill_id,
                status=wire.SkillStatus(status),
                attempt=1,
                started=at,
            ),
        )

    report(1, a, S.RUNNING, began)
    stale = wire.ExecutorSnapshot(
        agent="r3",
        stamp=time_to_msg(began + 0.1),
        last_command_seq=upload.seq,
        last_report_seq=1,
        queue_hash=queue_hash([a, b]),
        state="running",
    )
    report(2, a, S.SUCCESS, began + 0.2)
    op.wait_status([a], S.SUCCESS)
    robot.publish("snapshot", stale)  # taken before report 2, processed after it
    time.sleep(0.3)  # the server drops it without a word: nothing to wait on
    report(3, b, S.RUNNING, began + 0.3)
    wait_until(lambda: op.mission().skill(b).status is S.RUNNING, 30.0, "report 3 to be applied")
    # The ack travels on its own topic: the mission view can show report 3 before it lands.
    wait_until(lambda: 3 in [m.seq for m in robot.received("report_ack")], 30.0, "report 3's ack")


def test_a_new_executor_does_not_inherit_the_previous_ones_parameters(rosmc: Start) -> None:
    system, op = rosmc(agents=())
    system.start_executor("r1", True)  # behind a link emulator that is not running: no link
    wait_until(
        lambda: "mission executor ready" in system.log("r1").read_text(),
        30.0,
        "the first executor to start",
    )
    for name in ("agent", "robot_side", "state_file"):
        assert not rospy.has_param(f"/r1/mission_executor/{name}"), name
    system.stop("r1")
    system.start_executor("r1", None)  # as a launch file without robot_side starts it
    op.wait_links(["r1"])
    assert "(direct link)" in system.log("r1").read_text()


def test_the_round_trip_is_measured_on_a_quiet_link(rosmc: Start) -> None:
    _, op = rosmc(agents=("r1",))  # linked; no command has been sent
    link = wait_until(
        lambda: (state := op.agent_state("r1").link).round_trip >= 0.0 and state,
        30.0,
        "a round-trip figure from the heartbeat echo",
    )
    assert link.state == wire.LinkState.UP
    assert 0.0 <= link.round_trip < math.inf, link.round_trip  # a figure: bench_executor


def test_commands_for_a_robot_never_heard_are_queued_collapsed_and_sent_when_it_appears(
    rosmc: Start,
) -> None:
    system, op = rosmc(agents=())  # r1's executor is not running yet
    ids = [op.add("r1", "wait", {"duration": 0.05}) for _ in range(2)]
    for _ in range(30):  # an operator changing their mind while the robot is out of reach
        answer = op.change("synchronize", agent="r1", upto_id="")
        assert "queued for r1" in answer.note, answer.note
        op.change("unsynchronize", agent="r1", from_id="")
    assert op.agent_state("r1").link.commands_in_flight == 0, "every upload was cancelled"
    assert "queued for r1" in op.change("synchronize", agent="r1", upto_id="").note
    for _ in range(3):
        answer = op.call("control", agent="r1", command=srv.ControlRequest.START)
        assert "queued for r1" in answer.note
    link = op.agent_state("r1").link
    assert link.state == wire.LinkState.UNKNOWN
    assert link.commands_in_flight == 2, "one upload and one start wait"

    system.start_executor("r1")
    op.wait_links(["r1"])
    op.wait_status(ids, S.SUCCESS)
    snapshot = rospy.wait_for_message(
        interface.ground_link("r1").snapshot, wire.ExecutorSnapshot, timeout=30.0
    )
    assert snapshot.last_command_seq == 2, "the robot received exactly the upload and a start"


def test_synchronizing_a_barrier_member_alone_warns_and_shows_what_it_waits_on(
    rosmc: Start,
) -> None:
    _, op = rosmc(agents=("r1", "r2"))
    first = op.add("r1", "wait", {"duration": 0.05})
    partner = op.add("r2", "wait", {"duration": 0.05})
    barrier = op.add_barrier([first, partner])
    answer = op.change("synchronize", agent="r1", upto_id="")
    assert answer.note.startswith(f"warning: barrier {barrier} also waits on r2's wait")
    assert partner in answer.note
    state = wait_until(
        lambda: (s := op.agent_state("r1")).waiting_on and s,
        30.0,
        "r1's state to show what it waits on",
    )
    assert state.waiting_on == "r2 (not synchronized)"
    assert op.change("synchronize", agent="r2", upto_id="").note == ""


def test_commands_for_a_robot_out_of_contact_wait_and_arrive_once_in_order(rosmc: Start) -> None:
    """While r1's link is blacked out, every operator command is answered and waits for it."""
    system, op = rosmc(agents=("r1",), emulated=("r1",), server_params=("_link_timeout:=1.0",))
    robot = LinkEnd("r1", "robot", robot_names=True)  # hears what reaches the robot
    ground = LinkEnd("r1", "robot")  # hears what the ground sends
    wait_until(lambda: robot.connected() and ground.connected(), 30.0, "both ends of r1's link")
    keep = op.add("r1", "wait", {"duration": 0.05})
    drop = op.add("r1", "wait", {"duration": 0.05})
    op.blackout("r1", True)
    wait_until(
        lambda: op.agent_state("r1").link.state == wire.LinkState.DOWN, 30.0, "the link DOWN"
    )
    sent_before = len(ground.received("command"))
    reached_before = len(robot.received("command"))

    answer = op.change("synchronize", agent="r1", upto_id="")
    assert answer.note.startswith("queued for r1: out of contact"), answer.note
    op.change("unsynchronize", agent="r1", from_id=drop)  # take the second one back
    with MissionClient(timeout=60.0) as client:
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=30.0))
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=45.0))
    state = op.mission()
    assert state.skill(keep).transfer is Transfer.UPLOADING, describe(state)
    assert state.skill(drop).is_editable, describe(state)
    link = op.agent_state("r1").link
    assert link.state == wire.LinkState.DOWN
    assert link.commands_waiting == 2, "the upload of one skill and the last policy"
    assert link.waiting_for >= 0.0
    assert len(ground.received("command")) == sent_before, "nothing leaves while it waits"

    op.blackout("r1", False)
    op.wait_status([keep], S.IDLE_SYNCHRONIZED, timeout=60.0)
    op.wait_mission(
        lambda m: "hold after 45 s" in policy_words(op.agent_state("r1").lost_link),
        60.0,
        "the last policy",
    )
    reached = robot.received("command")[reached_before:]
    once = {c.seq: c for c in reached}  # retransmissions carry the same number
    assert [(K(c.type), [s.id for s in c.skills]) for c in once.values()] == [
        (K.UPLOAD, [keep]),
        (K.SET_OPTIONS, []),
    ]
    assert json.loads(list(once.values())[1].argument)["lost_link"]["after"] == 45.0
    assert op.agent_state("r1").link.commands_waiting == 0
    op.start("r1")
    op.wait_status([keep], S.SUCCESS)
    assert op.mission().skill(drop).status is S.IDLE
    robot.close()
    ground.close()

    system.stop("server")
    cancel = wire.CommandRecord.CANCELLED
    records = read_journal(system.journal, [interface.ROBOT_COMMANDS_TOPIC]).records
    delivered = [
        (K(r.message.type), list(r.message.skill_ids), r.message.held)
        for r in records
        if r.message.event == wire.CommandRecord.DELIVERED and r.message.held
    ]
    assert delivered == [(K.UPLOAD, [keep], True), (K.SET_OPTIONS, [], True)]
    late = [r.message for r in records if r.message.event == wire.CommandRecord.DELIVERED]
    assert all(m.delivered >= m.asked for m in late)
    cancelled = [K(m.type) for m in (r.message for r in records) if m.event == cancel]
    assert cancelled.count(K.SET_OPTIONS) == 1, "the first policy change was replaced"
