"""One simulated robot's task protocol, without ROS: start, pause, resume, cancel by task id.

A :class:`TaskDesk` runs at most one task at a time on its robot. A new START
preempts the running task; a repeated START (or any request) for a task the
desk already knows is answered with that task's current status instead of
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
from ..core.skills_registry import task_for
from ..core.tasks import TaskFailed, TaskRunner

HISTORY = 64  # finished tasks remembered per robot, to answer retransmitted requests


class TaskState(IntEnum):
    """The states of ``rosmc/RobotTaskStatus`` (same numbers)."""

    RUNNING = 0
    PAUSED = 1
    SUCCEEDED = 2
    FAILED = 3


@dataclass(frozen=True)
class TaskStatus:
    """What a robot says about one of its tasks."""

    task_id: str
    state: TaskState
    text: str

    @property
    def finished(self) -> bool:
        """Succeeded or failed."""
        return self.state in (TaskState.SUCCEEDED, TaskState.FAILED)


class TaskDesk:
    """The tasks of one robot: the running one, and the finished ones it still remembers."""

    def __init__(self, sim: Simulation, robot: Robot) -> None:
        self.sim = sim
        self.robot = robot
        self._runner: TaskRunner | None = None
        self._current: TaskStatus | None = None
        self._finished: OrderedDict[str, TaskStatus] = OrderedDict()

    @property
    def current(self) -> TaskStatus | None:
        """The running or paused task's status, if a task is active."""
        return self._current

    @property
    def busy(self) -> bool:
        """Whether a task is running or paused."""
        return self._current is not None

    def status(self, task_id: str) -> TaskStatus | None:
        """The latest status of a task the desk knows."""
        if self._current is not None and self._current.task_id == task_id:
            return self._current
        return self._finished.get(task_id)

    def start(self, task_id: str, skill: str, params: Mapping[str, Any]) -> list[TaskStatus]:
        """Start ``skill``; an unknown skill, or one this robot lacks, fails at once."""
        known = self.status(task_id)
        if known is not None:
            return [known]
        out = self._preempt(task_id)
        try:
            kind = task_for(skill, self.robot.kind)
        except TaskFailed as reason:
            return [*out, self._finish(task_id, TaskState.FAILED, str(reason))]
        self._runner = TaskRunner(self.sim, self.robot, kind.function, params, kind.needs_power)
        self._current = TaskStatus(task_id, TaskState.RUNNING, f"starting {skill}")
        return [*out, self._current]

    def refuse(self, task_id: str, reason: str) -> list[TaskStatus]:
        """A START that cannot run (e.g. malformed parameters): it fails, like a started one."""
        known = self.status(task_id)
        if known is not None:
            return [known]
        return [*self._preempt(task_id), self._finish(task_id, TaskState.FAILED, reason)]

    def pause(self, task_id: str) -> list[TaskStatus]:
        """Hold the running task still."""
        if self._is_current(task_id) and self._runner is not None and not self._runner.paused:
            self._runner.pause()
            progress = self._runner.progress
            self._current = TaskStatus(
                task_id, TaskState.PAUSED, f"paused: {progress}" if progress else "paused"
            )
        return self._answer(task_id)

    def resume(self, task_id: str) -> list[TaskStatus]:
        """Go on with a paused task."""
        if self._is_current(task_id) and self._runner is not None and self._runner.paused:
            self._runner.resume()
            self._current = TaskStatus(task_id, TaskState.RUNNING, self._runner.progress)
        return self._answer(task_id)

    def cancel(self, task_id: str) -> list[TaskStatus]:
        """Stop a task for good; a task never heard of is remembered as cancelled."""
        if self._is_current(task_id):
            return [self._stop("cancelled")]
        if self.status(task_id) is None:
            return [self._finish(task_id, TaskState.FAILED, "cancelled before it started")]
        return self._answer(task_id)

    def update(self) -> TaskStatus | None:
        """Advance the active task one step; its status if that changed."""
        if self._runner is None or self._current is None or self._runner.paused:
            return None
        result = self._runner.update()
        task_id = self._current.task_id
        if result is not None:
            state = TaskState.SUCCEEDED if result.success else TaskState.FAILED
            return self._finish(task_id, state, result.text)
        if self._runner.progress != self._current.text:
            self._current = TaskStatus(task_id, TaskState.RUNNING, self._runner.progress)
            return self._current
        return None

    def close(self) -> list[TaskStatus]:
        """Cancel whatever runs (the simulation is going away)."""
        return [] if self._current is None else [self._stop("the simulator shut down")]

    def _is_current(self, task_id: str) -> bool:
        return self._current is not None and self._current.task_id == task_id

    def _answer(self, task_id: str) -> list[TaskStatus]:
        known = self.status(task_id)
        return [] if known is None else [known]

    def _preempt(self, new_task_id: str) -> list[TaskStatus]:
        if self._current is None:
            return []
        return [self._stop(f"preempted by {new_task_id}")]

    def _stop(self, reason: str) -> TaskStatus:
        assert self._current is not None
        if self._runner is not None:
            self._runner.cancel()
        return self._finish(self._current.task_id, TaskState.FAILED, reason)

    def _finish(self, task_id: str, state: TaskState, text: str) -> TaskStatus:
        status = TaskStatus(task_id, state, text)
        if self._current is not None and self._current.task_id == task_id:
            self._current, self._runner = None, None
        self._finished[task_id] = status
        while len(self._finished) > HISTORY:
            self._finished.popitem(last=False)
        return status
