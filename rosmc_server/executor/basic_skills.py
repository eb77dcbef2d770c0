"""Skills any robot can run, with real behaviour: waiting, probing, counting.

They make the executor usable without a simulator (and are what the tests run):

* ``wait(duration)``: waits ``duration`` seconds of robot time, honouring pause and cancel.
* ``probe(duration, fail)``: works ``duration`` seconds, then fails if ``fail`` is true.
* ``count(steps, period)``: counts ``steps`` steps of ``period`` seconds, reporting progress;
  written as a non-threaded behaviour stepped by the executor.
"""

from __future__ import annotations

from .core import Outcome, SkillBehavior, SkillContext, SkillType, ThreadedSkill


class Wait(ThreadedSkill):
    """Wait a number of seconds of robot time."""

    def run(self, ctx: SkillContext) -> Outcome:
        """Sleep in slices, reporting the time left every second."""
        duration = ctx.number("duration")
        end = ctx.now() + duration
        while (left := end - ctx.now()) > 0:
            ctx.progress(f"{left:.0f} s left")
            self.sleep(min(1.0, left), ctx.clock)
        return Outcome.ok()


class Probe(ThreadedSkill):
    """Work for a while, then fail if asked to (the test's failing skill)."""

    def run(self, ctx: SkillContext) -> Outcome:
        """Sleep ``duration``; fail with a clear reason when ``fail`` is set."""
        self.sleep(ctx.number("duration"), ctx.clock)
        if ctx.params["fail"]:
            return Outcome.failed("the probe failed as its parameters asked")
        return Outcome.ok("probe done")


class Count(SkillBehavior):
    """Count steps on the executor's own ticks (no thread), reporting progress."""

    def __init__(self) -> None:
        self._ctx: SkillContext | None = None
        self._done = 0
        self._next = 0.0
        self._paused = False
        self._cancelled = False

    def start(self, ctx: SkillContext) -> None:
        """Remember the parameters; the first step ends one period from now."""
        self._ctx = ctx
        self._next = ctx.now() + ctx.number("period")

    def update(self, now: float) -> Outcome | None:
        """Count a step whenever a period has passed."""
        assert self._ctx is not None
        if self._cancelled:
            return Outcome.failed("cancelled")
        steps = self._ctx.integer("steps")
        if self._paused:
            self._next = now + self._ctx.number("period")
            return None
        if now >= self._next:
            self._done += 1
            self._next = now + self._ctx.number("period")
            self._ctx.progress(f"step {self._done} of {steps}")
        return Outcome.ok() if self._done >= steps else None

    def pause(self) -> None:
        """Stop counting."""
        self._paused = True

    def resume(self) -> None:
        """Count on."""
        self._paused = False

    def cancel(self) -> None:
        """Give up."""
        self._cancelled = True


def skill_types(agent: str = "") -> list[SkillType]:
    """The basic skills, for the executor's ``~skills`` parameter (any agent).

    Their parameters are declared by the library the executor is given (``~library``),
    as ``tests/data/test_team.yaml`` does: ``wait(duration: float)``,
    ``probe(duration: float, fail: bool)``, ``count(steps: int, period: float)``.
    """
    return [
        SkillType("wait", Wait, description="Wait some seconds."),
        SkillType("probe", Probe, description="Work, then fail if asked."),
        SkillType("count", Count, description="Count steps with progress."),
    ]
