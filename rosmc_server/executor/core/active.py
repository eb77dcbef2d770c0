"""The skill an engine is working on: waiting at its barrier, running or paused."""

from __future__ import annotations

from dataclasses import dataclass, field

from rosmc_server.core import SkillStatus
from rosmc_server.core.robots.protocol import BarrierInfo

from .barrier_wait import Announcements
from .skills import SkillBehavior


@dataclass
class ActiveSkill:
    """The engine's one active skill and what it needs to go on with it.

    ``behavior`` is set once the skill runs (before, it waits at ``barrier``);
    ``deadline`` bounds the run or the wait (0: none) and moves on by the time paused;
    ``told`` is what this robot last announced to its barrier partners;
    ``waiting_since`` when (engine clock) it last began waiting at its barrier.
    """

    skill_id: str
    behavior: SkillBehavior | None = None
    barrier: BarrierInfo | None = None
    paused_from: SkillStatus | None = None
    deadline: float = 0.0
    paused_at: float = 0.0
    retries_used: int = 0
    waiting_since: float = 0.0
    told: Announcements = field(default_factory=Announcements)

    @property
    def at_barrier(self) -> bool:
        """Waiting at its barrier: it has one and has not started running."""
        return self.barrier is not None and self.behavior is None
