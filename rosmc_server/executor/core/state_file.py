"""The executor's state on the robot's disk, so a reboot does not lose the mission.

Plain JSON written atomically (temporary file + rename). Parameter values keep
their type (a pose stays a pose). A skill that was running when the executor
died cannot be resumed mid-way: it comes back IDLE_SYNCHRONIZED, and the robot
waits for the operator's start.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from rosmc_server.core import (
    LostLinkPolicy,
    Pose,
    Resolution,
    RosmcError,
    SkillInstance,
    SkillStatus,
    Transfer,
)
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.robots.protocol import (
    Ack,
    AckResult,
    BarrierInfo,
    Mode,
    Report,
    Signal,
    SignalKind,
)

from .engine import Engine

STATE_VERSION = 1


def save_state(engine: Engine, path: Path) -> None:
    """Write the engine's state to ``path`` atomically."""
    data = {
        "rosmc_executor": STATE_VERSION,
        "agent": engine.agent,
        "mode": engine.mode.value,
        "last_command_seq": engine.commands.last_seq,
        "last_report_seq": engine.ledger.last_report_seq,
        "queue": [_skill_out(s) for s in engine.ledger.queue],
        "unacked": [_report_out(r) for r in engine.ledger.unacked],
        "acks": [_ack_out(a) for a in engine.commands.acks.values()],
        "barriers": [
            {"id": b.id, "members": [list(m) for m in b.members]}
            for b in engine.board.barriers.values()
        ],
        "board": engine.board.to_dict(),
        "policy": engine.lost_link.policy.to_dict(),
        "policy_note": engine.lost_link.note,
        "policy_default": engine.lost_link.is_default,
        "held": engine.lost_link.held.value,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.tmp")
    with open(temporary, "w", encoding="utf-8") as out:
        json.dump(data, out, separators=(",", ":"))
        out.flush()
        os.fsync(out.fileno())
    temporary.replace(path)


def load_state(engine: Engine, path: Path) -> list[str]:
    """Restore a saved state into a fresh engine; returns ids interrupted by the restart.

    Raises ValueError if the file is not an executor state of this agent.
    """
    data = json.loads(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict) or data.get("rosmc_executor") != STATE_VERSION:
        raise ValueError(f"{path}: not an executor state file of version {STATE_VERSION}")
    if data.get("agent") != engine.agent:
        raise ValueError(f"{path}: holds the state of {data.get('agent')!r}, not {engine.agent!r}")
    engine.ledger.queue = [_skill_in(s, engine.agent) for s in data["queue"]]
    engine.commands.last_seq = int(data["last_command_seq"])
    engine.ledger.last_report_seq = int(data["last_report_seq"])
    engine.ledger.unacked = [_report_in(r) for r in data["unacked"]]
    for ack in data["acks"]:
        engine.commands.acks[int(ack["seq"])] = _ack_in(ack)
    engine.board.replace(
        tuple(
            BarrierInfo(b["id"], tuple((str(m[0]), str(m[1])) for m in b["members"]))
            for b in data["barriers"]
        )
    )
    engine.board.load(data["board"])
    policy = dict(data["policy"])
    if "kind" in policy:  # written before the policy moved into the core
        policy["policy"] = policy.pop("kind")
    try:
        engine.lost_link.policy = LostLinkPolicy.from_dict(policy)
    except RosmcError as error:
        raise ValueError(f"{path}: {error}") from error
    engine.lost_link.note = str(data.get("policy_note", ""))
    engine.lost_link.is_default = data.get("policy_default") is True
    engine.lost_link.held = HoldCause.of(str(data.get("held", "")))  # still paused: still held
    mode = Mode(data["mode"])
    engine.mode = Mode.STOPPED if mode is Mode.STARTED else mode
    return _interrupted_by_restart(engine)


WITHDRAWN = SignalKind.WITHDRAWN


def _interrupted_by_restart(engine: Engine) -> list[str]:
    """Skills that were active go back to IDLE_SYNCHRONIZED; their barrier partners are told."""
    interrupted = [s.id for s in engine.ledger.queue if s.status.is_active]
    for skill_id in interrupted:
        why = "interrupted by an executor restart"
        engine.ledger.set(skill_id, SkillStatus.IDLE_SYNCHRONIZED, text=why, started=0.0)
        barrier = engine.board.barrier_of(skill_id)
        if barrier is not None:  # peers may still count this robot as ready
            now = engine.clock()
            engine.outputs.signal(Signal(engine.agent, barrier.id, skill_id, WITHDRAWN, now))
    return interrupted


def _skill_out(skill: SkillInstance) -> dict[str, Any]:
    return {
        "id": skill.id,
        "skill": skill.skill,
        "label": skill.label,
        "params": {name: _value_out(value) for name, value in skill.params.items()},
        "bindings": dict(skill.bindings),
        "status": skill.status.name,
        "resolution": skill.resolution.name,
        "attempt": skill.attempt,
        "timeout": skill.timeout,
        "max_retries": skill.max_retries,
        "status_text": skill.status_text,
        "started": skill.started,
        "finished": skill.finished,
    }


def _skill_in(data: dict[str, Any], agent: str) -> SkillInstance:
    return SkillInstance(
        id=data["id"],
        agent=agent,
        skill=data["skill"],
        label=data["label"],
        params={name: _value_in(value) for name, value in data["params"].items()},
        bindings=dict(data["bindings"]),
        status=SkillStatus[data["status"]],
        transfer=Transfer.NONE,
        resolution=Resolution[data["resolution"]],
        attempt=int(data["attempt"]),
        timeout=float(data["timeout"]),
        max_retries=int(data["max_retries"]),
        status_text=data["status_text"],
        started=float(data["started"]),
        finished=float(data["finished"]),
    )


def _value_out(value: object) -> dict[str, Any]:
    if isinstance(value, Pose):
        return {"pose": value.to_dict()}
    return {"value": value}


def _value_in(data: dict[str, Any]) -> Any:
    return Pose(**data["pose"]) if "pose" in data else data["value"]


def _report_out(report: Report) -> dict[str, Any]:
    return {
        "seq": report.seq,
        "stamp": report.stamp,
        "skill_id": report.skill_id,
        "status": report.status.name,
        "attempt": report.attempt,
        "status_text": report.status_text,
        "started": report.started,
        "finished": report.finished,
    }


def _report_in(data: dict[str, Any]) -> Report:
    return Report(
        int(data["seq"]),
        float(data["stamp"]),
        data["skill_id"],
        SkillStatus[data["status"]],
        int(data["attempt"]),
        data["status_text"],
        float(data["started"]),
        float(data["finished"]),
    )


def _ack_out(ack: Ack) -> dict[str, Any]:
    return {
        "seq": ack.seq,
        "result": ack.result.name,
        "error": ack.error,
        "accepted_ids": list(ack.accepted_ids),
        "rejected_ids": list(ack.rejected_ids),
        "rejection_reasons": list(ack.rejection_reasons),
        "queue_hash": ack.queue_hash,
    }


def _ack_in(data: dict[str, Any]) -> Ack:
    return Ack(
        int(data["seq"]),
        AckResult[data["result"]],
        data["error"],
        tuple(data["accepted_ids"]),
        tuple(data["rejected_ids"]),
        tuple(data["rejection_reasons"]),
        data["queue_hash"],
    )
