"""Execution control of a robot: what the operator commands, and what the executor reports.

:class:`ControlCommand` numbers match ``rosmc/Control``. :class:`ExecutorState` is the
executor's one-word state (``AgentStatus.executor_state`` on the wire); the executor
names it, and :meth:`ExecutorState.of` is the one place a reported word becomes a state.
"""

from __future__ import annotations

import enum


class ControlCommand(enum.IntEnum):
    """Execution control of a robot (numbers match ``rosmc/Control``)."""

    START = 0
    PAUSE = 1
    RESUME = 2
    STOP = 3


class ExecutorState(enum.Enum):
    """What a robot's mission executor is doing, as it reports it.

    ``UNKNOWN`` stands for a robot not heard yet (or a word this version does not know).
    """

    UNKNOWN = ""
    STOPPED = "stopped"
    PAUSED = "paused"
    IDLE = "idle"
    RUNNING = "running"
    WAITING = "waiting"
    HOLDING = "holding"
    CONTINGENCY = "contingency"

    @classmethod
    def of(cls, word: str) -> ExecutorState:
        """The state a reported word names (UNKNOWN for "" or an unknown word)."""
        try:
            return cls(word)
        except ValueError:
            return cls.UNKNOWN

    @property
    def started(self) -> bool:
        """The operator let the robot execute (it runs, waits or holds, not paused)."""
        return self in _STARTED


_STARTED = frozenset(
    {
        ExecutorState.IDLE,
        ExecutorState.RUNNING,
        ExecutorState.WAITING,
        ExecutorState.HOLDING,
        ExecutorState.CONTINGENCY,
    }
)


class HoldCause(enum.Enum):
    """Why a robot holds on its own after its lost-link policy acted (``NONE``: it does not).

    The executor reports it as a word (``ExecutorSnapshot.hold``, ``AgentState.hold``); a
    holding robot starts no new work and its barrier partners wait for it until the
    operator resumes it. :meth:`of` is the one place a reported word becomes a cause; its
    words for operators are :data:`~..views.vocabulary.HOLD_WHERE`.
    """

    NONE = ""
    LOST_LINK = "lost_link"
    RETURN_POINT = "return_point"
    SAFE_SKILL = "safe_skill"

    @classmethod
    def of(cls, word: str) -> HoldCause:
        """The cause a reported word names (NONE for "" or a word this version does not know)."""
        try:
            return cls(word)
        except ValueError:
            return cls.NONE
