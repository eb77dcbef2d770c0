"""The skill-run protocol of one simulated robot on ROS.

Subscribes ``/<robot>/sim/skill_run`` (rosmc/SkillRun) and publishes
``/<robot>/sim/skill_run_status`` (rosmc/SkillRunStatus, latched). A state change
(running, paused, succeeded, failed) is published at once; progress text at
most every :data:`PROGRESS_PERIOD` wall seconds; and the latest status again
every :data:`HEARTBEAT_PERIOD` wall seconds while a run is active and for
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

from .skill_run_desk import RunStatus, SkillRunDesk
from .timing import Throttle
from .topics import skill_run_status_topic, skill_run_topic

PROGRESS_PERIOD = 0.2
HEARTBEAT_PERIOD = 1.0
LINGER = 5.0

_log = logging.getLogger(__name__)


class SkillRunChannel:
    """Connects one robot's :class:`SkillRunDesk` to its skill-run topics."""

    def __init__(self, desk: SkillRunDesk) -> None:
        self.desk = desk
        self.robot = desk.robot.name
        self._requests: collections.deque[wire.SkillRun] = collections.deque()
        self._last: RunStatus | None = None
        self._ended_at = float("-inf")
        self._progress = Throttle(PROGRESS_PERIOD)
        self._heartbeat = Throttle(HEARTBEAT_PERIOD)
        self._publisher = rospy.Publisher(
            skill_run_status_topic(self.robot), wire.SkillRunStatus, queue_size=100, latch=True
        )
        self._subscriber = rospy.Subscriber(
            skill_run_topic(self.robot), wire.SkillRun, self._requests.append, queue_size=100
        )

    def handle_requests(self, now: float) -> None:
        """Act on the requests that arrived since the last step."""
        while self._requests:
            for status in self._handle(self._requests.popleft()):
                self._publish(status, now)

    def update(self, now: float) -> None:
        """Advance the active run one step and publish what changed (throttled)."""
        status = self.desk.update()
        last = self._last
        if status is not None and (
            last is None
            or status.run_id != last.run_id
            or status.state != last.state
            or self._progress.due(now)
        ):
            self._publish(status, now)
        elif last is not None and self._lively(now) and self._heartbeat.due(now):
            self._publish(self.desk.current or self.desk.status(last.run_id) or last, now)

    def _lively(self, now: float) -> bool:
        """Whether a run is active or ended less than LINGER seconds ago."""
        return self.desk.busy or now - self._ended_at < LINGER

    def close(self) -> None:
        """Cancel the active run and say so."""
        for status in self.desk.close():
            if not rospy.is_shutdown():
                self._publisher.publish(self._to_msg(status))
        self._subscriber.unregister()

    def _handle(self, msg: wire.SkillRun) -> list[RunStatus]:
        run_id = msg.run_id
        if not run_id:
            _log.warning("%s: ignoring a skill-run request without run_id", self.robot)
            return []
        if msg.action == wire.SkillRun.START:
            try:
                params = dict(param_from_msg(p) for p in msg.parameters)
            except RosmcError as error:
                return self.desk.refuse(run_id, f"invalid parameters: {error}")
            _log.info("%s: start %s (%s)", self.robot, msg.skill, run_id)
            return self.desk.start(run_id, msg.skill, params)
        if msg.action == wire.SkillRun.PAUSE:
            return self.desk.pause(run_id)
        if msg.action == wire.SkillRun.RESUME:
            return self.desk.resume(run_id)
        if msg.action == wire.SkillRun.CANCEL:
            return self.desk.cancel(run_id)
        _log.warning("%s: ignoring unknown skill-run action %d", self.robot, msg.action)
        return []

    def _publish(self, status: RunStatus, now: float) -> None:
        if status.finished:
            if self._last is None or self._last != status:
                _log.info(
                    "%s: %s %s: %s", self.robot, status.run_id, status.state.name, status.text
                )
            self._ended_at = now
        self._last = status
        self._heartbeat.reset()
        self._heartbeat.due(now)  # the next heartbeat is one period from now
        self._publisher.publish(self._to_msg(status))

    def _to_msg(self, status: RunStatus) -> wire.SkillRunStatus:
        return wire.SkillRunStatus(
            robot=self.robot, run_id=status.run_id, state=int(status.state), text=status.text
        )
