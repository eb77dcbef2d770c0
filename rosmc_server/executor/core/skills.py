"""The interface between the executor and the robot's skill implementations.

A skill implementation is registered by name as a :class:`SkillType`: a factory
of :class:`SkillBehavior` objects plus the typed parameters it reads. The
executor creates one behavior per execution, starts it with the parameters
(by name, typed), calls :meth:`SkillBehavior.update` regularly until it returns
an :class:`Outcome`, and may pause, resume or cancel it on the way.

Skills that are easier to write as blocking code derive from
:class:`ThreadedSkill` and implement :meth:`ThreadedSkill.run`, calling
``self.checkpoint()`` often: it blocks while paused and raises
:class:`Cancelled` once cancelled.
"""

from __future__ import annotations

import threading
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from rosmc_server.core import ParamType, Value


@dataclass(frozen=True)
class Outcome:
    """How a skill execution ended."""

    success: bool
    reason: str = ""

    @classmethod
    def ok(cls, reason: str = "") -> Outcome:
        """A success."""
        return cls(True, reason)

    @classmethod
    def failed(cls, reason: str) -> Outcome:
        """A failure, with the reason the operator will read."""
        return cls(False, reason)


@dataclass
class SkillContext:
    """What a running skill gets from the executor."""

    agent: str
    skill_id: str
    params: Mapping[str, Value]
    attempt: int
    clock: Callable[[], float]
    _progress: Callable[[str], None] = field(repr=False, default=lambda text: None)

    def progress(self, text: str) -> None:
        """Report progress text to the ground (e.g. "3 of 5 waypoints")."""
        self._progress(text)

    def now(self) -> float:
        """The executor's clock (sim time in simulation)."""
        return self.clock()

    def number(self, name: str) -> float:
        """A FLOAT (or INT) parameter as a float; TypeError if it is no number."""
        value = self.params[name]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise TypeError(f"parameter '{name}' is not a number: {value!r}")
        return float(value)

    def integer(self, name: str) -> int:
        """An INT parameter; TypeError if it is no integer."""
        value = self.params[name]
        if isinstance(value, bool) or not isinstance(value, int):
            raise TypeError(f"parameter '{name}' is not an integer: {value!r}")
        return value


class SkillBehavior(ABC):
    """One execution of a skill."""

    @abstractmethod
    def start(self, ctx: SkillContext) -> None:
        """Begin executing; must return quickly."""

    @abstractmethod
    def update(self, now: float) -> Outcome | None:
        """Advance; return the outcome once finished, None while still running."""

    def pause(self) -> None:  # noqa: B027 - optional hook
        """Hold still until :meth:`resume`."""

    def resume(self) -> None:  # noqa: B027 - optional hook
        """Continue after :meth:`pause`."""

    def cancel(self) -> None:  # noqa: B027 - optional hook
        """Stop for good (stop command, timeout, executor shutdown)."""


@dataclass(frozen=True)
class SkillType:
    """A skill implementation registered with the executor under ``name``.

    ``parameters`` lists the parameters the implementation reads and their
    types; an upload lacking one, or giving it another type, is refused.
    """

    name: str
    create: Callable[[], SkillBehavior]
    parameters: Mapping[str, ParamType] = field(default_factory=dict)
    description: str = ""

    def coerce(self, params: Mapping[str, object]) -> dict[str, Value]:
        """Parameters from plain data (JSON): pose mappings become poses."""
        from rosmc_server.core.skills.params import Pose

        out: dict[str, Value] = {}
        for name, value in params.items():
            if self.parameters.get(name) is ParamType.POSE and isinstance(value, Mapping):
                out[name] = Pose.from_any(value, f"parameter '{name}'")
            else:
                out[name] = value  # type: ignore[assignment]
        return out

    def check(self, params: Mapping[str, Value]) -> str:
        """Why ``params`` cannot run this skill, or "" if they can."""
        for name, ptype in self.parameters.items():
            if name not in params:
                return f"skill '{self.name}' needs parameter '{name}'"
            if not _matches(ptype, params[name]):
                return f"parameter '{name}' of skill '{self.name}' must be {ptype.name.lower()}"
        return ""


def _matches(ptype: ParamType, value: Value) -> bool:
    from rosmc_server.core.skills.params import Pose

    checks: Mapping[ParamType, Callable[[Value], bool]] = {
        ParamType.BOOL: lambda v: isinstance(v, bool),
        ParamType.INT: lambda v: isinstance(v, int) and not isinstance(v, bool),
        ParamType.FLOAT: lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
        ParamType.STRING: lambda v: isinstance(v, str),
        ParamType.LIST: lambda v: isinstance(v, list),
        ParamType.DICT: lambda v: isinstance(v, dict),
        ParamType.POSE: lambda v: isinstance(v, Pose),
    }
    return checks[ptype](value)


class Cancelled(Exception):
    """Raised inside :meth:`ThreadedSkill.run` by ``checkpoint`` once cancelled."""


class ThreadedSkill(SkillBehavior):
    """A skill written as blocking code in :meth:`run`, executed on its own thread."""

    def __init__(self) -> None:
        self._running = threading.Event()
        self._running.set()
        self._cancelled = threading.Event()
        self._outcome: Outcome | None = None
        self._thread: threading.Thread | None = None
        self.ctx: SkillContext | None = None

    @abstractmethod
    def run(self, ctx: SkillContext) -> Outcome:
        """Do the work; call :meth:`checkpoint` often."""

    def checkpoint(self, timeout: float | None = None) -> None:
        """Block while paused; raise Cancelled once cancelled."""
        while not self._running.wait(0.05 if timeout is None else timeout):
            if self._cancelled.is_set():
                break
        if self._cancelled.is_set():
            raise Cancelled

    def sleep(self, seconds: float, clock: Callable[[], float]) -> None:
        """Sleep ``seconds`` of ``clock`` time, honouring pause and cancel."""
        end = clock() + seconds
        while True:
            self.checkpoint()
            left = end - clock()
            if left <= 0:
                return
            self._cancelled.wait(min(left, 0.01))

    def start(self, ctx: SkillContext) -> None:
        """Start :meth:`run` on a thread."""
        self.ctx = ctx
        self._thread = threading.Thread(target=self._main, args=(ctx,), daemon=True)
        self._thread.start()

    def _main(self, ctx: SkillContext) -> None:
        try:
            self._outcome = self.run(ctx)
        except Cancelled:
            self._outcome = Outcome.failed("cancelled")
        except Exception as error:  # a skill's own bug becomes a clear failure
            self._outcome = Outcome.failed(f"skill crashed: {type(error).__name__}: {error}")

    def update(self, now: float) -> Outcome | None:
        """The outcome once :meth:`run` returned."""
        return self._outcome

    def pause(self) -> None:
        """Make the next checkpoint block."""
        self._running.clear()

    def resume(self) -> None:
        """Release a blocked checkpoint."""
        self._running.set()

    def cancel(self) -> None:
        """Make the next checkpoint raise Cancelled."""
        self._cancelled.set()
        self._running.set()
