"""Which of the executor's periodic snapshots go out, and how much each says.

A snapshot is the robot's heartbeat on the link as well as its state: the ground calls the
link DOWN when it has heard nothing for its link timeout. While the robot works, its
snapshot changes and goes every period; once it is idle, only its stamp changes, and it
goes every ``idle_period`` seconds, but twice within the ground's link timeout (which the
ground's report acks carry). The lost-link policy in force, the longest part of an idle
snapshot, goes when it changed, in every whole snapshot, and every ``policy_repeat``
seconds; the others leave it out (None) and the ground keeps the last one.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ...core.robots.protocol import Snapshot
from ...core.skills.policy import PolicyInForce

IDLE_PERIOD = 5.0  # seconds between unchanged snapshots, at most
POLICY_REPEAT = 30.0  # seconds after which a snapshot repeats an unchanged policy


@dataclass
class SnapshotPacer:
    """Decides each due snapshot; the executor's loop asks every ``period`` seconds.

    Args:
        period: Seconds between snapshots while they change.
        idle_period: Seconds between unchanged ones (see the module docstring).
        policy_repeat: Seconds after which an unchanged policy is said again.

    Attributes:
        ground_timeout: The ground's link timeout (0 until the ground said it).
    """

    period: float = 1.0
    idle_period: float = IDLE_PERIOD
    policy_repeat: float = POLICY_REPEAT
    ground_timeout: float = 0.0
    _content: Snapshot | None = None  # the last sent, stamp left out
    _sent: float = 0.0
    _policy: tuple[PolicyInForce | None, float] = (None, 0.0)  # the policy last said, and when

    def unchanged_period(self) -> float:
        """Seconds between unchanged snapshots now."""
        if self.ground_timeout <= 0.0:
            return self.period  # not said yet
        return max(self.period, min(self.idle_period, self.ground_timeout / 2.0))

    def due(self, snapshot: Snapshot, now: float) -> Snapshot | None:
        """What to send of ``snapshot`` at ``now``: None if it is not due yet."""
        content = dataclasses.replace(snapshot, stamp=0.0)
        if content == self._content and now < self._sent + self.unchanged_period():
            return None
        self._content, self._sent = content, now
        said, when = self._policy
        if snapshot.full or snapshot.policy != said or now >= when + self.policy_repeat:
            self._policy = (snapshot.policy, now)
            return snapshot
        return dataclasses.replace(snapshot, policy=None)

    def next_check(self, now: float) -> float:
        """When to ask next: after ``period``, or when an unchanged one falls due."""
        return min(now + self.period, self._sent + self.unchanged_period())
