"""Executor logic in pure Python: queue, barriers, skills, store-and-forward reports."""

from rosmc_server.core.robots.protocol import (
    Ack,
    AckResult,
    BarrierInfo,
    Command,
    Report,
    Signal,
    SignalKind,
    Snapshot,
)

from .engine import Engine, EngineOutputs
from .skills import Outcome, SkillBehavior, SkillContext, SkillType, ThreadedSkill

__all__ = [
    "Ack",
    "AckResult",
    "BarrierInfo",
    "Command",
    "Engine",
    "EngineOutputs",
    "Outcome",
    "Report",
    "Signal",
    "SignalKind",
    "SkillBehavior",
    "SkillContext",
    "SkillType",
    "Snapshot",
    "ThreadedSkill",
]
