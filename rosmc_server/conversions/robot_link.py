"""The robot link's protocol objects <-> robot-link and barrier messages.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core (here :mod:`rosmc_server.core.robots.protocol`, which the ground and
the on-robot executor both speak).
"""

from __future__ import annotations

import rosmc.msg as wire

from ..core.robots.commands import CommandKind
from ..core.robots.protocol import Ack, BarrierInfo, Command, Report, Signal, SignalKind, Snapshot
from .mission import skill_from_msg, skill_to_msg
from .policy import policy_in_force_to_msg
from .values import time_to_msg


def command_from_msg(msg: wire.RobotCommand) -> Command:
    """A RobotCommand as an executor command (ValueError if malformed)."""
    try:
        kind = CommandKind(msg.type)
    except ValueError:
        raise ValueError(f"unknown command type {msg.type}") from None
    barriers = []
    for barrier in msg.barriers:
        if len(barrier.agents) != len(barrier.skill_ids):
            raise ValueError(
                f"barrier '{barrier.id}' lists {len(barrier.agents)} agents "
                f"for {len(barrier.skill_ids)} skills"
            )
        members = tuple(zip(barrier.skill_ids, barrier.agents, strict=True))
        barriers.append(BarrierInfo(barrier.id, members))
    return Command(
        seq=msg.seq,
        kind=kind,
        skills=tuple(skill_from_msg(s) for s in msg.skills),
        skill_ids=tuple(msg.skill_ids),
        barriers=tuple(barriers),
        argument=msg.argument,
    )


def ack_to_msg(agent: str, ack: Ack, stamp: float) -> wire.RobotAck:
    """An ack as ``rosmc/RobotAck``."""
    return wire.RobotAck(
        agent=agent,
        seq=ack.seq,
        stamp=time_to_msg(stamp),
        result=int(ack.result),
        error=ack.error,
        accepted_ids=list(ack.accepted_ids),
        rejected_ids=list(ack.rejected_ids),
        rejection_reasons=list(ack.rejection_reasons),
        queue_hash=ack.queue_hash,
    )


def report_to_msg(agent: str, report: Report) -> wire.RobotReport:
    """A report as ``rosmc/RobotReport``."""
    return wire.RobotReport(
        agent=agent,
        seq=report.seq,
        stamp=time_to_msg(report.stamp),
        skill_id=report.skill_id,
        status=wire.SkillStatus(int(report.status)),
        attempt=report.attempt,
        status_text=report.status_text,
        started=report.started,
        finished=report.finished,
    )


def signal_to_msg(signal: Signal) -> wire.BarrierSignal:
    """A barrier signal as ``rosmc/BarrierSignal``."""
    return wire.BarrierSignal(
        agent=signal.agent,
        barrier_id=signal.barrier_id,
        skill_id=signal.skill_id,
        kind=int(signal.kind),
        stamp=time_to_msg(signal.stamp),
    )


def signal_from_msg(msg: wire.BarrierSignal) -> Signal:
    """``rosmc/BarrierSignal`` as a signal (ValueError if malformed)."""
    return Signal(msg.agent, msg.barrier_id, msg.skill_id, SignalKind(msg.kind), msg.stamp.to_sec())


def snapshot_to_msg(agent: str, snapshot: Snapshot) -> wire.ExecutorSnapshot:
    """A snapshot as ``rosmc/ExecutorSnapshot``."""
    return wire.ExecutorSnapshot(
        agent=agent,
        stamp=time_to_msg(snapshot.stamp),
        last_command_seq=snapshot.last_command_seq,
        last_report_seq=snapshot.last_report_seq,
        queue_hash=snapshot.queue_hash,
        queue=[skill_to_msg(s) for s in snapshot.queue],
        state=snapshot.state,
        active_skill_id=snapshot.active_skill_id,
        waiting_on=snapshot.waiting_on,
        policy=policy_in_force_to_msg(snapshot.policy),
        queue_omitted=not snapshot.full,
        status_digest=snapshot.status_digest,
        hold=snapshot.hold.value,
        waiting_since=snapshot.waiting_since,
    )
