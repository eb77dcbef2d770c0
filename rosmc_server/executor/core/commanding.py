"""What the executor does with each ground command, and its answers.

Every handler takes the engine and one command, changes the robot's queue or
execution through the engine's public surface (:class:`CommandTarget`, which the
:class:`~.engine.Engine` is), and returns the :class:`Ack` the ground receives.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Protocol

from rosmc_server.core import InvalidRequest, LostLinkKind, LostLinkPolicy, SkillInstance
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.protocol import Ack, AckResult, BarrierInfo, Command
from rosmc_server.core.skills.policy import options_from_argument

from . import queueing
from .barriers import BarrierBoard
from .ledger import SkillLedger
from .lost_link import LostLinkGuard, pose_parameter
from .skills import SkillType


class CommandTarget(Protocol):
    """What the ground's commands change on a robot: the engine's public surface."""

    @property
    def ledger(self) -> SkillLedger:
        """The robot's skills in order (and its reports)."""

    @property
    def agent(self) -> str:
        """The robot's name."""

    @property
    def skill_types(self) -> Mapping[str, SkillType]:
        """The skills this robot implements, by name."""

    @property
    def board(self) -> BarrierBoard:
        """The barriers the robot knows."""

    @property
    def lost_link(self) -> LostLinkGuard:
        """What the robot does on its own when out of contact."""

    @property
    def active_skill_id(self) -> str:
        """The skill running (or paused, or waiting at its barrier); "" if none."""

    def queue_hash(self) -> str:
        """The digest of the queue the ground compares with its own."""

    def advance(self) -> None:
        """Start the next skill if the robot is running and none is active."""

    def start(self) -> None:
        """Start (or resume) executing the queue."""

    def pause(self, why: str) -> None:
        """Pause the active skill."""

    def stop(self, why: str) -> None:
        """Stop executing; the active skill goes back to the queue."""

    def set_barriers(self, barriers: tuple[BarrierInfo, ...]) -> None:
        """Replace the barriers the robot knows."""


def execute(engine: CommandTarget, cmd: Command) -> Ack:
    """Run one ground command on the engine and give the robot's answer."""
    handlers: Mapping[CommandKind, Callable[[CommandTarget, Command], Ack]] = {
        CommandKind.UPLOAD: _upload,
        CommandKind.UNSYNC: _unsync,
        CommandKind.START: _start,
        CommandKind.RESUME: _start,
        CommandKind.PAUSE: _pause_command,
        CommandKind.STOP: _stop,
        CommandKind.RETRY: _retry,
        CommandKind.SKIP: _skip,
        CommandKind.BARRIERS: _set_barriers,
        CommandKind.SET_OPTIONS: _set_options,
        CommandKind.SYNC_STATE: _sync_state,
    }
    return handlers[cmd.kind](engine, cmd)


def ack(engine: CommandTarget, seq: int, **fields: object) -> Ack:
    """The answer to command ``seq``: accepted, partly or wholly rejected per ``fields``."""
    rejected = fields.get("rejected_ids", ())
    accepted = fields.get("accepted_ids", ())
    result = AckResult.ACCEPTED
    if rejected:
        result = AckResult.PARTIAL if accepted else AckResult.REJECTED
    return Ack(seq, result, queue_hash=engine.queue_hash(), **fields)  # type: ignore[arg-type]


def _upload(engine: CommandTarget, cmd: Command) -> Ack:
    answer = queueing.upload(engine.ledger.queue, cmd.skills, functools.partial(why_not, engine))
    engine.ledger.queue = answer.queue
    engine.board.replace(cmd.barriers)
    engine.advance()
    return _answer(engine, cmd.seq, answer, error=next(iter(answer.reasons), ""))


def _answer(engine: CommandTarget, seq: int, answer: queueing.Answer, error: str = "") -> Ack:
    return ack(
        engine,
        seq,
        accepted_ids=answer.accepted,
        rejected_ids=answer.rejected,
        rejection_reasons=answer.reasons,
        error=error,
    )


def why_not(engine: CommandTarget, skill: SkillInstance) -> str:
    """Why the robot cannot take ``skill`` ("" if it can)."""
    if skill.agent != engine.agent:
        return f"skill '{skill.id}' is for {skill.agent}, not {engine.agent}"
    kind = engine.skill_types.get(skill.skill)
    if kind is None:
        return f"{engine.agent} does not implement skill '{skill.skill}'"
    return kind.check(skill.params)


def _unsync(engine: CommandTarget, cmd: Command) -> Ack:
    answer = queueing.unsync(engine.ledger.queue, cmd.skill_ids, engine.active_skill_id)
    engine.ledger.queue = answer.queue
    return _answer(engine, cmd.seq, answer)


def _start(engine: CommandTarget, cmd: Command) -> Ack:
    engine.start()
    holding = queueing.holding(engine.ledger.queue)
    note = f"holding after the failure of '{holding.id}': retry or skip it" if holding else ""
    return ack(engine, cmd.seq, error=note)


def _pause_command(engine: CommandTarget, cmd: Command) -> Ack:
    engine.pause("paused by the operator")
    return ack(engine, cmd.seq)


def _stop(engine: CommandTarget, cmd: Command) -> Ack:
    engine.stop("stopped by the operator")
    return ack(engine, cmd.seq)


def _retry(engine: CommandTarget, cmd: Command) -> Ack:
    if not cmd.skill_ids or not cmd.skills:
        return ack(engine, cmd.seq, error="a retry names the failed skill and its new instance")
    answer = queueing.retry(engine.ledger.queue, cmd.skill_ids[0], cmd.skills[0])
    if answer.accepted:
        engine.board.member_retried(cmd.skill_ids[0], cmd.skills[0].id)
    return _queue_changed(engine, cmd.seq, answer)


def _skip(engine: CommandTarget, cmd: Command) -> Ack:
    if not cmd.skill_ids:
        return ack(engine, cmd.seq, error="a skip names the failed skill")
    return _queue_changed(engine, cmd.seq, queueing.skip(engine.ledger.queue, cmd.skill_ids[0]))


def _queue_changed(engine: CommandTarget, seq: int, answer: queueing.Answer) -> Ack:
    engine.ledger.queue = answer.queue
    engine.advance()
    return _answer(engine, seq, answer, error=next(iter(answer.reasons), ""))


def _set_barriers(engine: CommandTarget, cmd: Command) -> Ack:
    engine.set_barriers(cmd.barriers)
    return ack(engine, cmd.seq)


def _set_options(engine: CommandTarget, cmd: Command) -> Ack:
    try:
        policy, default = options_from_argument(cmd.argument)
        check_policy_skill(engine, policy)
    except InvalidRequest as error:
        return ack(engine, cmd.seq, error=str(error), rejected_ids=("options",))
    engine.lost_link.adopt(policy, default)  # a default never replaces an operator's choice
    return ack(engine, cmd.seq)


def check_policy_skill(engine: CommandTarget, policy: LostLinkPolicy) -> None:
    """InvalidRequest unless the robot implements the skill ``policy`` runs, if any."""
    if not policy.kind.runs_skill:
        return
    kind = engine.skill_types.get(policy.skill)
    if kind is None:
        raise InvalidRequest(f"the safe skill {policy.skill!r} is not implemented on this robot")
    if policy.kind is LostLinkKind.RETURN_TO_LINK and not pose_parameter(kind):
        raise InvalidRequest(
            f"the return skill {policy.skill!r} takes no single pose parameter on this robot"
        )


def _sync_state(engine: CommandTarget, cmd: Command) -> Ack:
    """Make the queue the ground's list, keeping whatever has started here."""
    engine.board.replace(cmd.barriers)
    return _queue_changed(
        engine,
        cmd.seq,
        queueing.adopt(engine.ledger.queue, cmd.skills, functools.partial(why_not, engine)),
    )
