"""The executor engine with a fake clock, fake skills and a recording output.

Covers every command kind, command numbering, peer-to-peer barriers (withdrawal,
RELEASED, pause/resume at a barrier), stop, retries, timeouts, holding after a
failure, the lost-link policy and the state file round trip.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar

import pytest

from rosmc_server.core import (
    LostLinkKind,
    ParamType,
    PolicyInForce,
    Pose,
    Resolution,
    SkillInstance,
    SkillStatus,
    Transfer,
)
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.link import queue_hash
from rosmc_server.executor.basic_skills import Count
from rosmc_server.executor.core import (
    AckResult,
    BarrierInfo,
    Command,
    Engine,
    Outcome,
    Report,
    Signal,
    SignalKind,
    SkillBehavior,
    SkillContext,
    SkillType,
)
from rosmc_server.executor.core.engine import ANNOUNCE_PERIOD, KEPT_ACKS, Mode
from rosmc_server.executor.core.progress import PROGRESS_PERIOD
from rosmc_server.executor.core.state_file import load_state, save_state

S = SkillStatus
K = CommandKind


def policy_words(engine: Any) -> str:
    """The policy in force as the engine's snapshot reports it, in words."""
    policy = engine.snapshot().policy
    assert policy is not None, "a whole snapshot says the policy"
    return str(policy.describe())


class FakeClock:
    """A clock the test moves by hand."""

    def __init__(self, now: float = 1000.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


@dataclass
class Recorder:
    """EngineOutputs that keeps everything the engine emits."""

    reports: list[Report] = field(default_factory=list)
    signals: list[Signal] = field(default_factory=list)
    changes: int = 0

    def report(self, report: Report) -> None:
        self.reports.append(report)

    def signal(self, signal: Signal) -> None:
        self.signals.append(signal)

    def changed(self) -> None:
        self.changes += 1

    def trail(self, skill_id: str) -> list[SkillStatus]:
        """The statuses reported for one skill, repeats collapsed."""
        out: list[SkillStatus] = []
        for report in self.reports:
            if report.skill_id == skill_id and (not out or out[-1] is not report.status):
                out.append(report.status)
        return out


class Timed(SkillBehavior):
    """Runs ``duration`` seconds of clock time (paused time does not count).

    Fails at the end if ``fail`` is set, or while ``attempt < succeed_from``.
    """

    instances: ClassVar[list[Timed]] = []

    def __init__(self) -> None:
        self.calls: list[str] = []
        self.ctx: SkillContext | None = None
        self.elapsed = 0.0
        self.last = 0.0
        self.paused = False
        self.cancelled = False
        Timed.instances.append(self)

    def start(self, ctx: SkillContext) -> None:
        self.calls.append("start")
        self.ctx = ctx
        self.last = ctx.now()

    def update(self, now: float) -> Outcome | None:
        assert self.ctx is not None
        if self.cancelled:
            return Outcome.failed("cancelled")
        if not self.paused:
            self.elapsed += now - self.last
        self.last = now
        if self.elapsed < float(self.ctx.params.get("duration", 1.0)):
            return None
        if self.ctx.params.get("fail") or self.ctx.attempt < int(
            self.ctx.params.get("succeed_from", 1)
        ):
            return Outcome.failed(f"failed on attempt {self.ctx.attempt}")
        return Outcome.ok()

    def pause(self) -> None:
        assert self.ctx is not None
        self.calls.append("pause")
        self.update(self.ctx.now())
        self.paused = True

    def resume(self) -> None:
        assert self.ctx is not None
        self.calls.append("resume")
        self.paused = False
        self.last = self.ctx.now()

    def cancel(self) -> None:
        self.calls.append("cancel")
        self.cancelled = True


class Crashing(SkillBehavior):
    """A skill implementation with a bug in ``update``."""

    def start(self, ctx: SkillContext) -> None:
        pass

    def update(self, now: float) -> Outcome | None:
        raise ZeroDivisionError("division by zero")


class Unstartable(SkillBehavior):
    """A skill implementation that cannot start."""

    def start(self, ctx: SkillContext) -> None:
        raise RuntimeError("no arm attached")

    def update(self, now: float) -> Outcome | None:
        raise AssertionError("never started")


SKILL_TYPES = {
    t.name: t
    for t in (
        SkillType("timed", Timed, {"duration": ParamType.FLOAT}),
        SkillType("probe", Timed, {"duration": ParamType.FLOAT, "fail": ParamType.BOOL}),
        SkillType("goto", Timed, {"target": ParamType.POSE}),
        SkillType("count", Count, {"steps": ParamType.INT, "period": ParamType.FLOAT}),
        SkillType("crash", Crashing),
        SkillType("unstartable", Unstartable),
        SkillType("home", Timed),
    )
}


def make_skill(
    skill_id: str, name: str = "timed", agent: str = "r1", **fields: Any
) -> SkillInstance:
    """A skill instance as the ground uploads it (status IDLE, transfer UPLOADING)."""
    params: dict[str, Any] = {"duration": 1.0} if name == "timed" else {}
    params.update(fields.pop("params", {}))
    return SkillInstance(
        skill_id,
        agent,
        name,
        fields.pop("label", name),
        params,
        transfer=Transfer.UPLOADING,
        **fields,
    )


class Robot:
    """One engine with its clock and recorder, and a command counter."""

    def __init__(self, agent: str = "r1", clock: FakeClock | None = None) -> None:
        self.clock = clock or FakeClock()
        self.out = Recorder()
        self.engine = Engine(agent, SKILL_TYPES, self.clock, self.out)
        self.seq = 0

    def send(self, kind: CommandKind, **fields: Any) -> Any:
        """Send the next numbered command; returns its ack."""
        self.seq += 1
        return self.engine.handle_command(Command(self.seq, kind, **fields))

    def upload(self, *skills: SkillInstance, barriers: tuple[BarrierInfo, ...] = ()) -> Any:
        return self.send(K.UPLOAD, skills=skills, barriers=barriers)

    def status(self, skill_id: str) -> SkillStatus:
        return self.skill(skill_id).status

    def skill(self, skill_id: str) -> SkillInstance:
        return next(s for s in self.engine.ledger.queue if s.id == skill_id)

    def ids(self) -> list[str]:
        return [s.id for s in self.engine.ledger.queue]

    def run_for(self, seconds: float, step: float = 0.1) -> None:
        """Advance the clock in steps, ticking the engine."""
        end = self.clock.now + seconds
        while self.clock.now < end - 1e-9:
            self.clock.now = min(end, self.clock.now + step)
            self.engine.tick()


@pytest.fixture(autouse=True)
def _forget_instances() -> None:
    Timed.instances.clear()


@pytest.fixture
def robot() -> Robot:
    return Robot()


# -- uploads and command numbering --------------------------------------------------
def test_upload_holds_the_skills_and_answers_with_the_queue_hash(robot: Robot) -> None:
    ack = robot.upload(make_skill("a"), make_skill("b"))
    assert ack.result is AckResult.ACCEPTED
    assert ack.accepted_ids == ("a", "b") and ack.rejected_ids == ()
    assert ack.queue_hash == queue_hash(["a", "b"]) == robot.engine.queue_hash()
    assert [(s.status, s.transfer) for s in robot.engine.ledger.queue] == [
        (S.IDLE_SYNCHRONIZED, Transfer.NONE)
    ] * 2
    assert robot.out.reports == []  # holding a skill is no status change to report
    assert robot.engine.state_name() == "stopped"


def test_upload_refuses_an_unknown_skill_and_everything_after_it(robot: Robot) -> None:
    ack = robot.upload(make_skill("a"), make_skill("t", "teleport"), make_skill("b"))
    assert ack.result is AckResult.PARTIAL
    assert ack.accepted_ids == ("a",)
    assert ack.rejected_ids == ("t", "b")
    assert ack.rejection_reasons == (
        "r1 does not implement skill 'teleport'",
        "follows refused skill 't'",
    )
    assert ack.error == "r1 does not implement skill 'teleport'"
    assert robot.ids() == ["a"]


@pytest.mark.parametrize(
    ("params", "reason"),
    [
        ({"duration": "ten"}, "parameter 'duration' of skill 'probe' must be float"),
        ({"duration": True, "fail": False}, "parameter 'duration' of skill 'probe' must be float"),
        ({"duration": 1.0, "fail": 1}, "parameter 'fail' of skill 'probe' must be bool"),
        ({"duration": 1.0}, "skill 'probe' needs parameter 'fail'"),
    ],
)
def test_upload_refuses_wrong_parameter_types(
    robot: Robot, params: dict[str, Any], reason: str
) -> None:
    ack = robot.upload(make_skill("p", "probe", params=params))
    assert ack.result is AckResult.REJECTED
    assert ack.rejection_reasons == (reason,)
    assert robot.ids() == []


def test_upload_checks_pose_and_int_parameters(robot: Robot) -> None:
    ok = robot.upload(
        make_skill("g", "goto", params={"target": Pose(1.0, 2.0)}),
        make_skill("c", "count", params={"steps": 3, "period": 1}),  # an int is a fine float
    )
    assert ok.result is AckResult.ACCEPTED
    bad = robot.upload(make_skill("g2", "goto", params={"target": {"x": 1.0}}))
    assert bad.rejection_reasons == ("parameter 'target' of skill 'goto' must be pose",)
    bad = robot.upload(make_skill("c2", "count", params={"steps": 2.5, "period": 1.0}))
    assert bad.rejection_reasons == ("parameter 'steps' of skill 'count' must be int",)


def test_upload_refuses_another_robots_skill(robot: Robot) -> None:
    ack = robot.upload(make_skill("x", agent="r2"))
    assert ack.rejection_reasons == ("skill 'x' is for r2, not r1",)


def test_a_repeated_upload_is_accepted_without_duplicating(robot: Robot) -> None:
    robot.upload(make_skill("a"))
    ack = robot.upload(make_skill("a"), make_skill("b"))
    assert ack.result is AckResult.ACCEPTED and ack.accepted_ids == ("a", "b")
    assert robot.ids() == ["a", "b"]


def test_a_duplicate_command_gets_the_same_answer_and_runs_once(robot: Robot) -> None:
    first = robot.engine.handle_command(Command(1, K.UPLOAD, skills=(make_skill("a"),)))
    robot.engine.handle_command(Command(2, K.UPLOAD, skills=(make_skill("b"),)))
    again = robot.engine.handle_command(Command(1, K.UPLOAD, skills=(make_skill("c"),)))
    assert again == first
    assert robot.ids() == ["a", "b"]
    assert robot.engine.commands.last_seq == 2


def test_an_early_command_waits_for_the_missing_one(robot: Robot) -> None:
    assert robot.engine.handle_command(Command(2, K.START)) is None
    assert robot.engine.mode is Mode.STOPPED and robot.engine.commands.last_seq == 0
    assert robot.engine.handle_command(Command(1, K.UPLOAD, skills=(make_skill("a"),))) is not None
    assert robot.engine.handle_command(Command(2, K.START)) is not None
    assert robot.status("a") is S.RUNNING


def test_a_duplicate_older_than_the_kept_answers_is_answered_plainly(robot: Robot) -> None:
    for seq in range(1, KEPT_ACKS + 3):
        robot.engine.handle_command(Command(seq, K.PAUSE))
    assert len(robot.engine.commands.acks) == KEPT_ACKS
    ack = robot.engine.handle_command(Command(1, K.PAUSE))
    assert ack is not None and ack.seq == 1 and ack.error == "already executed"


def test_an_unreadable_command_is_refused_in_its_turn(robot: Robot) -> None:
    robot.upload(make_skill("a"))
    assert robot.engine.refuse_command(3, "garbled") is None  # early: 2 is missing
    refused = robot.engine.refuse_command(2, "garbled")
    assert refused is not None
    assert (refused.seq, refused.result, refused.error) == (2, AckResult.REJECTED, "garbled")
    assert robot.engine.refuse_command(2, "other") == refused  # a duplicate
    assert robot.engine.handle_command(Command(2, K.START)) == refused  # it used up its number
    assert robot.engine.handle_command(Command(3, K.START)) is not None
    assert robot.status("a") is S.RUNNING


def test_every_command_counts_as_ground_contact_even_a_duplicate(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=json.dumps({"lost_link": {"policy": "hold", "after": 5}}))
    robot.run_for(4.0)
    robot.engine.handle_command(Command(1, K.SET_OPTIONS))  # a retransmission
    robot.run_for(4.0)
    assert robot.engine.mode is Mode.STOPPED  # not held
    robot.run_for(1.5)
    assert robot.engine.mode is Mode.PAUSED


# -- running -------------------------------------------------------------------------
def test_start_runs_the_queue_in_order_with_numbered_reports(robot: Robot) -> None:
    robot.upload(make_skill("a"), make_skill("b", params={"duration": 2.0}))
    t0 = robot.clock.now
    robot.send(K.START)
    assert robot.status("a") is S.RUNNING and robot.skill("a").started == t0
    robot.run_for(1.0)
    assert robot.status("a") is S.SUCCESS and robot.status("b") is S.RUNNING
    assert robot.skill("a").finished == pytest.approx(t0 + 1.0)
    robot.run_for(2.0)
    assert robot.status("b") is S.SUCCESS
    assert [(r.seq, r.skill_id, r.status) for r in robot.out.reports] == [
        (1, "a", S.RUNNING),
        (2, "a", S.SUCCESS),
        (3, "b", S.RUNNING),
        (4, "b", S.SUCCESS),
    ]
    assert robot.engine.ledger.unacked == robot.out.reports
    assert robot.engine.state_name() == "idle"


def test_acknowledged_reports_are_forgotten(robot: Robot) -> None:
    robot.upload(make_skill("a"))
    robot.send(K.START)
    robot.run_for(1.0)
    robot.engine.report_acknowledged(1)
    assert [r.seq for r in robot.engine.ledger.unacked] == [2]
    robot.engine.report_acknowledged(5)
    assert robot.engine.ledger.unacked == []


def test_an_upload_to_a_started_idle_robot_runs_at_once(robot: Robot) -> None:
    robot.send(K.START)
    assert robot.engine.state_name() == "idle"
    robot.upload(make_skill("a"))
    assert robot.status("a") is S.RUNNING


def test_progress_is_reported_as_running_text(robot: Robot) -> None:
    robot.upload(make_skill("c", "count", params={"steps": 2, "period": 0.5}))
    robot.send(K.START)
    robot.run_for(1.2)
    texts = [(r.status, r.status_text) for r in robot.out.reports]
    assert texts == [
        (S.RUNNING, ""),
        (S.RUNNING, "step 1 of 2"),
        (S.RUNNING, "step 2 of 2"),
        (S.SUCCESS, ""),
    ]


def test_progress_said_on_every_step_reaches_the_ground_once_a_period(robot: Robot) -> None:
    """Each text is a report over the radio: a chatty skill is paced, its last text kept."""
    robot.upload(make_skill("c", "count", params={"steps": 50, "period": 0.1}))
    robot.send(K.START)
    robot.run_for(6.0)
    texts = [r.status_text for r in robot.out.reports if r.status is S.RUNNING and r.status_text]
    assert 5 <= len(texts) <= 1 + 5.0 / PROGRESS_PERIOD, texts
    assert texts[0] == "step 1 of 50" and texts[-1] == "step 50 of 50"
    assert robot.status("c") is S.SUCCESS


def test_progress_from_a_skill_thread_waits_for_the_next_tick(robot: Robot) -> None:
    """A threaded skill must not change the engine's state from its own thread."""
    robot.upload(make_skill("a", params={"duration": 5.0}))
    robot.send(K.START)
    ctx = Timed.instances[0].ctx
    assert ctx is not None
    before = list(robot.out.reports)
    ctx.progress("half way")  # as if from the skill's thread
    assert robot.out.reports == before
    assert robot.skill("a").status_text == ""
    robot.run_for(0.1)
    assert robot.skill("a").status_text == "half way"
    assert robot.out.reports[-1].status_text == "half way"


def test_pause_and_resume_a_running_skill(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 1.0}))
    robot.send(K.START)
    robot.run_for(0.5)
    robot.send(K.PAUSE)
    behavior = Timed.instances[0]
    assert robot.status("a") is S.PAUSED
    assert robot.skill("a").status_text == "paused by the operator"
    robot.run_for(5.0)
    assert robot.status("a") is S.PAUSED
    robot.send(K.RESUME)
    assert robot.status("a") is S.RUNNING and robot.skill("a").status_text == ""
    robot.run_for(0.5)
    assert robot.status("a") is S.SUCCESS
    assert behavior.calls == ["start", "pause", "resume"]


def test_pause_and_start_with_nothing_active(robot: Robot) -> None:
    robot.send(K.PAUSE)
    assert robot.engine.state_name() == "paused"
    robot.upload(make_skill("a"))
    assert robot.status("a") is S.IDLE_SYNCHRONIZED
    robot.send(K.START)
    assert robot.status("a") is S.RUNNING


def test_stop_returns_the_running_skill_and_start_runs_it_afresh(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 1.0}), make_skill("b"))
    robot.send(K.START)
    robot.run_for(0.6)
    robot.send(K.STOP)
    first = Timed.instances[0]
    assert first.calls == ["start", "cancel"]
    assert robot.status("a") is S.IDLE_SYNCHRONIZED
    assert robot.skill("a").started == 0.0
    assert robot.skill("a").status_text == "stopped by the operator"
    assert robot.engine.state_name() == "stopped"
    robot.run_for(3.0)
    assert robot.status("b") is S.IDLE_SYNCHRONIZED
    restart = robot.clock.now
    robot.send(K.START)
    assert robot.skill("a").started == restart
    robot.run_for(0.6)
    assert robot.status("a") is S.RUNNING  # a fresh run, not the rest of the old one
    robot.run_for(0.4)
    assert robot.status("a") is S.SUCCESS


def test_stop_with_nothing_active_only_stops(robot: Robot) -> None:
    ack = robot.send(K.STOP)
    assert ack.result is AckResult.ACCEPTED and robot.engine.mode is Mode.STOPPED
    assert robot.out.reports == []


# -- unsynchronize -----------------------------------------------------------------------
def test_unsync_removes_skills_that_have_not_started(robot: Robot) -> None:
    robot.upload(make_skill("a"), make_skill("b"), make_skill("c"))
    robot.send(K.START)
    ack = robot.send(K.UNSYNC, skill_ids=("a", "b", "c"))
    assert ack.accepted_ids == ("b", "c")
    assert ack.rejected_ids == ("a",) and ack.rejection_reasons == ("it had started",)
    assert ack.result is AckResult.PARTIAL
    assert robot.ids() == ["a"] and robot.status("a") is S.RUNNING
    assert ack.queue_hash == queue_hash(["a"])
    robot.run_for(1.0)
    assert robot.status("a") is S.SUCCESS
    assert robot.engine.state_name() == "idle"


def test_unsync_of_an_id_the_robot_no_longer_holds_counts_as_removed(robot: Robot) -> None:
    robot.upload(make_skill("a"))
    ack = robot.send(K.UNSYNC, skill_ids=("a", "ghost"))
    assert ack.accepted_ids == ("a", "ghost") and robot.ids() == []


def test_unsync_keeps_a_skill_waiting_at_its_barrier() -> None:
    robot = Robot("r1")
    barrier = BarrierInfo("B", (("a", "r1"), ("x", "r2")))
    robot.upload(make_skill("a"), make_skill("b"), barriers=(barrier,))
    robot.send(K.START)
    assert robot.status("a") is S.SYNCWAITING
    ack = robot.send(K.UNSYNC, skill_ids=("a", "b"))
    assert ack.accepted_ids == ("b",) and ack.rejected_ids == ("a",)


# -- failures: holding, retry, skip, timeouts, automatic retries --------------------------
def test_a_failure_holds_the_robot_until_retry(robot: Robot) -> None:
    robot.upload(make_skill("p", "probe", params={"duration": 0.5, "fail": True}), make_skill("b"))
    robot.send(K.START)
    robot.run_for(0.5)
    assert robot.status("p") is S.FAILURE
    assert robot.skill("p").status_text == "failed on attempt 1"
    robot.run_for(2.0)
    assert robot.status("b") is S.IDLE_SYNCHRONIZED
    assert robot.engine.state_name() == "holding"
    ack = robot.send(K.START)
    assert ack.error == "holding after the failure of 'p': retry or skip it"
    fresh = replace(make_skill("p2", "probe", params={"duration": 0.5, "fail": True}), attempt=2)
    ack = robot.send(K.RETRY, skill_ids=("p",), skills=(fresh,))
    assert ack.accepted_ids == ("p2",)
    assert robot.ids() == ["p", "p2", "b"]
    assert robot.skill("p").resolution is Resolution.RETRIED
    assert robot.skill("p").status is S.FAILURE  # the log stays
    assert robot.status("p2") is S.RUNNING and robot.skill("p2").attempt == 2
    robot.run_for(0.5)
    assert robot.status("p2") is S.FAILURE
    assert robot.skill("p2").status_text == "failed on attempt 2"


def test_a_repeated_retry_inserts_one_fresh_instance(robot: Robot) -> None:
    robot.upload(make_skill("p", "probe", params={"duration": 0.1, "fail": True}))
    robot.send(K.START)
    robot.run_for(0.1)
    fresh = replace(make_skill("p2", "probe", params={"duration": 0.1, "fail": False}), attempt=2)
    command = Command(robot.seq + 1, K.RETRY, skill_ids=("p",), skills=(fresh,))
    first = robot.engine.handle_command(command)
    assert robot.engine.handle_command(command) == first
    assert robot.ids() == ["p", "p2"]


@pytest.mark.parametrize(
    ("fields", "error"),
    [
        ({"skill_ids": ("b",), "skills": (make_skill("b2"),)}, "nothing to retry"),
        ({"skill_ids": ("ghost",), "skills": (make_skill("g2"),)}, "nothing to retry"),
        ({"skill_ids": ("b",)}, "a retry names the failed skill and its new instance"),
    ],
)
def test_retry_refuses_what_has_not_failed(
    robot: Robot, fields: dict[str, Any], error: str
) -> None:
    robot.upload(make_skill("b"))
    ack = robot.send(K.RETRY, **fields)
    assert ack.error == error
    assert robot.ids() == ["b"]


def test_skip_leaves_the_failure_and_goes_on(robot: Robot) -> None:
    robot.upload(make_skill("p", "probe", params={"duration": 0.1, "fail": True}), make_skill("b"))
    robot.send(K.START)
    robot.run_for(0.1)
    ack = robot.send(K.SKIP, skill_ids=("p",))
    assert ack.accepted_ids == ("p",)
    assert robot.skill("p").resolution is Resolution.SKIPPED
    assert robot.status("p") is S.FAILURE
    assert robot.status("b") is S.RUNNING
    assert robot.send(K.SKIP, skill_ids=("b",)).error == "nothing to skip"
    assert robot.send(K.SKIP).error == "a skip names the failed skill"


def test_a_skill_that_overruns_its_timeout_fails(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 5.0}, timeout=0.5), make_skill("b"))
    robot.send(K.START)
    robot.run_for(0.4)
    assert robot.status("a") is S.RUNNING
    robot.run_for(0.1)
    assert robot.status("a") is S.FAILURE
    assert robot.skill("a").status_text == "timed out after 0.5 s"
    assert Timed.instances[0].calls == ["start", "cancel"]
    assert robot.status("b") is S.IDLE_SYNCHRONIZED


def test_paused_time_does_not_count_against_the_timeout(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 1.0}, timeout=1.5))
    robot.send(K.START)
    robot.run_for(0.5)
    robot.send(K.PAUSE)
    robot.run_for(10.0)
    robot.send(K.RESUME)
    robot.run_for(0.6)
    assert robot.status("a") is S.SUCCESS


def test_automatic_retries_report_each_attempt(robot: Robot) -> None:
    robot.upload(
        make_skill("p", "probe", params={"duration": 0.5, "fail": True}, max_retries=2),
    )
    t0 = robot.clock.now
    robot.send(K.START)
    robot.run_for(2.0)
    assert robot.status("p") is S.FAILURE
    trail = [(r.status, r.attempt, r.status_text) for r in robot.out.reports]
    assert trail == [
        (S.RUNNING, 1, ""),
        (S.RUNNING, 2, "retry 1 of 2"),
        (S.RUNNING, 3, "retry 2 of 2"),
        (S.FAILURE, 3, "failed on attempt 3"),
    ]
    assert {r.started for r in robot.out.reports} == {t0}  # one execution, several attempts
    assert len(Timed.instances) == 3


def test_an_automatic_retry_can_succeed(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 0.2, "succeed_from": 3}, max_retries=5))
    robot.send(K.START)
    robot.run_for(1.0)
    assert robot.status("a") is S.SUCCESS and robot.skill("a").attempt == 3


def test_timeouts_apply_to_each_automatic_retry(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 9.0}, timeout=0.3, max_retries=1))
    robot.send(K.START)
    robot.run_for(0.3)
    assert robot.status("a") is S.RUNNING and robot.skill("a").attempt == 2
    robot.run_for(0.3)
    assert robot.status("a") is S.FAILURE
    assert robot.skill("a").status_text == "timed out after 0.3 s"


def test_a_crashing_skill_fails_cleanly(robot: Robot) -> None:
    robot.upload(make_skill("c", "crash"), make_skill("u", "unstartable"))
    robot.send(K.START)
    robot.run_for(0.1)
    assert robot.status("c") is S.FAILURE
    assert robot.skill("c").status_text == "skill crashed: ZeroDivisionError: division by zero"
    robot.send(K.SKIP, skill_ids=("c",))
    assert robot.status("u") is S.FAILURE
    assert robot.skill("u").status_text == "could not start: no arm attached"


# -- barrier and options commands ----------------------------------------------------------
def test_deleting_the_barrier_of_a_waiting_skill_lets_it_run(robot: Robot) -> None:
    barrier = BarrierInfo("B", (("a", "r1"), ("x", "r2")))
    robot.upload(make_skill("a"), barriers=(barrier,))
    robot.send(K.START)
    assert robot.status("a") is S.SYNCWAITING
    robot.send(K.BARRIERS, barriers=())
    assert robot.status("a") is S.RUNNING


def test_a_barrier_added_to_a_waiting_skill_changes_whom_it_waits_for(robot: Robot) -> None:
    barrier = BarrierInfo("B", (("a", "r1"), ("x", "r2")))
    robot.upload(make_skill("a"), barriers=(barrier,))
    robot.send(K.START)
    wider = BarrierInfo("B", (("a", "r1"), ("x", "r2"), ("y", "r3")))
    robot.engine.hear(Signal("r2", "B", "x", SignalKind.WITHDRAWN, 0.0))
    robot.send(K.BARRIERS, barriers=(wider,))
    assert robot.skill("a").status_text == "waiting on r2, r3 at B"


def test_deleting_the_barrier_of_a_skill_paused_at_it_does_not_run_it(robot: Robot) -> None:
    barrier = BarrierInfo("B", (("a", "r1"), ("x", "r2")))
    robot.upload(make_skill("a"), barriers=(barrier,))
    robot.send(K.START)
    robot.send(K.PAUSE)
    assert robot.status("a") is S.PAUSED
    robot.send(K.BARRIERS, barriers=())
    assert robot.status("a") is S.PAUSED  # the operator paused this robot
    robot.send(K.RESUME)
    assert robot.status("a") is S.RUNNING
    robot.run_for(1.0)
    assert robot.status("a") is S.SUCCESS


@pytest.mark.parametrize(
    ("argument", "error"),
    [
        ("{", "the executor options are not valid JSON"),
        ("[]", "the executor options must be an object with a 'lost_link' object"),
        ('{"lost_link": {"policy": "panic"}}', "lost-link policy must be one of"),
        ('{"lost_link": {"policy": "hold", "after": -1}}', "'after' must be a positive"),
        ('{"lost_link": {"policy": "hold", "after": true}}', "'after' must be a positive"),
        ('{"lost_link": {"policy": "safe_skill", "skill": "fly"}}', "'fly' is not implemented"),
        ('{"lost_link": {"policy": "safe_skill", "skill": "home", "params": 3}}', "'params'"),
    ],
)
def test_set_options_refuses_bad_options(robot: Robot, argument: str, error: str) -> None:
    ack = robot.send(K.SET_OPTIONS, argument=argument)
    assert ack.result is AckResult.REJECTED and error in ack.error
    assert robot.engine.lost_link.policy.kind is LostLinkKind.CONTINUE


def test_set_options_sets_the_policy(robot: Robot) -> None:
    argument = json.dumps({"lost_link": {"policy": "safe_skill", "after": 30, "skill": "home"}})
    ack = robot.send(K.SET_OPTIONS, argument=argument)
    assert ack.result is AckResult.ACCEPTED
    assert policy_words(robot.engine) == "on link loss: run home after 30 s, then hold"
    assert robot.send(K.SET_OPTIONS, argument="").result is AckResult.ACCEPTED
    assert policy_words(robot.engine) == "on link loss: continue"


def test_sync_state_adopts_the_grounds_list_keeping_what_started(robot: Robot) -> None:
    robot.upload(make_skill("a"), make_skill("b"), make_skill("c"))
    robot.send(K.START)
    ground = (make_skill("a"), make_skill("c"), make_skill("d"), make_skill("t", "teleport"))
    barrier = BarrierInfo("B", (("d", "r1"), ("x", "r2")))
    ack = robot.send(K.SYNC_STATE, skills=ground, barriers=(barrier,))
    assert robot.ids() == ["a", "c", "d"]  # b dropped, d added, teleport refused
    assert robot.status("a") is S.RUNNING  # untouched
    assert ack.queue_hash == queue_hash(["a", "c", "d"])
    assert robot.engine.board.barrier_of("d") == barrier


def test_sync_state_keeps_a_started_skill_the_ground_left_out(robot: Robot) -> None:
    robot.upload(make_skill("a"), make_skill("b"))
    robot.send(K.START)
    robot.send(K.SYNC_STATE, skills=(make_skill("b"),))
    assert robot.ids() == ["a", "b"] and robot.status("a") is S.RUNNING


def test_snapshot_describes_the_whole_state(robot: Robot) -> None:
    robot.upload(make_skill("a"), make_skill("b"))
    robot.send(K.START)
    snap = robot.engine.snapshot()
    assert snap.last_command_seq == 2 and snap.last_report_seq == 1
    assert snap.queue_hash == queue_hash(["a", "b"])
    assert [s.id for s in snap.queue] == ["a", "b"]
    assert (snap.state, snap.active_skill_id, snap.waiting_on) == ("running", "a", "")
    assert snap.policy == PolicyInForce()
    assert snap.stamp == robot.clock.now


# -- barriers between robots ----------------------------------------------------------------
class Team:
    """Several engines on one clock; signals are delivered only when the test says so."""

    def __init__(self, *agents: str) -> None:
        self.clock = FakeClock()
        self.robots = {agent: Robot(agent, self.clock) for agent in agents}
        self._delivered = {agent: 0 for agent in agents}

    def __getitem__(self, agent: str) -> Robot:
        return self.robots[agent]

    def deliver(self, lose: frozenset[str] = frozenset()) -> int:
        """Deliver every new signal to every other robot; returns how many went out."""
        total = 0
        moving = True
        while moving:
            moving = False
            for agent, robot in self.robots.items():
                new = robot.out.signals[self._delivered[agent] :]
                self._delivered[agent] = len(robot.out.signals)
                for signal in new:
                    total += 1
                    moving = True
                    if agent in lose:
                        continue
                    for other, peer in self.robots.items():
                        if other != agent:
                            peer.engine.hear(signal)
        return total

    def tick(self, seconds: float, step: float = 0.1) -> None:
        end = self.clock.now + seconds
        while self.clock.now < end - 1e-9:
            self.clock.now = min(end, self.clock.now + step)
            for robot in self.robots.values():
                robot.engine.tick()
            self.deliver()


def barrier_of(*members: tuple[str, str], barrier_id: str = "B") -> BarrierInfo:
    return BarrierInfo(barrier_id, tuple(members))


@pytest.fixture
def pair() -> Team:
    """r1 holds [a1 (1 s), b1 (barrier)], r2 holds [a2 (3 s), b2 (barrier)]."""
    team = Team("r1", "r2")
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    team["r1"].upload(
        make_skill("a1", agent="r1"), make_skill("b1", agent="r1"), barriers=(barrier,)
    )
    team["r2"].upload(
        make_skill("a2", agent="r2", params={"duration": 3.0}),
        make_skill("b2", agent="r2"),
        barriers=(barrier,),
    )
    return team


def test_the_first_robot_waits_at_the_barrier_until_the_peer_arrives(pair: Team) -> None:
    pair["r1"].send(K.START)
    pair["r2"].send(K.START)
    pair.tick(1.0)
    r1 = pair["r1"]
    assert r1.status("b1") is S.SYNCWAITING
    assert r1.skill("b1").status_text == "waiting on r2 at B"
    assert r1.engine.snapshot().waiting_on == "r2 at B"
    assert r1.engine.state_name() == "waiting"
    pair.tick(1.9)
    assert r1.status("b1") is S.SYNCWAITING
    assert pair["r2"].status("a2") is S.RUNNING
    pair.tick(0.1)
    assert r1.status("b1") is S.RUNNING and pair["r2"].status("b2") is S.RUNNING
    assert r1.skill("b1").started == pair["r2"].skill("b2").started
    assert r1.out.trail("b1") == [S.SYNCWAITING, S.RUNNING]
    assert r1.skill("b1").status_text == ""


def test_a_waiting_robot_reannounces_ready(pair: Team) -> None:
    r1 = pair["r1"]
    r1.send(K.START)
    r1.run_for(1.0)
    ready = [s for s in r1.out.signals if s.kind is SignalKind.READY]
    assert len(ready) == 1 and ready[0] == Signal("r1", "B", "b1", SignalKind.READY, 1001.0)
    r1.run_for(2.0, step=0.25)
    stamps = [s.stamp for s in r1.out.signals if s.kind is SignalKind.READY]
    assert len(stamps) == 1 + int(2.0 / ANNOUNCE_PERIOD)
    assert all(b - a == pytest.approx(ANNOUNCE_PERIOD) for a, b in itertools.pairwise(stamps))


def test_the_last_robot_to_arrive_releases_the_barrier(pair: Team) -> None:
    pair["r1"].send(K.START)
    pair.tick(1.0)
    pair["r2"].send(K.START)  # r2 runs a2 first
    pair.tick(3.0)
    kinds = [(s.agent, s.kind) for r in pair.robots.values() for s in r.out.signals]
    assert ("r2", SignalKind.RELEASED) in kinds
    assert pair["r1"].status("b1") is S.RUNNING


def test_released_lets_a_robot_start_that_missed_the_others_ready() -> None:
    robot = Robot("r3")
    barrier = barrier_of(("x1", "r1"), ("x2", "r2"), ("x3", "r3"))
    robot.upload(make_skill("x3", agent="r3"), barriers=(barrier,))
    robot.send(K.START)
    robot.engine.hear(Signal("r1", "B", "x1", SignalKind.READY, 0.0))
    assert robot.engine.snapshot().waiting_on == "r2 at B; r1 at B (arrived, not yet confirmed)"
    # r1 heard r2 (this robot did not) and started: everybody was ready.
    robot.engine.hear(Signal("r1", "B", "x1", SignalKind.RELEASED, 0.0))
    assert robot.status("x3") is S.RUNNING


def test_three_robots_release_together() -> None:
    team = Team("r1", "r2", "r3")
    barrier = barrier_of(("x1", "r1"), ("x2", "r2"), ("x3", "r3"))
    for agent in ("r1", "r2", "r3"):
        team[agent].upload(make_skill(f"x{agent[1]}", agent=agent), barriers=(barrier,))
    team["r1"].send(K.START)
    team["r2"].send(K.START)
    team.deliver()
    assert team["r1"].engine.snapshot().waiting_on == (
        "r3 at B; r2 at B (arrived, not yet confirmed)"
    )
    team["r3"].send(K.START)
    team.deliver()
    assert [team[a].status(f"x{a[1]}") for a in ("r1", "r2", "r3")] == [S.RUNNING] * 3
    assert len({team[a].skill(f"x{a[1]}").started for a in ("r1", "r2", "r3")}) == 1


def test_peers_arriving_one_by_one_cost_no_reports() -> None:
    agents = [f"r{i}" for i in range(1, 7)]
    team = Team(*agents)
    barrier = barrier_of(*((f"x{a}", a) for a in agents))
    for agent in agents:
        team[agent].upload(make_skill(f"x{agent}", agent=agent), barriers=(barrier,))
    for agent in agents:
        team[agent].send(K.START)
        team.deliver()
    first = team["r1"]
    assert [(r.status, r.status_text) for r in first.out.reports] == [
        (S.SYNCWAITING, "waiting on r2, r3, r4, r5, r6 at B"),
        (S.RUNNING, ""),
    ]
    assert all(team[a].status(f"x{a}") is S.RUNNING for a in agents)


def test_own_signals_are_ignored(robot: Robot) -> None:
    barrier = barrier_of(("a", "r1"), ("x", "r2"))
    robot.upload(make_skill("a"), barriers=(barrier,))
    robot.send(K.START)
    robot.engine.hear(Signal("r1", "B", "a", SignalKind.RELEASED, 0.0))
    assert robot.status("a") is S.SYNCWAITING


def test_a_signal_for_another_barrier_does_not_release(robot: Robot) -> None:
    barrier = barrier_of(("a", "r1"), ("x", "r2"))
    robot.upload(make_skill("a"), barriers=(barrier,))
    robot.send(K.START)
    robot.engine.hear(Signal("r2", "OTHER", "y", SignalKind.RELEASED, 0.0))
    assert robot.status("a") is S.SYNCWAITING


def test_withdrawal_keeps_the_peer_waiting(pair: Team) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    pair.tick(1.0)
    assert r1.status("b1") is S.SYNCWAITING
    r1.send(K.PAUSE)
    assert r1.status("b1") is S.PAUSED
    assert r1.out.signals[-1].kind is SignalKind.WITHDRAWN
    pair.deliver()
    r2.send(K.START)
    pair.tick(3.0)
    assert r2.status("b2") is S.SYNCWAITING  # r1 withdrew: no release
    assert r2.skill("b2").status_text == "waiting on r1 at B"
    pair.tick(2.0)
    assert r1.status("b1") is S.PAUSED  # paused robots do not re-announce or release
    assert r2.status("b2") is S.SYNCWAITING


def test_resume_at_a_barrier_returns_to_waiting_then_releases(pair: Team) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    r2.send(K.START)
    pair.tick(1.0)
    r1.send(K.PAUSE)
    pair.tick(0.5)
    r1.send(K.RESUME)
    pair.deliver()
    assert r1.status("b1") is S.SYNCWAITING  # not RUNNING: r2 is not there yet
    assert r1.out.trail("b1") == [S.SYNCWAITING, S.PAUSED, S.SYNCWAITING]
    pair.tick(1.5)
    assert r1.status("b1") is S.RUNNING and r2.status("b2") is S.RUNNING


def test_pause_while_the_peer_arrives_then_resume_releases_at_once(pair: Team) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    r2.send(K.START)
    pair.tick(1.0)
    r1.send(K.PAUSE)
    pair.tick(2.5)
    assert r2.status("b2") is S.SYNCWAITING and r1.status("b1") is S.PAUSED
    r1.send(K.RESUME)
    pair.deliver()
    assert r1.status("b1") is S.RUNNING and r2.status("b2") is S.RUNNING


def test_stop_at_a_barrier_withdraws(pair: Team) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    pair.tick(1.0)
    r1.send(K.STOP)
    assert r1.status("b1") is S.IDLE_SYNCHRONIZED
    assert r1.out.signals[-1].kind is SignalKind.WITHDRAWN
    r2.send(K.START)
    pair.tick(3.5)
    assert r2.status("b2") is S.SYNCWAITING
    r1.send(K.START)
    pair.deliver()
    assert r1.status("b1") is S.RUNNING and r2.status("b2") is S.RUNNING


def test_a_barrier_with_a_stopped_peer_never_releases(pair: Team) -> None:
    pair["r1"].send(K.START)
    pair.tick(10.0)
    assert pair["r1"].status("b1") is S.SYNCWAITING


# -- a member that fails at its barrier: the wait timeout, retry and skip -------------------
def waiting_team(timeout: float = 2.0) -> Team:
    """r1 holds b1 (its wait bounded by ``timeout``), r2 holds a2 (3 s) then b2; one barrier."""
    team = Team("r1", "r2")
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    team["r1"].upload(make_skill("b1", agent="r1", timeout=timeout), barriers=(barrier,))
    team["r2"].upload(
        make_skill("a2", agent="r2", params={"duration": 3.0}),
        make_skill("b2", agent="r2"),
        barriers=(barrier,),
    )
    return team


def retry_b1(team: Team, barriers_first: bool) -> None:
    """The ground's retry of b1 as b1x: new barrier sets for both robots and the RETRY."""
    rejoined = barrier_of(("b1x", "r1"), ("b2", "r2"))
    fresh = replace(make_skill("b1x", agent="r1"), attempt=2)
    if barriers_first:
        team["r1"].send(K.BARRIERS, barriers=(rejoined,))
    team["r1"].send(K.RETRY, skill_ids=("b1",), skills=(fresh,))
    team.deliver()
    team["r2"].send(K.BARRIERS, barriers=(rejoined,))
    team.deliver()


def test_a_member_gives_up_waiting_after_its_timeout_and_withdraws() -> None:
    team = waiting_team(timeout=2.0)
    r1 = team["r1"]
    r1.send(K.START)
    team.tick(1.9)
    assert r1.status("b1") is S.SYNCWAITING
    team.tick(0.1)
    assert r1.status("b1") is S.FAILURE
    assert r1.skill("b1").status_text == "timed out after 2 s waiting at barrier 'B' for r2"
    assert r1.out.signals[-1].kind is SignalKind.WITHDRAWN
    assert r1.out.trail("b1") == [S.SYNCWAITING, S.FAILURE]
    assert r1.engine.state_name() == "holding"  # no automatic retry of a wait


def test_paused_time_does_not_count_against_the_wait_timeout() -> None:
    team = waiting_team(timeout=2.0)
    r1 = team["r1"]
    r1.send(K.START)
    team.tick(1.5)
    r1.send(K.PAUSE)
    team.tick(10.0)
    r1.send(K.RESUME)
    team.tick(0.4)
    assert r1.status("b1") is S.SYNCWAITING
    team.tick(0.1)
    assert r1.status("b1") is S.FAILURE


@pytest.mark.parametrize("barriers_first", [True, False], ids=["barriers-first", "retry-first"])
def test_a_retried_member_rejoins_and_starts_with_the_waiting_partner(
    barriers_first: bool,
) -> None:
    team = waiting_team(timeout=2.0)
    r1, r2 = team["r1"], team["r2"]
    r1.send(K.START)
    r2.send(K.START)
    team.tick(3.5)  # r1 gave up at 2 s; r2 reached b2 at 3 s and waits for r1
    assert r1.status("b1") is S.FAILURE
    assert r2.status("b2") is S.SYNCWAITING and r2.skill("b2").status_text == "waiting on r1 at B"
    retry_b1(team, barriers_first)
    assert r1.status("b1x") is S.RUNNING and r2.status("b2") is S.RUNNING
    assert r1.skill("b1x").started == r2.skill("b2").started
    assert r1.out.trail("b1x") == [S.SYNCWAITING, S.RUNNING]
    assert r1.engine.board.barrier_of("b1") is None


def test_a_retry_after_the_release_runs_alone() -> None:
    team = Team("r1", "r2")
    r1, r2 = team["r1"], team["r2"]
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    probe = make_skill("b1", "probe", agent="r1", params={"duration": 0.5, "fail": True})
    r1.upload(probe, barriers=(barrier,))
    r2.upload(make_skill("b2", agent="r2"), barriers=(barrier,))
    r2.send(K.START)
    team.deliver()
    r1.send(K.START)  # r2 is ready: r1 confirms, r2 starts on it
    team.deliver(lose=frozenset({"r2"}))  # r1 never hears r2's CONFIRMED or RELEASED
    assert r1.status("b1") is S.SYNCWAITING and r2.status("b2") is S.RUNNING
    team.tick(0.5)  # r1's next CONFIRMED reaches r2, which answers RELEASED
    assert r1.status("b1") is S.RUNNING
    team.tick(1.0)
    assert r1.status("b1") is S.FAILURE and r2.status("b2") is S.SUCCESS
    signals = len(r1.out.signals)
    fresh = replace(probe, id="b1x", attempt=2, params={"duration": 0.5})
    r1.send(K.RETRY, skill_ids=("b1",), skills=(fresh,))  # the ground leaves the barrier be
    assert r1.status("b1x") is S.RUNNING  # at once: it released once, it waits for nobody
    assert r1.out.signals[signals:] == []


def test_a_waiting_partner_goes_on_when_the_failed_member_is_skipped() -> None:
    team = waiting_team(timeout=1.0)
    r1, r2 = team["r1"], team["r2"]
    r1.send(K.START)
    r2.send(K.START)
    team.tick(3.5)
    assert r1.status("b1") is S.FAILURE and r2.status("b2") is S.SYNCWAITING
    r2.send(K.BARRIERS, barriers=())  # the ground dissolved the barrier
    r1.send(K.SKIP, skill_ids=("b1",))
    assert r2.status("b2") is S.RUNNING


# -- lost-link policy ------------------------------------------------------------------------
def hold_after(seconds: float) -> str:
    return json.dumps({"lost_link": {"policy": "hold", "after": seconds}})


def test_hold_after_losing_the_ground(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=hold_after(5))
    robot.upload(make_skill("a", params={"duration": 20.0}))
    robot.send(K.START)
    robot.run_for(4.9)
    assert robot.status("a") is S.RUNNING
    robot.run_for(0.2)
    assert robot.status("a") is S.PAUSED
    assert robot.skill("a").status_text == "held after 5 s without ground contact"
    assert policy_words(robot.engine) == (
        "on link loss: hold after 5 s; held after 5 s without ground contact"
    )
    robot.engine.report_acknowledged(0)  # the ground is back
    assert policy_words(robot.engine).endswith("; ground contact is back")
    robot.run_for(10.0)
    assert robot.status("a") is S.PAUSED  # the operator decides when to go on
    robot.send(K.RESUME)
    assert robot.status("a") is S.RUNNING


def test_report_acks_keep_the_link_alive(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=hold_after(2))
    robot.upload(make_skill("a", params={"duration": 20.0}))
    robot.send(K.START)
    for _ in range(10):
        robot.run_for(1.0)
        robot.engine.report_acknowledged(robot.engine.ledger.last_report_seq)
    assert robot.status("a") is S.RUNNING


def test_hold_triggers_once_per_outage(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=hold_after(1))
    robot.upload(make_skill("a", params={"duration": 20.0}))
    robot.send(K.START)
    robot.run_for(1.5)
    robot.send(K.RESUME)
    robot.run_for(0.5)
    assert robot.status("a") is S.RUNNING
    robot.run_for(1.0)
    assert robot.status("a") is S.PAUSED  # a second outage holds again


def test_hold_at_a_barrier_withdraws(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=hold_after(1))
    robot.upload(make_skill("a"), barriers=(barrier_of(("a", "r1"), ("x", "r2")),))
    robot.send(K.START)
    robot.run_for(1.1)
    assert robot.status("a") is S.PAUSED
    assert robot.out.signals[-1].kind is SignalKind.WITHDRAWN


def test_continue_never_holds(robot: Robot) -> None:
    robot.upload(make_skill("a", params={"duration": 200.0}))
    robot.send(K.START)
    robot.run_for(150.0, step=1.0)
    assert robot.status("a") is S.RUNNING


def test_safe_skill_runs_then_holds(robot: Robot) -> None:
    argument = json.dumps(
        {"lost_link": {"policy": "safe_skill", "after": 2, "skill": "home", "params": {}}}
    )
    robot.send(K.SET_OPTIONS, argument=argument)
    robot.upload(make_skill("a", params={"duration": 20.0}), make_skill("b"))
    robot.send(K.START)
    robot.run_for(2.05)
    assert robot.status("a") is S.PAUSED
    assert robot.engine.state_name() == "contingency"
    home = Timed.instances[-1]
    assert home.ctx is not None and home.ctx.skill_id == ""
    robot.run_for(1.0)  # "home" takes its default second
    assert robot.engine.state_name() == "paused"
    assert robot.engine.lost_link.note.endswith("(done); holding")
    assert robot.status("a") is S.PAUSED and robot.status("b") is S.IDLE_SYNCHRONIZED
    robot.send(K.RESUME)
    assert robot.status("a") is S.RUNNING
    assert "holding" not in policy_words(robot.engine)  # what it did is over


def test_a_robot_started_while_its_safe_skill_runs_goes_on_after_it(robot: Robot) -> None:
    argument = json.dumps(
        {"lost_link": {"policy": "safe_skill", "after": 2, "skill": "home", "params": {}}}
    )
    robot.send(K.SET_OPTIONS, argument=argument)
    robot.upload(make_skill("a", params={"duration": 20.0}))
    robot.send(K.START)
    robot.run_for(2.05)
    robot.send(K.START)  # the operator, heard again, has it go on
    assert robot.engine.state_name() == "contingency"
    assert robot.engine.lost_link.note.startswith("ran 'home'")
    robot.run_for(1.0)
    assert robot.status("a") is S.RUNNING
    assert robot.engine.lost_link.note == ""


def test_safe_skill_is_not_run_with_nothing_to_do(robot: Robot) -> None:
    argument = json.dumps({"lost_link": {"policy": "safe_skill", "after": 1, "skill": "home"}})
    robot.send(K.SET_OPTIONS, argument=argument)
    robot.send(K.START)
    robot.run_for(1.5)
    assert robot.engine.state_name() == "paused"
    assert robot.engine.lost_link.note == "held after 1 s without ground contact"
    assert Timed.instances == []


# -- the state file ------------------------------------------------------------------------
def restart(robot: Robot, path: Path, agent: str = "r1") -> tuple[Robot, list[str]]:
    """Save ``robot``'s state, then load it into a fresh engine on the same clock."""
    save_state(robot.engine, path)
    fresh = Robot(agent, robot.clock)
    interrupted = load_state(fresh.engine, path)
    fresh.seq = fresh.engine.commands.last_seq
    return fresh, interrupted


def test_state_round_trip_keeps_queue_reports_answers_barriers_and_policy(
    robot: Robot, tmp_path: Path
) -> None:
    path = tmp_path / "state" / "r1.json"
    robot.send(K.SET_OPTIONS, argument=hold_after(30))
    robot.upload(
        make_skill("p", "probe", params={"duration": 0.1, "fail": True}, label="Probe it"),
        make_skill("g", "goto", params={"target": Pose(1.0, 2.0, 0.5, yaw=1.5)}, timeout=9.0),
        make_skill("c", "count", params={"steps": 2, "period": 0.5}, max_retries=3),
        barriers=(barrier_of(("c", "r1"), ("y", "r2")),),
    )
    robot.engine.hear(Signal("r2", "B", "y", SignalKind.RELEASED, 0.0))
    robot.send(K.START)
    robot.run_for(0.1)
    robot.send(K.SKIP, skill_ids=("p",))
    robot.engine.report_acknowledged(1)
    fresh, interrupted = restart(robot, path)
    engine = fresh.engine
    assert interrupted == ["g"]
    assert [s.id for s in engine.ledger.queue] == ["p", "g", "c"]
    # status, resolution, texts, stamps
    assert engine.ledger.queue[0] == robot.engine.ledger.queue[0]
    assert engine.ledger.queue[1].params["target"] == Pose(1.0, 2.0, 0.5, yaw=1.5)
    assert engine.ledger.queue[1].timeout == 9.0 and engine.ledger.queue[2].max_retries == 3
    assert engine.ledger.queue[2] == robot.engine.ledger.queue[2]
    assert engine.lost_link.policy == robot.engine.lost_link.policy
    assert engine.board.barriers == robot.engine.board.barriers
    assert engine.board.may_start(barrier_of(("c", "r1"), ("y", "r2")), 0.0)  # RELEASED kept
    assert engine.commands.last_seq == robot.engine.commands.last_seq
    assert engine.commands.acks == robot.engine.commands.acks
    assert engine.mode is Mode.STOPPED  # a restarted robot waits for the operator


def test_the_interrupted_skill_returns_to_idle_synchronized(robot: Robot, tmp_path: Path) -> None:
    robot.upload(make_skill("a", params={"duration": 0.5}), make_skill("b"), make_skill("c"))
    robot.send(K.START)
    robot.run_for(0.7)
    assert robot.status("b") is S.RUNNING
    fresh, interrupted = restart(robot, tmp_path / "r1.json")
    assert interrupted == ["b"]
    b = fresh.skill("b")
    assert (b.status, b.started, b.status_text) == (
        S.IDLE_SYNCHRONIZED,
        0.0,
        "interrupted by an executor restart",
    )
    assert fresh.status("a") is S.SUCCESS
    # The unacknowledged reports survive, and numbering goes on after them.
    assert [r.seq for r in fresh.engine.ledger.unacked] == [1, 2, 3, 4]
    assert fresh.out.reports[-1].seq == 4 and fresh.out.reports[-1].skill_id == "b"
    assert fresh.engine.state_name() == "stopped"
    fresh.send(K.START)
    fresh.run_for(2.5)
    assert [fresh.status(i) for i in "abc"] == [S.SUCCESS] * 3


def test_a_duplicate_after_a_restart_gets_the_original_answer(robot: Robot, tmp_path: Path) -> None:
    command = Command(1, K.UPLOAD, skills=(make_skill("a"), make_skill("t", "teleport")))
    first = robot.engine.handle_command(command)
    fresh, _ = restart(robot, tmp_path / "r1.json")
    assert fresh.engine.handle_command(command) == first
    assert fresh.ids() == ["a"]


def test_a_paused_robot_stays_paused_after_a_restart(robot: Robot, tmp_path: Path) -> None:
    robot.upload(make_skill("a"))
    robot.send(K.START)
    robot.send(K.PAUSE)
    fresh, interrupted = restart(robot, tmp_path / "r1.json")
    assert interrupted == ["a"] and fresh.engine.mode is Mode.PAUSED
    fresh.send(K.RESUME)
    assert fresh.status("a") is S.RUNNING


def test_a_restart_while_waiting_at_a_barrier_withdraws(pair: Team, tmp_path: Path) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    r2.send(K.START)
    pair.tick(1.0)
    assert r1.status("b1") is S.SYNCWAITING  # and r2 has heard it
    fresh, interrupted = restart(r1, tmp_path / "r1.json")
    assert interrupted == ["b1"]
    assert fresh.out.signals == [Signal("r1", "B", "b1", SignalKind.WITHDRAWN, 1001.0)]
    pair.robots["r1"] = fresh
    pair._delivered["r1"] = 0
    pair.deliver()
    pair.tick(2.5)
    assert r2.status("b2") is S.SYNCWAITING, "r2 must not start while r1 is stopped"
    fresh.send(K.START)
    pair.deliver()
    assert fresh.status("b1") is S.RUNNING and r2.status("b2") is S.RUNNING


def test_a_ready_that_is_not_repeated_expires(pair: Team) -> None:
    """A peer that died while waiting cannot withdraw; its READY must not count for ever."""
    r1, r2 = pair["r1"], pair["r2"]
    r1.send(K.START)
    r2.send(K.START)
    pair.tick(1.0)
    del pair.robots["r1"]  # killed: no WITHDRAWN, no more READY
    pair.tick(2.5)
    assert r2.status("b2") is S.SYNCWAITING
    assert r2.skill("b2").status_text == "waiting on r1 at B"


def test_a_restarted_robot_hears_readiness_afresh(pair: Team, tmp_path: Path) -> None:
    r1, r2 = pair["r1"], pair["r2"]
    r2.send(K.START)
    r1.send(K.START)
    pair.tick(1.0)
    r1.send(K.STOP)
    pair.deliver()
    fresh, _ = restart(r1, tmp_path / "r1.json")
    pair.robots["r1"] = fresh
    pair._delivered["r1"] = 0
    pair.tick(1.5)  # r2 is busy with a2 until 3 s: it says nothing about b2 yet
    fresh.send(K.START)
    assert fresh.status("b1") is S.SYNCWAITING
    pair.tick(0.6)
    assert fresh.status("b1") is S.RUNNING and r2.status("b2") is S.RUNNING


def test_peer_readiness_is_not_restored_after_a_restart(tmp_path: Path) -> None:
    team = Team("r1", "r2")
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    r1, r2 = team["r1"], team["r2"]
    r1.upload(make_skill("a1", agent="r1"), make_skill("b1", agent="r1"), barriers=(barrier,))
    r2.upload(make_skill("b2", agent="r2"), barriers=(barrier,))
    r1.send(K.START)
    r2.send(K.START)
    team.tick(0.5)  # r1 runs a1 and has heard r2 ready at b2
    save_state(r1.engine, tmp_path / "r1.json")
    del team.robots["r1"]  # r1 is down ...
    r2.send(K.PAUSE)  # ... and misses r2 withdrawing
    team.deliver()
    fresh = Robot("r1", team.clock)
    load_state(fresh.engine, tmp_path / "r1.json")
    fresh.seq = fresh.engine.commands.last_seq
    team.robots["r1"] = fresh
    team._delivered["r1"] = 0
    fresh.send(K.START)
    team.tick(1.1)
    assert fresh.status("a1") is S.SUCCESS
    assert fresh.status("b1") is S.SYNCWAITING  # r2 is paused: no release


def test_loading_refuses_another_agent_or_version(robot: Robot, tmp_path: Path) -> None:
    path = tmp_path / "r1.json"
    save_state(robot.engine, path)
    with pytest.raises(ValueError, match="holds the state of 'r1', not 'r2'"):
        load_state(Robot("r2").engine, path)
    data = json.loads(path.read_text())
    data["rosmc_executor"] = 99
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="not an executor state file of version 1"):
        load_state(Robot("r1").engine, path)


def test_saving_is_atomic_and_leaves_no_temporary_file(robot: Robot, tmp_path: Path) -> None:
    robot.upload(make_skill("a"))
    save_state(robot.engine, tmp_path / "r1.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r1.json"]


def test_the_snapshot_says_since_when_it_waits_at_its_barrier() -> None:
    robot = Robot("r1")
    barrier = BarrierInfo("B", (("a", "r1"), ("x", "r2")))
    robot.upload(make_skill("a"), barriers=(barrier,))
    assert robot.engine.snapshot().waiting_since == 0.0
    arrived = robot.clock.now
    robot.send(K.START)
    robot.run_for(5.0)
    snapshot = robot.engine.snapshot()
    assert snapshot.waiting_on == "r2 at B" and snapshot.waiting_since == arrived
    assert snapshot.stamp - snapshot.waiting_since == 5.0  # its age, on its own clock
    robot.send(K.PAUSE)  # paused: it does not wait at the barrier
    assert robot.engine.snapshot().waiting_since == 0.0


def test_a_hold_after_the_policy_is_reported_until_the_operator_starts_it(robot: Robot) -> None:
    robot.send(K.SET_OPTIONS, argument=json.dumps({"lost_link": {"policy": "hold", "after": 5}}))
    robot.upload(make_skill("a", params={"duration": 30.0}))
    robot.send(K.START)
    robot.run_for(4.0)
    assert robot.engine.snapshot().hold is HoldCause.NONE
    robot.run_for(2.0)  # 6 s without the ground: the policy holds it
    assert robot.status("a") is S.PAUSED
    assert robot.engine.snapshot().hold is HoldCause.LOST_LINK
    robot.send(K.PAUSE)  # an operator's pause keeps it held for the same reason
    assert robot.engine.snapshot().hold is HoldCause.LOST_LINK
    robot.send(K.RESUME)
    assert robot.status("a") is S.RUNNING and robot.engine.snapshot().hold is HoldCause.NONE


def test_a_hold_survives_an_executor_restart(robot: Robot, tmp_path: Path) -> None:
    robot.send(K.SET_OPTIONS, argument=json.dumps({"lost_link": {"policy": "hold", "after": 5}}))
    robot.upload(make_skill("a", params={"duration": 30.0}))
    robot.send(K.START)
    robot.run_for(6.0)
    assert robot.engine.snapshot().hold is HoldCause.LOST_LINK
    save_state(robot.engine, tmp_path / "r1.json")
    fresh = Robot()
    load_state(fresh.engine, tmp_path / "r1.json")
    assert fresh.engine.snapshot().hold is HoldCause.LOST_LINK, "still paused: still held"
    fresh.seq = robot.seq  # the ground numbers on
    fresh.send(K.START)
    assert fresh.engine.snapshot().hold is HoldCause.NONE
