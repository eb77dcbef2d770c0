"""The lost-link policy at work on the robot: ground contact, the trigger, the safe skill.

The policy itself (:class:`~rosmc_server.core.policy.LostLinkPolicy`) is the core's,
shared with the server and the operators' tools; this module only runs it.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

from rosmc_server.core import LostLinkKind, LostLinkPolicy

from .skills import SkillBehavior, SkillContext, SkillType

_log = logging.getLogger(__name__)


class LostLinkGuard:
    """Watches the ground link and acts on the robot's lost-link policy.

    Args:
        agent: The robot.
        clock: Seconds (the engine's clock).
        skill_types: The skills the robot implements (the safe skill is one of them).

    Attributes:
        policy: The policy in force.
        note: What the policy did last, for operators ("" until it acted).
        contingency: The safe skill while it runs (the robot is held meanwhile).
    """

    def __init__(
        self, agent: str, clock: Callable[[], float], skill_types: Mapping[str, SkillType]
    ) -> None:
        self.agent = agent
        self.clock = clock
        self.skill_types = skill_types
        self.policy = LostLinkPolicy()
        self.note = ""
        self.contingency: SkillBehavior | None = None
        self._last_contact = clock()
        self._triggered = False

    def contact(self) -> bool:
        """The ground was heard; True if that ends a triggered policy (the note changed)."""
        self._last_contact = self.clock()
        if not self._triggered:
            return False
        self._triggered = False
        self.note += "; ground contact is back"
        return True

    def due(self, now: float) -> bool:
        """Whether the policy acts now: the link has been silent too long, and it has not yet."""
        if self.policy.kind is LostLinkKind.CONTINUE or self._triggered:
            return False
        return now - self._last_contact >= self.policy.after

    def trigger(self, now: float, idle: bool, pause: Callable[[str], None]) -> None:
        """Act: hold the robot with ``pause``, then run the safe skill (unless ``idle``)."""
        silent = now - self._last_contact
        self._triggered = True
        policy = self.policy
        if policy.kind is LostLinkKind.HOLD or idle:
            self.note = f"held after {silent:.0f} s without ground contact"
            pause(self.note)
        else:
            self.note = f"ran '{policy.skill}' after {silent:.0f} s without ground contact"
            pause(self.note)
            kind = self.skill_types[policy.skill]
            self.contingency = kind.create()
            ctx = SkillContext(self.agent, "", kind.coerce(policy.params), 1, self.clock)
            self.contingency.start(ctx)
        _log.warning("%s: %s", self.agent, self.note)

    def step(self, now: float) -> bool:
        """Advance the safe skill; True once it has finished (the robot holds)."""
        if self.contingency is None:
            return False
        outcome = self.contingency.update(now)
        if outcome is None:
            return False
        done = "done" if outcome.success else f"failed: {outcome.reason}"
        self.note += f" ({done}); holding"
        self.contingency = None
        return True

    def describe(self) -> str:
        """The policy in force and what it did, in one line."""
        return self.policy.describe() + (f"; {self.note}" if self.note else "")
