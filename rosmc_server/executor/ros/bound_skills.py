"""Skills that run through an existing ROS interface, as a library binding configures.

* :class:`ActionSkill` sends an actionlib goal, shows feedback as status text, and turns
  the result into the outcome. Pause and stop preempt the goal; resume sends it again.
* :class:`ServiceSkill` calls a service; its response is the outcome. A call cannot be
  interrupted: pause holds the skill once the call returned, stop fails it then.
* :class:`TopicSkill` publishes one message once the topic has a subscriber, and succeeds.

Each waits for its server or subscriber first, saying so in its status text; the skill's
timeout bounds that wait like the rest of the run.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus

from ...common.ros.connections import publishers_count_me
from ..core import Outcome, SkillContext, ThreadedSkill
from ..core.skills import Cancelled
from .message_fields import MessageRecipe, Template, read_field

_log = logging.getLogger(__name__)
POLL = 0.05  # seconds between looks at a goal (pause and stop are seen that often)
_FAILED = {
    GoalStatus.ABORTED: "the action server aborted the goal",
    GoalStatus.REJECTED: "the action server rejected the goal",
    GoalStatus.PREEMPTED: "the action server preempted the goal",
    GoalStatus.RECALLED: "the action server recalled the goal",
}


@dataclass(frozen=True)
class Reply:
    """How a result or response becomes an outcome."""

    text: Template
    success: str = ""  # a bool field that decides success ("" = the call's own success)

    def outcome(self, msg: Any, failure: str = "") -> Outcome:
        """The outcome: ``failure`` if set, else the success field (if any) decides."""
        text = _render(self.text, msg)
        if failure:
            return Outcome.failed(f"{failure}: {text}" if text else failure)
        if self.success and msg is not None and not read_field(msg, self.success):
            return Outcome.failed(text or f"{self.success} is false")
        return Outcome.ok(text)


def _failure(state: int) -> str:
    if state == GoalStatus.SUCCEEDED:
        return ""
    return _FAILED.get(state, "the goal was lost")


def _render(template: Template, msg: Any) -> str:
    try:
        return template.render(msg)
    except (ValueError, TypeError, KeyError, AttributeError, IndexError) as error:
        return f"(cannot show {template.text!r}: {error})"


class _BoundSkill(ThreadedSkill):
    """What the bound skills share: waiting for the other side, pause- and stop-aware."""

    def _wait_for(self, ready: Callable[[], bool], ctx: SkillContext, what: str) -> None:
        told = False
        while not ready():
            if not told:
                ctx.progress(f"waiting for {what}")
                told = True
            self.sleep(0.1, time.monotonic)
        if told:
            ctx.progress("")


class ActionSkill(_BoundSkill):
    """One run of a skill bound to an actionlib action."""

    def __init__(
        self,
        client: actionlib.SimpleActionClient,
        name: str,
        goal: MessageRecipe,
        status: Template,
        reply: Reply,
    ) -> None:
        super().__init__()
        self._client, self._name, self._goal, self._status, self._reply = (
            client,
            name,
            goal,
            status,
            reply,
        )
        self._lock = threading.Lock()
        self._sent = False  # a goal of this run is out
        self._preempted_by_pause = False
        self._done = threading.Event()
        self._result: tuple[int, Any] = (GoalStatus.LOST, None)

    def run(self, ctx: SkillContext) -> Outcome:
        """Send the goal (again after each pause) until it ends."""
        goal = self._goal.build(ctx.params)
        while True:
            self.checkpoint()  # holds while paused (the goal was preempted)
            self._wait_for(self._server_ready, ctx, f"action server {self._name}")
            with self._lock:
                if self._cancelled.is_set():
                    raise Cancelled
                if not self._running.is_set():
                    continue  # paused meanwhile: the next wait holds until resumed
                self._done.clear()
                self._preempted_by_pause = False
                self._client.send_goal(goal, done_cb=self._on_done, feedback_cb=self._feedback)
                self._sent = True
            while not self._done.wait(POLL):
                self.checkpoint()
            self.checkpoint()  # paused: hold here; stopped: end here
            state, result = self._result
            if state in (GoalStatus.PREEMPTED, GoalStatus.RECALLED) and self._preempted_by_pause:
                continue  # resumed after a pause: the same goal again
            return self._reply.outcome(result, _failure(state))

    def _server_ready(self) -> bool:
        """The server is up and will reach this client with its feedback and result.

        actionlib's own check counts the result topic connected from this side only: a
        server that finishes at once could publish its one result before it writes to us.
        """
        if not self._client.wait_for_server(rospy.Duration(0.1)):
            return False
        action = self._client.action_client
        return publishers_count_me(action.result_sub) and publishers_count_me(action.feedback_sub)

    def _on_done(self, state: int, result: Any) -> None:
        self._result = (state, result)
        self._done.set()

    def _feedback(self, feedback: Any) -> None:
        if self.ctx is not None and self._status.text:
            self.ctx.progress(_render(self._status, feedback))

    def pause(self) -> None:
        """Preempt the goal; resume sends it again."""
        with self._lock:
            super().pause()
            if self._sent and not self._done.is_set():
                self._preempted_by_pause = True
                self._client.cancel_goal()

    def cancel(self) -> None:
        """Preempt the goal for good."""
        with self._lock:
            super().cancel()
            if self._sent and not self._done.is_set():
                self._client.cancel_goal()


class ServiceSkill(_BoundSkill):
    """One run of a skill bound to a service."""

    def __init__(
        self, proxy: rospy.ServiceProxy, name: str, request: MessageRecipe, reply: Reply
    ) -> None:
        super().__init__()
        self._proxy, self._name, self._request, self._reply = proxy, name, request, reply

    def run(self, ctx: SkillContext) -> Outcome:
        """Call the service once it is there; its response is the outcome."""
        request = self._request.build(ctx.params)
        self._wait_for(self._service_ready, ctx, f"service {self._name}")
        try:
            response = self._proxy.call(request)
        except (rospy.ServiceException, rospy.ROSException) as error:
            self.checkpoint()
            return Outcome.failed(f"the call to service {self._name} failed: {error}")
        self.checkpoint()
        return self._reply.outcome(response)

    def _service_ready(self) -> bool:
        try:
            rospy.wait_for_service(self._name, timeout=0.1)
        except rospy.ROSException:
            return False
        return True


class TopicSkill(_BoundSkill):
    """One run of a skill bound to a topic: publish once, then succeed."""

    def __init__(self, publisher: rospy.Publisher, message: MessageRecipe) -> None:
        super().__init__()
        self._publisher, self._message = publisher, message

    def run(self, ctx: SkillContext) -> Outcome:
        """Publish once the topic has a subscriber."""
        msg = self._message.build(ctx.params)
        name = self._publisher.resolved_name
        connected = lambda: self._publisher.get_num_connections() > 0  # noqa: E731
        self._wait_for(connected, ctx, f"a subscriber of {name}")
        self.checkpoint()
        self._publisher.publish(msg)
        return Outcome.ok(f"sent on {name}")
