"""The lost-link policy at work on the robot: ground contact, the trigger, the safe skill.

The policy itself (:class:`~rosmc_server.core.skills.policy.LostLinkPolicy`) is the core's,
shared with the server and the operators' tools; this module only runs it.

Where the robot is comes from a :data:`PoseSource` that the robot's integration gives
the executor (the simulator's robots read their odometry): the guard samples it as the
engine ticks (every :data:`POSE_SAMPLE_PERIOD` s) and when the ground is heard, so
``return_to_link`` knows where the robot last had a link. It returns to where it was
:data:`LINK_MARGIN` seconds before the last contact: a link is known lost only some time
after it went, so the very last contact can lie beyond the edge of coverage. The poses
come from the robot's own steady sampling, not only from the moments the ground was
heard: over a poor radio those are seconds apart, and a sim running many times faster
than real time hears the ground once per many simulated seconds.

Two clocks, each for its own purpose. Ground contact is link liveness, so the silence a
policy counts (and the idleness it may add) is measured on the robot's ``link_clock``: a
steady wall clock, as the ground measures a robot's silence and paces its heartbeat. A
radio is silent for wall seconds whatever the simulation's speed; counted in sim seconds,
a loaded machine that delays the heartbeat by half a wall second would look like a minute
without the ground at a real-time factor of 100. Where the robot was is mission time: the
poses are stamped with the engine's ``clock``, like the skills that move it.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable, Mapping

from rosmc_server.core import (
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    ParamType,
    PolicyInForce,
)
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.skills.params import Pose, value_to_data

from .skills import SkillBehavior, SkillContext, SkillType

_log = logging.getLogger(__name__)
LINK_MARGIN = 10.0
"""Seconds of mission time before the last ground contact: where the robot returns to."""
POSE_SAMPLE_PERIOD = 0.5
"""Seconds between the poses the guard remembers while the robot works."""

PoseSource = Callable[[], Pose | None]
"""Where the robot is now in the mission's map frame (None while it does not know)."""


def no_pose() -> Pose | None:
    """The pose source of a robot that gives none: its position is never known."""
    return None


def pose_parameter(kind: SkillType) -> str:
    """The one pose parameter of a return skill, or "" if it has not exactly one."""
    poses = [name for name, ptype in kind.parameters.items() if ptype is ParamType.POSE]
    return poses[0] if len(poses) == 1 else ""


class LostLinkGuard:
    """Watches the ground link and acts on the robot's lost-link policy.

    Args:
        agent: The robot.
        clock: Seconds of mission time (the engine's clock): poses, the safe skill.
        skill_types: The skills the robot implements (the safe skill is one of them).
        pose_source: Where the robot is (remembered whenever the ground is heard).
        link_clock: Steady wall seconds for ground contact (``clock`` if not given).

    Attributes:
        policy: The policy in force.
        is_default: Whether ``policy`` is the library's default (no operator chose one).
        note: What the policy did last, for operators ("" until it acted).
        contingency: The safe skill while it runs (the robot is held meanwhile).
        held: Why the policy left the robot holding (NONE until it did, and once the
            operator started the robot again).
    """

    def __init__(
        self,
        agent: str,
        clock: Callable[[], float],
        skill_types: Mapping[str, SkillType],
        pose_source: PoseSource = no_pose,
        link_clock: Callable[[], float] | None = None,
    ) -> None:
        self.agent = agent
        self.clock = clock
        self.link_clock = link_clock or clock
        self.skill_types = skill_types
        self.policy = LostLinkPolicy()
        self.is_default = False
        self.note = ""
        self.contingency: SkillBehavior | None = None
        self.held = HoldCause.NONE
        self._recent: deque[tuple[float, Pose]] = deque()  # poses within the margin
        self._link_pose: Pose | None = None
        self._pose_source = pose_source
        self._last_contact = self.link_clock()
        self._idle_since: float | None = None
        self._triggered = False

    def adopt(self, policy: LostLinkPolicy, default: bool) -> bool:
        """Take ``policy`` (an operator's, or the library's ``default``); False if ignored.

        A library default never replaces a policy an operator chose. What the previous
        policy did is forgotten, unless its skill still runs.
        """
        if default and self.policy_chosen:
            return False
        self.policy, self.is_default = policy, default
        if self.contingency is None:
            self.note = ""
        return True

    @property
    def policy_chosen(self) -> bool:
        """Whether an operator chose the policy in force (not the library, not the start)."""
        return not self.is_default and self.policy != LostLinkPolicy()

    def contact(self) -> bool:
        """The ground was heard; True if that ends a triggered policy (the note changed)."""
        self._last_contact = self.link_clock()
        self._sample(self.clock())
        if self._recent:
            self._link_pose = self._recent[0][1]
        if not self._triggered:
            return False
        self._triggered = False
        self.note += "; ground contact is back"
        return True

    def operator_took_over(self) -> None:
        """The robot was started again: what the policy did is over (its note would still
        say "holding"), unless its skill still runs (its note says so)."""
        self.held = HoldCause.NONE
        if self.contingency is None:
            self.note = ""

    def observe(self, now: float) -> None:
        """Remember where the robot is, at most every :data:`POSE_SAMPLE_PERIOD` s."""
        if not self._recent or now - self._recent[-1][0] >= POSE_SAMPLE_PERIOD:
            self._sample(now)

    def _sample(self, now: float) -> None:
        """Add the pose now; keep the newest pose at least the margin old, and all after."""
        pose = self._pose_source()
        if pose is None:
            return
        recent = self._recent
        recent.append((now, pose))
        while len(recent) > 1 and recent[1][0] <= now - LINK_MARGIN:
            recent.popleft()

    @property
    def last_link_pose(self) -> Pose | None:
        """Where the robot returns to: its pose :data:`LINK_MARGIN` s before the last contact.

        The oldest pose known then if it had not been sampled that long; None if none is known.
        """
        return self._link_pose

    def due(self, idle: bool) -> bool:
        """Whether the policy acts now (``idle``: the robot has nothing left to do).

        A ``silent`` policy counts the seconds without the ground; an ``idle`` one the
        seconds both idle and without the ground, both on the link clock. It acts once per
        outage.
        """
        now = self.link_clock()
        if not idle:
            self._idle_since = None
        elif self._idle_since is None:
            self._idle_since = now
        if self.policy.kind is LostLinkKind.CONTINUE or self._triggered:
            return False
        since = self._last_contact
        if self.policy.when is LostLinkTrigger.IDLE:
            if self._idle_since is None:
                return False
            since = max(since, self._idle_since)
        return now - since >= self.policy.after

    def trigger(self, idle: bool, pause: Callable[[str], None]) -> None:
        """Act: hold the robot with ``pause``, then run the policy's skill.

        A ``silent`` safe_skill policy only holds a robot that is ``idle`` (it keeps its
        meaning from before idle triggers existed).
        """
        silent = self.link_clock() - self._last_contact
        self._triggered = True
        policy = self.policy
        params: dict[str, object] = dict(policy.params)
        held = f"held after {silent:.0f} s without ground contact"
        silent_kind = policy.when is LostLinkTrigger.SILENT
        just_hold = policy.kind is LostLinkKind.HOLD or (
            policy.kind is LostLinkKind.SAFE_SKILL and idle and silent_kind
        )
        if policy.kind is LostLinkKind.RETURN_TO_LINK:
            target = self._return_target()
            if target is None:
                just_hold, held = True, held + " (no position with a link is known)"
            else:
                params.update(target)
        if just_hold:
            self.note = held
            self.held = HoldCause.LOST_LINK
            pause(self.note)
        else:
            self.note = self._running_note(silent)
            pause(self.note)
            kind = self.skill_types[policy.skill]
            self.contingency = kind.create()
            ctx = SkillContext(self.agent, "", kind.coerce(params), 1, self.clock)
            self.contingency.start(ctx)
        _log.warning("%s: %s", self.agent, self.note)

    def _return_target(self) -> dict[str, object] | None:
        """The return skill's pose parameter set to the last position with a link."""
        name = pose_parameter(self.skill_types[self.policy.skill])
        if self.last_link_pose is None or not name:
            return None
        return {name: value_to_data(self.last_link_pose)}

    def _running_note(self, silent: float) -> str:
        if self.policy.kind is LostLinkKind.RETURN_TO_LINK and self.last_link_pose is not None:
            pose = self.last_link_pose
            return (
                f"returning to the last link position ({pose.x:.1f}, {pose.y:.1f}) "
                f"after {silent:.0f} s without ground contact"
            )
        return f"ran '{self.policy.skill}' after {silent:.0f} s without ground contact"

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
        returned = self.policy.kind is LostLinkKind.RETURN_TO_LINK and outcome.success
        self.held = HoldCause.RETURN_POINT if returned else HoldCause.SAFE_SKILL
        return True

    def in_force(self) -> PolicyInForce:
        """The policy in force and what it did, as the robot reports it."""
        return PolicyInForce(self.policy, self.is_default, self.note)
