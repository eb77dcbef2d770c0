"""The executor engine: runs a robot's synchronized skills in order, without the ground.

It reacts to numbered ground commands (executing each once, answering
duplicates with the stored answer), to peers' barrier signals, and to time
(:meth:`Engine.tick`: skill progress, timeouts, retries, lost-link policy).
Every status change becomes a numbered report (:mod:`.ledger`) kept until the ground
acknowledges it, so an outage delays reports but never loses or reorders them.
The engine is single-threaded; the ROS adapter serializes calls with a lock.
Skills may report progress from threads of their own: that is queued and
applied by the next :meth:`Engine.tick`.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable, Mapping
from typing import Protocol

from rosmc_server.core import SkillStatus
from rosmc_server.core.model.control import ExecutorState, HoldCause
from rosmc_server.core.robots.protocol import (
    Ack,
    BarrierInfo,
    Command,
    Mode,
    Signal,
    SignalKind,
    Snapshot,
)

from . import commanding, queueing, reporting
from .active import ActiveSkill
from .barrier_wait import ANNOUNCE_PERIOD, BarrierWaits
from .barriers import BarrierBoard
from .ledger import KEPT_ACKS, CommandLog, ReportOutputs, SkillLedger
from .lost_link import LostLinkGuard, PoseSource, no_pose
from .progress import ProgressBox
from .skills import Outcome, SkillContext, SkillType

_log = logging.getLogger(__name__)
S = SkillStatus
__all__ = ["ANNOUNCE_PERIOD", "KEPT_ACKS", "Engine", "EngineOutputs", "Mode"]


class EngineOutputs(ReportOutputs, Protocol):
    """Where the engine's messages go (the ROS adapter publishes them).

    Status reports (also kept in ``Engine.ledger.unacked`` until acknowledged) and state
    changes to persist, as :class:`~.ledger.ReportOutputs`; and barrier signals.
    """

    def signal(self, signal: Signal) -> None:
        """A barrier signal for the peers."""


class Engine:
    """One robot's mission executor.

    The ground commands (:mod:`.commanding`) work through its public surface: the
    ``queue``, the barrier ``board``, :meth:`advance`, :meth:`start`, :meth:`pause`,
    :meth:`stop`, :meth:`set_barriers`, :attr:`active_skill_id` and ``lost_link.policy``.

    ``clock`` is mission time (skills, timeouts, report stamps; sim time in simulation);
    ``pace_clock`` paces progress texts and ``link_clock`` measures ground contact, both
    steady wall clocks on a robot (each defaults to ``clock``).
    """

    def __init__(
        self,
        agent: str,
        skill_types: Mapping[str, SkillType],
        clock: Callable[[], float],
        outputs: EngineOutputs,
        pose_source: PoseSource = no_pose,
        pace_clock: Callable[[], float] | None = None,
        link_clock: Callable[[], float] | None = None,
    ) -> None:
        self.agent = agent
        self.skill_types = dict(skill_types)
        self.clock = clock
        self.outputs = outputs
        self.ledger = SkillLedger(clock, outputs)
        self.mode = Mode.STOPPED
        self.commands = CommandLog()
        self.board = BarrierBoard(agent)
        self.waits = BarrierWaits(agent, self.board, clock, outputs.signal)
        self.lost_link = LostLinkGuard(agent, clock, self.skill_types, pose_source, link_clock)
        self._active: ActiveSkill | None = None
        # Progress texts from skill threads, applied by tick() at most once a period.
        self._progress_box = ProgressBox(pace_clock or clock)

    # -- ground commands -----------------------------------------------------------
    def handle_command(self, cmd: Command) -> Ack | None:
        """Execute the next command once; answer duplicates again; ignore early ones."""
        return self._numbered(cmd.seq, lambda: self._execute(cmd))

    def refuse_command(self, seq: int, error: str) -> Ack | None:
        """Answer a command that could not be read: numbered like any other, not executed.

        Refusing it (rather than staying silent) keeps the link going: the ground
        learns why, and the commands after it are not held up for ever.
        """
        return self._numbered(seq, lambda: self._ack(seq, error=error, rejected_ids=("command",)))

    def _numbered(self, seq: int, answer: Callable[[], Ack]) -> Ack | None:
        self.ground_contact()
        done = self.commands.last_seq
        ack = self.commands.answer(seq, answer, lambda: self._ack(seq, error="already executed"))
        if self.commands.last_seq != done:
            self.outputs.changed()  # a command ran
        return ack

    def _execute(self, cmd: Command) -> Ack:
        return commanding.execute(self, cmd)

    def _ack(self, seq: int, **fields: object) -> Ack:
        return commanding.ack(self, seq, **fields)

    # -- peers and the ground -------------------------------------------------------------
    def hear(self, signal: Signal) -> None:
        """A peer's barrier signal: answered if this robot started there, else weighed."""
        self.waits.hear(signal)
        active = self._active
        if active is not None and active.at_barrier:
            self._try_release(active)

    def report_acknowledged(self, seq: int) -> None:
        """The ground has every report up to ``seq``."""
        self.ground_contact()
        if self.ledger.acknowledged(seq):
            self.outputs.changed()

    def ground_contact(self) -> None:
        """Something arrived from the ground station."""
        if self.lost_link.contact():
            self.outputs.changed()

    # -- time ---------------------------------------------------------------------
    def tick(self) -> None:
        """Advance the active skill, timeouts, retries, announcements and the link policy."""
        now = self.clock()
        self._apply_progress()
        idle = self.idle
        self.lost_link.observe(now)
        if self.lost_link.due(idle):
            self.lost_link.trigger(idle, self.pause)
            self.outputs.changed()
        if self.lost_link.step(now):
            self.outputs.changed()
            if self.mode is Mode.STARTED:  # an operator started it meanwhile: it goes on
                self.lost_link.operator_took_over()
                self.advance()
        active = self._active
        if active is None:
            return
        if active.behavior is not None and self.ledger.status(active.skill_id) is S.RUNNING:
            self._update_running(active, now)
        elif self.ledger.status(active.skill_id) is S.SYNCWAITING:
            if active.deadline and now >= active.deadline and self.waits.may_give_up(active.told):
                self._give_up_waiting(active)
            elif self.waits.reannounce_due(active.told):
                self._announce_wait(active)

    def _update_running(self, active: ActiveSkill, now: float) -> None:
        assert active.behavior is not None
        try:
            outcome = active.behavior.update(now)
        except Exception as error:  # a broken skill implementation fails the skill
            outcome = Outcome.failed(f"skill crashed: {type(error).__name__}: {error}")
        if outcome is not None:
            self._apply_progress(flush=True)  # what the skill said before it finished
        if outcome is None and active.deadline and now >= active.deadline:
            active.behavior.cancel()
            skill = self.ledger.find(active.skill_id)
            outcome = Outcome.failed(
                f"timed out after {skill.timeout:g} s" if skill else "timed out"
            )
        if outcome is not None:
            self._finish(active, outcome)

    # -- execution -------------------------------------------------------------------
    @property
    def idle(self) -> bool:
        """Nothing left to do on its own: no active skill and none it will start.

        That is: the queue is done, the robot holds at a failure, or it is not started.
        """
        if self._active is not None or self.lost_link.contingency is not None:
            return False
        upcoming = queueing.upcoming(self.ledger.queue)
        return upcoming is None or upcoming.status is S.FAILURE or self.mode is not Mode.STARTED

    @property
    def active(self) -> ActiveSkill | None:
        """The skill being worked on (at its barrier, running or paused), if any."""
        return self._active

    @property
    def active_skill_id(self) -> str:
        """The skill being worked on (at its barrier, running or paused); "" if none."""
        return self._active.skill_id if self._active is not None else ""

    def start(self) -> None:
        """Execute: a paused skill resumes (or waits at its barrier again), else the next starts."""
        self.mode = Mode.STARTED
        self.lost_link.operator_took_over()
        active = self._active
        if active is not None and self.ledger.status(active.skill_id) is S.PAUSED:
            self._resume_active(active)
        self.advance()

    def stop(self, why: str) -> None:
        """Stop: the active skill is cancelled and goes back to IDLE_SYNCHRONIZED."""
        self.mode = Mode.STOPPED
        if self._active is not None:
            self._drop_active(self._active, why)

    def set_barriers(self, barriers: tuple[BarrierInfo, ...]) -> None:
        """Replace the barriers the robot knows; a skill waiting at one checks again."""
        self.board.replace(barriers)
        active = self._active
        if active is None or not active.at_barrier:
            return
        active.barrier = self.board.barrier_of(active.skill_id)
        if active.barrier is not None and self.ledger.status(active.skill_id) is S.SYNCWAITING:
            self.ledger.set(active.skill_id, S.SYNCWAITING, text=self.waits.text(active.barrier))
        self._try_release(active)

    def advance(self) -> None:
        """Start the next skill if the robot may execute and nothing is active."""
        if self.mode is not Mode.STARTED or self._active is not None or self.lost_link.contingency:
            return
        upcoming = queueing.upcoming(self.ledger.queue)
        if upcoming is None or upcoming.status is S.FAILURE:
            return  # finished, or holding after a failure
        active = ActiveSkill(upcoming.id, barrier=self.board.barrier_of(upcoming.id))
        self._active = active
        if active.barrier is None:
            self._run(active)
            return
        if upcoming.timeout > 0:  # the timeout bounds the wait too: partners may never come
            active.deadline = self.clock() + upcoming.timeout
        active.waiting_since = self.clock()
        self.ledger.set(upcoming.id, S.SYNCWAITING, text=self.waits.text(active.barrier))
        self._announce_wait(active)
        self._try_release(active)

    def _try_release(self, active: ActiveSkill) -> None:
        if self.mode is not Mode.STARTED:
            return  # paused or stopped: the skill waits for the operator, barrier or not
        barrier = active.barrier
        if barrier is None:
            if active.behavior is None:
                self._run(active)
            return
        if self.waits.try_release(active.skill_id, barrier, active.told):
            self._run(active)

    def _give_up_waiting(self, active: ActiveSkill) -> None:
        """The wait at the barrier outlasted the skill's timeout: it fails, partners are told.

        No automatic retry: those re-run a skill that failed running. The robot holds
        until the operator retries (the fresh instance takes this one's place in the
        barrier) or skips (the barrier goes on without it).
        """
        skill = self.ledger.find(active.skill_id)
        assert skill is not None and active.barrier is not None
        text = self.waits.give_up(skill.id, active.barrier, active.told, skill.timeout)
        self._active = None
        self.ledger.set(skill.id, S.FAILURE, text=text, finished=self.clock())

    def _announce_wait(self, active: ActiveSkill) -> None:
        if active.barrier is not None:
            self.waits.announce_wait(active.skill_id, active.barrier, active.told)

    def _announce(self, active: ActiveSkill, kind: SignalKind) -> None:
        if active.barrier is not None:
            self.waits.announce(active.skill_id, active.barrier, active.told, kind)

    def _run(self, active: ActiveSkill) -> None:
        skill = self.ledger.find(active.skill_id)
        assert skill is not None
        kind = self.skill_types[skill.skill]
        behavior = kind.create()
        now = self.clock()
        ctx = SkillContext(
            self.agent,
            skill.id,
            skill.params,
            skill.attempt + (1 if active.retries_used else 0),  # one more than the last run
            self.clock,
            functools.partial(self._progress_box.put, skill.id),
        )
        active.behavior = behavior
        active.deadline = now + skill.timeout if skill.timeout > 0 else 0.0
        started = now if active.retries_used == 0 else skill.started
        text = f"retry {active.retries_used} of {skill.max_retries}" if active.retries_used else ""
        self.ledger.set(skill.id, S.RUNNING, text=text, started=started, attempt=ctx.attempt)
        try:
            behavior.start(ctx)
        except Exception as error:  # a skill that cannot start fails cleanly
            self._finish(active, Outcome.failed(f"could not start: {error}"))

    def _finish(self, active: ActiveSkill, outcome: Outcome) -> None:
        skill = self.ledger.find(active.skill_id)
        assert skill is not None
        if outcome.success:
            self._active = None
            self.ledger.set(skill.id, S.SUCCESS, text=outcome.reason, finished=self.clock())
            self.advance()
            return
        if active.retries_used < skill.max_retries:
            active.retries_used += 1
            _log.info("%s: '%s' failed (%s); retrying", self.agent, skill.id, outcome.reason)
            self._run(active)
            return
        self._active = None
        self.ledger.set(skill.id, S.FAILURE, text=outcome.reason, finished=self.clock())

    def _apply_progress(self, flush: bool = False) -> None:
        taken = self._progress_box.take(flush)
        if taken is not None:
            self._progress(*taken)

    def _progress(self, skill_id: str, text: str) -> None:
        skill = self.ledger.find(skill_id)
        active = self._active
        if skill is None or active is None or active.skill_id != skill_id:
            return
        if skill.status is S.RUNNING and text != skill.status_text:
            self.ledger.set(skill_id, S.RUNNING, text=text)

    def pause(self, why: str) -> None:
        """Hold the robot: the active skill pauses (or leaves its barrier wait)."""
        self.mode = Mode.PAUSED
        active = self._active
        if active is None:
            return
        status = self.ledger.status(active.skill_id)
        if status is S.RUNNING and active.behavior is not None:
            active.behavior.pause()
        elif status is S.SYNCWAITING:
            self._announce(active, SignalKind.WITHDRAWN)
        else:
            return
        active.paused_at = self.clock()
        active.paused_from = status
        self.ledger.set(active.skill_id, S.PAUSED, text=why)

    def _resume_active(self, active: ActiveSkill) -> None:
        if active.deadline:  # time spent paused counts against no timeout, running or waiting
            active.deadline += self.clock() - active.paused_at
        if active.paused_from is S.RUNNING and active.behavior is not None:
            active.behavior.resume()
            self.ledger.set(active.skill_id, S.RUNNING, text="")
        else:
            if active.barrier is not None:
                # Back to waiting at the barrier, not to PAUSED (and not straight to running).
                waiting = self.waits.text(active.barrier)
                active.waiting_since = self.clock()
                self.ledger.set(active.skill_id, S.SYNCWAITING, text=waiting)
                self._announce_wait(active)
            self._try_release(active)  # runs it if its barrier went away meanwhile
        active.paused_from = None

    def _drop_active(self, active: ActiveSkill, why: str) -> None:
        if active.behavior is not None:
            active.behavior.cancel()
        if active.at_barrier:
            self._announce(active, SignalKind.WITHDRAWN)
        self._active = None
        self.ledger.set(active.skill_id, S.IDLE_SYNCHRONIZED, text=why, started=0.0)

    # -- state ------------------------------------------------------------------------
    def queue_hash(self) -> str:
        """Hash of the ids this robot holds, in order (the ground computes the same)."""
        return self.ledger.queue_hash()

    def state_name(self) -> str:
        """A one-word state for operators (an :class:`ExecutorState`'s word)."""
        return self.state().value

    def state(self) -> ExecutorState:
        """What the executor is doing now."""
        return reporting.executor_state(self)

    def snapshot(self, full: bool = True) -> Snapshot:
        """The state for the periodic snapshot: the queue only if ``full``, its digest always."""
        return reporting.snapshot(self, full)

    def hold(self) -> HoldCause:
        """Why the robot holds after its lost-link policy acted (NONE: it does not).

        Only while it stays paused: an operator's Start or Stop ends the hold.
        """
        return self.lost_link.held if self.mode is Mode.PAUSED else HoldCause.NONE
