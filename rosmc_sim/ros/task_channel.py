"""The robot-task protocol of one simulated robot on ROS.

Subscribes ``/<robot>/sim/task`` (rosmc/RobotTask) and publishes
``/<robot>/sim/task_status`` (rosmc/RobotTaskStatus, latched). A state change
(running, paused, succeeded, failed) is published at once; progress text at
most every :data:`PROGRESS_PERIOD` wall seconds; and the latest status again
every :data:`HEARTBEAT_PERIOD` wall seconds while a task is active and for
:data:`LINGER` seconds after it ended, so a subscriber that joined late still
hears the outcome.

Requests arrive on rospy's threads and are only queued there; the sim loop
handles them between steps, so the simulation is touched by one thread only.
"""

from __future__ import annotations

import collections
import logging

import rosmc.msg as wire
import rospy

from rosmc_server.conversions import param_from_msg
from rosmc_server.core import RosmcError

from .task_desk import TaskDesk, TaskStatus
from .timing import Throttle
from .topics import task_status_topic, task_topic

PROGRESS_PERIOD = 0.2
HEARTBEAT_PERIOD = 1.0
LINGER = 5.0

_log = logging.getLogger(__name__)


class TaskChannel:
    """Connects one robot's :class:`TaskDesk` to its task topics."""

    def __init__(self, desk: TaskDesk) -> None:
        self.desk = desk
        self.robot = desk.robot.name
        self._requests: collections.deque[wire.RobotTask] = collections.deque()
        self._last: TaskStatus | None = None
        self._ended_at = float("-inf")
        self._progress = Throttle(PROGRESS_PERIOD)
        self._heartbeat = Throttle(HEARTBEAT_PERIOD)
        self._publisher = rospy.Publisher(
            task_status_topic(self.robot), wire.RobotTaskStatus, queue_size=100, latch=True
        )
        self._subscriber = rospy.Subscriber(
            task_topic(self.robot), wire.RobotTask, self._requests.append, queue_size=100
        )

    def handle_requests(self, now: float) -> None:
        """Act on the requests that arrived since the last step."""
        while self._requests:
            for status in self._handle(self._requests.popleft()):
                self._publish(status, now)

    def update(self, now: float) -> None:
        """Advance the active task one step and publish what changed (throttled)."""
        status = self.desk.update()
        last = self._last
        if status is not None and (
            last is None
            or status.task_id != last.task_id
            or status.state != last.state
            or self._progress.due(now)
        ):
            self._publish(status, now)
        elif last is not None and self._lively(now) and self._heartbeat.due(now):
            self._publish(self.desk.current or self.desk.status(last.task_id) or last, now)

    def _lively(self, now: float) -> bool:
        """Whether a task is active or ended less than LINGER seconds ago."""
        return self.desk.busy or now - self._ended_at < LINGER

    def close(self) -> None:
        """Cancel the active task and say so."""
        for status in self.desk.close():
            if not rospy.is_shutdown():
                self._publisher.publish(self._to_msg(status))
        self._subscriber.unregister()

    def _handle(self, msg: wire.RobotTask) -> list[TaskStatus]:
        task_id = msg.task_id
        if not task_id:
            _log.warning("%s: ignoring a task request without task_id", self.robot)
            return []
        if msg.action == wire.RobotTask.START:
            try:
                params = dict(param_from_msg(p) for p in msg.parameters)
            except RosmcError as error:
                return self.desk.refuse(task_id, f"invalid parameters: {error}")
            _log.info("%s: start %s (%s)", self.robot, msg.skill, task_id)
            return self.desk.start(task_id, msg.skill, params)
        if msg.action == wire.RobotTask.PAUSE:
            return self.desk.pause(task_id)
        if msg.action == wire.RobotTask.RESUME:
            return self.desk.resume(task_id)
        if msg.action == wire.RobotTask.CANCEL:
            return self.desk.cancel(task_id)
        _log.warning("%s: ignoring unknown task action %d", self.robot, msg.action)
        return []

    def _publish(self, status: TaskStatus, now: float) -> None:
        if status.finished:
            if self._last is None or self._last != status:
                _log.info(
                    "%s: %s %s: %s", self.robot, status.task_id, status.state.name, status.text
                )
            self._ended_at = now
        self._last = status
        self._heartbeat.reset()
        self._heartbeat.due(now)  # the next heartbeat is one period from now
        self._publisher.publish(self._to_msg(status))

    def _to_msg(self, status: TaskStatus) -> wire.RobotTaskStatus:
        return wire.RobotTaskStatus(
            robot=self.robot, task_id=status.task_id, state=int(status.state), text=status.text
        )
