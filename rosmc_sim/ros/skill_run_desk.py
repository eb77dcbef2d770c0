"""One simulated robot's skill-run protocol, without ROS: start, pause, resume, cancel by run id.

A :class:`SkillRunDesk` runs at most one skill run at a time on its robot. A new START
preempts the one running; a repeated START (or any request) for a run the
desk already knows is answered with that run's current status instead of
acting twice, because the executor resends a START it got no answer to.
Every method returns the statuses the caller should publish.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from ..core.sim import Robot, Simulation
from ..core.skill_runs import SkillFailed, SkillRunner
from ..core.skills_registry import sim_skill_for

HISTORY = 64  # finished runs remembered per robot, to answer retransmitted requests


class RunState(IntEnum):
    """The states of ``rosmc/SkillRunStatus`` (same numbers)."""

    RUNNING = 0
    PAUSED = 1
    SUCCEEDED = 2
    FAILED = 3


@dataclass(frozen=True)
class RunStatus:
    """What a robot says about one of its skill runs."""

    run_id: str
    state: RunState
    text: str

    @property
    def finished(self) -> bool:
        """Succeeded or failed."""
        return self.state in (RunState.SUCCEEDED, RunState.FAILED)


class SkillRunDesk:
    """The skill runs of one robot: the running one, and the finished ones it still remembers."""

    def __init__(self, sim: Simulation, robot: Robot) -> None:
        self.sim = sim
        self.robot = robot
        self._runner: SkillRunner | None = None
        self._current: RunStatus | None = None
        self._finished: OrderedDict[str, RunStatus] = OrderedDict()

    @property
    def current(self) -> RunStatus | None:
        """The running or paused run's status, if a run is active."""
        return self._current

    @property
    def busy(self) -> bool:
        """Whether a skill run is running or paused."""
        return self._current is not None

    def status(self, run_id: str) -> RunStatus | None:
        """The latest status of a run the desk knows."""
        if self._current is not None and self._current.run_id == run_id:
            return self._current
        return self._finished.get(run_id)

    def start(self, run_id: str, skill: str, params: Mapping[str, Any]) -> list[RunStatus]:
        """Start ``skill``; an unknown skill, or one this robot lacks, fails at once."""
        known = self.status(run_id)
        if known is not None:
            return [known]
        out = self._preempt(run_id)
        try:
            kind = sim_skill_for(skill, self.robot.kind)
        except SkillFailed as reason:
            return [*out, self._finish(run_id, RunState.FAILED, str(reason))]
        self._runner = SkillRunner(self.sim, self.robot, kind.function, params, kind.needs_power)
        self._current = RunStatus(run_id, RunState.RUNNING, f"starting {skill}")
        return [*out, self._current]

    def refuse(self, run_id: str, reason: str) -> list[RunStatus]:
        """A START that cannot run (e.g. malformed parameters): it fails, like a started one."""
        known = self.status(run_id)
        if known is not None:
            return [known]
        return [*self._preempt(run_id), self._finish(run_id, RunState.FAILED, reason)]

    def pause(self, run_id: str) -> list[RunStatus]:
        """Hold the running skill still."""
        if self._is_current(run_id) and self._runner is not None and not self._runner.paused:
            self._runner.pause()
            progress = self._runner.progress
            self._current = RunStatus(
                run_id, RunState.PAUSED, f"paused: {progress}" if progress else "paused"
            )
        return self._answer(run_id)

    def resume(self, run_id: str) -> list[RunStatus]:
        """Go on with a paused run."""
        if self._is_current(run_id) and self._runner is not None and self._runner.paused:
            self._runner.resume()
            self._current = RunStatus(run_id, RunState.RUNNING, self._runner.progress)
        return self._answer(run_id)

    def cancel(self, run_id: str) -> list[RunStatus]:
        """Stop a run for good; a run never heard of is remembered as cancelled."""
        if self._is_current(run_id):
            return [self._stop("cancelled")]
        if self.status(run_id) is None:
            return [self._finish(run_id, RunState.FAILED, "cancelled before it started")]
        return self._answer(run_id)

    def update(self) -> RunStatus | None:
        """Advance the active run one step; its status if that changed."""
        if self._runner is None or self._current is None or self._runner.paused:
            return None
        result = self._runner.update()
        run_id = self._current.run_id
        if result is not None:
            state = RunState.SUCCEEDED if result.success else RunState.FAILED
            return self._finish(run_id, state, result.text)
        if self._runner.progress != self._current.text:
            self._current = RunStatus(run_id, RunState.RUNNING, self._runner.progress)
            return self._current
        return None

    def close(self) -> list[RunStatus]:
        """Cancel whatever runs (the simulation is going away)."""
        return [] if self._current is None else [self._stop("the simulator shut down")]

    def _is_current(self, run_id: str) -> bool:
        return self._current is not None and self._current.run_id == run_id

    def _answer(self, run_id: str) -> list[RunStatus]:
        known = self.status(run_id)
        return [] if known is None else [known]

    def _preempt(self, new_run_id: str) -> list[RunStatus]:
        if self._current is None:
            return []
        return [self._stop(f"preempted by {new_run_id}")]

    def _stop(self, reason: str) -> RunStatus:
        assert self._current is not None
        if self._runner is not None:
            self._runner.cancel()
        return self._finish(self._current.run_id, RunState.FAILED, reason)

    def _finish(self, run_id: str, state: RunState, text: str) -> RunStatus:
        status = RunStatus(run_id, state, text)
        if self._current is not None and self._current.run_id == run_id:
            self._current, self._runner = None, None
        self._finished[run_id] = status
        while len(self._finished) > HISTORY:
            self._finished.popitem(last=False)
        return status
