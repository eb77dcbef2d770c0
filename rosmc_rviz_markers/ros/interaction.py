"""What the operator does with the mouse, turned into mission server calls.

Feedback arrives as rviz sends it (``visualization_msgs/InteractiveMarkerFeedback``):

* ``MENU_SELECT``: the entry is looked up in the menu last published for that marker; a
  stale entry is ignored with a warning.
* ``POSE_UPDATE`` while dragging, then ``MOUSE_UP``: one ``move_task_marker`` with the final
  pose (or, without a ``MOUSE_UP``, after ``commit_delay`` seconds of quiet). A drag that is
  not finite, crosses an area or touches a locked marker is refused and the marker snaps
  back; so does one the server refuses (e.g. a stale revision).
* ``MOUSE_DOWN`` / ``BUTTON_CLICK``: select (publish ``rosmc/Selection``).

The stock tools' topics create task markers. Every call goes through the
:class:`~rosmc_server.ros.client.AsyncMissionClient` worker, made against the mirror's
revision when the operator acted (the client fills in each call's base revision, as for
the command GUI); nothing here blocks a ROS callback.
"""

from __future__ import annotations

import contextlib
import logging
import math
import threading
from collections.abc import Callable
from typing import Any

import rosmc.msg as wire
import rospy
from geometry_msgs.msg import PointStamped, PoseStamped, PoseWithCovarianceStamped
from visualization_msgs.msg import InteractiveMarkerFeedback as Feedback

from rosmc_server import interface
from rosmc_server.core import InvalidRequest, MarkerType, Pose, RosmcError
from rosmc_server.core.live.edit_history import EditHistory, EditKind
from rosmc_server.core.model.control import ControlCommand
from rosmc_server.core.skills.params import value_to_data
from rosmc_server.core.world import areas
from rosmc_server.ros.client import AsyncMissionClient, MissionClient, Outcome

from .. import topics
from ..core.menus import (
    AddSkill,
    DeleteMarker,
    EditAction,
    RenameMarker,
    ResumeRobot,
    SelectObject,
    UndoEdit,
)
from ..core.requests import (
    SkillPlan,
    edit_kind,
    moved_area,
    moved_pose,
    new_marker,
    robot_skill_plan,
)
from ..core.scene import Selection
from ..core.specs import Parsed, parse_name
from ..core.styling import is_locked
from .config import MarkerHost, MarkerNodeConfig
from .convert import pose_numbers
from .menu_calls import add_driving_first
from .undo_calls import UndoCalls

_log = logging.getLogger(__name__)
Call = Callable[[MissionClient], Any]


class Interaction:
    """Feedback, stock tools and selection of one marker node."""

    def __init__(self, node: MarkerHost, config: MarkerNodeConfig) -> None:
        self._node = node
        self._config = config
        self._client = AsyncMissionClient(MissionClient(5.0, config.ns), "rosmc-markers-client")
        self.history = EditHistory()  # this rviz's own edits, for Undo / Redo
        self.undo = UndoCalls(self.history, self._client, lambda: node.mirror.revision)
        self._drags: dict[str, tuple[float, float, float]] = {}
        self._timers: dict[str, threading.Timer] = {}
        self._lock = threading.Lock()
        self._selected = Selection()
        selection_topic = interface.prefixed(interface.SELECTION_TOPIC, config.ns)
        self._selection_pub = rospy.Publisher(
            selection_topic, wire.Selection, queue_size=1, latch=True
        )
        self._subscribers = [rospy.Subscriber(selection_topic, wire.Selection, self._on_selection)]
        if not config.read_only:
            tools = (
                (topics.NEW_POSITION_TOPIC, PointStamped, self._on_new_position),
                (topics.NEW_POSE_TOPIC, PoseStamped, self._on_new_pose),
                (topics.NEW_AREA_TOPIC, PoseWithCovarianceStamped, self._on_new_area),
            )
            for name, kind, callback in tools:
                self._subscribers.append(
                    rospy.Subscriber(topics.topic(name, config.ns), kind, self._guard(callback))
                )

    def forget_library(self) -> None:
        """Check requests against the library fetched anew (the server restarted)."""
        self._client.submit(lambda client: client.forget_library())

    def close(self) -> None:
        """Stop the worker, the timers and the subscribers."""
        for subscriber in self._subscribers:
            subscriber.unregister()
        with self._lock:
            for timer in self._timers.values():
                timer.cancel()
        self._client.close()

    @staticmethod
    def _guard(callback: Callable[[Any], None]) -> Callable[[Any], None]:
        def guarded(msg: Any) -> None:
            try:
                callback(msg)
            except Exception:  # a bad message must not kill the subscriber thread
                _log.exception("cannot handle a message")

        return guarded

    # -- feedback ---------------------------------------------------------------------------------
    def on_feedback(self, feedback: Any) -> None:
        """Handle one feedback message from rviz (on the server's subscriber thread)."""
        try:
            self._feedback(feedback)
        except Exception:  # keep the subscriber alive whatever the message held
            _log.exception("cannot handle feedback for '%s'", feedback.marker_name)

    def _feedback(self, fb: Any) -> None:
        parsed = parse_name(fb.marker_name)
        if parsed is None:
            _log.warning("ignored feedback for unknown marker '%s'", fb.marker_name)
            return
        kind = fb.event_type
        if kind == Feedback.MENU_SELECT:
            self._menu(fb, parsed)
        elif kind == Feedback.POSE_UPDATE:
            self._drag(fb, parsed)
        elif kind == Feedback.MOUSE_UP:
            if fb.marker_name in self._drags:
                self._drags[fb.marker_name] = pose_numbers(fb.pose)
                self._commit(fb.marker_name)
            else:
                self._select(parsed)
        elif kind in (Feedback.MOUSE_DOWN, Feedback.BUTTON_CLICK):
            self._select(parsed)

    def _refuse(self, name: str, why: str) -> None:
        _log.warning("%s; '%s' snaps back", why, name)
        self._node.snap_back(name)

    # -- menus ------------------------------------------------------------------------------------
    def _menu(self, fb: Any, parsed: Parsed) -> None:
        if self._config.read_only:
            _log.warning("the replay view is read-only: menu of '%s' ignored", fb.marker_name)
            return
        spec = self._node.published(fb.marker_name)
        action = spec.menu.actions.get(fb.menu_entry_id) if spec is not None else None
        if action is None:
            _log.warning(
                "ignored stale menu entry %d of marker '%s'", fb.menu_entry_id, fb.marker_name
            )
            return
        if isinstance(action, UndoEdit):
            self.undo.ask(action.redo)
            return
        if isinstance(action, SelectObject):
            self._select(parsed)
            return
        if isinstance(action, ResumeRobot):
            agent = action.agent
            # a control, not an edit (no EditKind): nothing for the undo history
            self._submit(lambda c: c.control(ControlCommand.RESUME, agent), f"resume {agent}")
            return
        mirror = self._node.mirror
        scene = self._node.scene
        with mirror.lock:
            state, revision = mirror.state, mirror.revision
            if state is None or scene is None:
                _log.warning("no mission yet: menu of '%s' ignored", fb.marker_name)
                return
            if parsed.kind == "task" and not state.has_marker(parsed.name):
                _log.warning("ignored menu entry of task marker '%s', which is gone", parsed.name)
                return
            status = mirror.agent_status(parsed.name) if parsed.kind == "robot" else None
            pose = status.pose if status is not None else None
        call = self._menu_call(action, parsed, scene.library, pose)
        self._submit(
            call, f"{fb.marker_name}: {self._title(action)}", revision, kind=edit_kind(action)
        )

    @staticmethod
    def _title(action: EditAction) -> str:
        if isinstance(action, AddSkill):
            driving = f"{action.drive[0]} and " if action.drive else ""
            return f"add {driving}{action.skill} to {action.agent}"
        if isinstance(action, RenameMarker):
            return f"rename to '{action.new_name}'"
        return "delete"

    @staticmethod
    def _menu_call(action: EditAction, parsed: Parsed, library: Any, pose: Pose | None) -> Call:
        name = parsed.name
        if isinstance(action, RenameMarker):
            return lambda c: c.rename_task_marker(name, action.new_name)
        if isinstance(action, DeleteMarker):
            return lambda c: c.delete_task_marker(name)
        if action.drive is not None and parsed.kind == "task":
            return lambda c: add_driving_first(c, action, name)
        if action.from_robot:
            plan = robot_skill_plan(library, action.agent, action.skill, pose)
        else:
            bindings = ((action.bind, name),) if action.bind and parsed.kind == "task" else ()
            plan = SkillPlan(action.agent, action.skill, dict(action.values), (), bindings)
        return lambda c: _add_planned(c, plan)

    # -- drags ------------------------------------------------------------------------------------
    def _drag(self, fb: Any, parsed: Parsed) -> None:
        name = fb.marker_name
        if self._config.read_only:
            self._refuse(name, "the replay view is read-only")
            return
        if parsed.kind != "task":
            self._refuse(name, f"{parsed.kind} '{parsed.name}' cannot be dragged")
            return
        with self._lock:
            self._drags[name] = pose_numbers(fb.pose)
            old = self._timers.pop(name, None)
            if old is not None:
                old.cancel()
            timer = threading.Timer(self._config.commit_delay, self._commit, (name,))
            timer.daemon = True
            self._timers[name] = timer
            timer.start()

    def _commit(self, name: str) -> None:
        with self._lock:
            target = self._drags.pop(name, None)
            timer = self._timers.pop(name, None)
        if timer is not None:
            timer.cancel()
        parsed = parse_name(name)
        if target is None or parsed is None:
            return
        x, y, yaw = target
        mirror = self._node.mirror
        with mirror.lock:
            state, revision = mirror.state, mirror.revision
            if state is None or not state.has_marker(parsed.name):
                _log.warning("ignored a drag of '%s', which is not a task marker", name)
                return
            marker = state.marker(parsed.name)
            locked = is_locked(state.bound_to(parsed.name))
        if locked:
            self._refuse(name, f"marker '{parsed.name}' is locked by a synchronized skill")
            return
        try:
            if marker.type is MarkerType.AREA:
                vertices = moved_area(marker, parsed.vertex, x, y)
                cx, cy = areas.centroid([(v.x, v.y) for v in vertices])
                pose = Pose(cx, cy)
            else:
                vertices = ()
                pose = moved_pose(marker, x, y, yaw)
        except InvalidRequest as error:
            self._refuse(name, f"ignored a drag of '{parsed.name}': {error}")
            return
        if pose == marker.pose and tuple(vertices) == marker.vertices:
            return
        self._submit(
            lambda c: c.move_task_marker(parsed.name, pose, vertices),
            f"move '{parsed.name}'",
            revision,
            on_error=lambda: self._node.snap_back(name),
            kind=EditKind.MOVE_MARKER,
        )

    # -- selection --------------------------------------------------------------------------------
    def _select(self, parsed: Parsed) -> None:
        mirror = self._node.mirror
        with mirror.lock:
            state = mirror.state
            if state is None:
                return
            if parsed.kind == "task" and state.has_marker(parsed.name):
                skills = [s.id for s in state.bound_to(parsed.name)]
                selection = Selection(frozenset(skills), frozenset({parsed.name}))
            elif parsed.kind == "robot":
                status = mirror.agent_status(parsed.name)
                current = status.current_skill if status is not None else ""
                ids = [current] if current and state.has_skill(current) else []
                selection = Selection(frozenset(ids), frozenset())
            else:
                return
        if selection == self._selected:
            return
        self._selected = selection
        msg = wire.Selection(
            source=rospy.get_name(),
            stamp=rospy.Time.now(),
            skill_ids=sorted(selection.skill_ids),
            marker_names=sorted(selection.marker_names),
        )
        self._selection_pub.publish(msg)

    def _on_selection(self, msg: Any) -> None:
        selection = Selection(frozenset(msg.skill_ids), frozenset(msg.marker_names))
        self._selected = selection
        scene, mirror = self._node.scene, self._node.mirror
        if scene is None:
            return
        with mirror.lock:
            touched = scene.select(selection, mirror.state)
        self._node.mark(touched)

    # -- stock tools ------------------------------------------------------------------------------
    def _on_new_position(self, msg: Any) -> None:
        self._create(MarkerType.POSITION, msg.header.frame_id, msg.point.x, msg.point.y, 0.0)

    def _on_new_pose(self, msg: Any) -> None:
        self._create(MarkerType.POSE, msg.header.frame_id, *pose_numbers(msg.pose))

    def _on_new_area(self, msg: Any) -> None:
        self._create(MarkerType.AREA, msg.header.frame_id, *pose_numbers(msg.pose.pose))

    def _create(self, kind: MarkerType, frame: str, x: float, y: float, yaw: float) -> None:
        what = kind.name.lower()
        if frame.lstrip("/") not in ("", interface.MAP_FRAME):
            _log.warning(
                "ignored a new %s marker in frame '%s' (set the fixed frame to map)", what, frame
            )
            return
        try:
            marker = new_marker(kind, x, y, yaw if math.isfinite(yaw) else 0.0)
        except InvalidRequest as error:
            _log.warning("ignored a new %s marker: %s", what, error)
            return
        revision = self._node.mirror.revision
        call: Call = lambda c: c.add_task_marker(marker)  # noqa: E731
        self._submit(call, f"new {what} marker", revision, kind=EditKind.ADD_MARKER)

    def on_reset(self, revision: int) -> None:
        """A snapshot came; one older than this node's last result means a new server."""
        if self.history.newest_above(revision):
            self.history.clear()  # its revisions named another server's edits
        self._client.submit(lambda c: c.forget_newer_than(revision))

    # -- calls ------------------------------------------------------------------------------------
    def _submit(
        self,
        call: Call,
        what: str,
        seen: int | None = None,
        on_error: Callable[[], None] | None = None,
        kind: EditKind | None = None,
    ) -> None:
        """Run ``call`` on the client's thread against ``seen``, the revision the operator
        saw; an accepted edit (``kind``) goes to the history."""

        def done(outcome: Outcome[Any]) -> None:
            if outcome.error is not None:
                _log.warning("%s refused: %s", what, outcome.error)
                if on_error is not None:
                    on_error()
                return
            revision = getattr(outcome.value, "revision", None)
            if revision is not None:
                self.history.done(kind, revision, what)
            _log.info("%s: done", what)

        future = self._client.submit(call, done, seen)
        future.add_done_callback(lambda f: f.exception())  # errors reach `done`, not stderr


def _add_planned(client: MissionClient, plan: SkillPlan) -> Any:
    """Create the plan's new markers, then the skill bound to them; undo markers on failure.

    Each call is made against the one before (the client's own last result)."""
    created: list[tuple[str, str]] = []
    try:
        for param, marker in plan.new_markers:
            added = client.add_task_marker(marker)
            created.append((param, added.name))
        return client.add_skill(
            plan.agent,
            plan.skill,
            {k: value_to_data(v) for k, v in plan.params.items()},
            bindings={**dict(plan.bindings), **dict(created)},
        )
    except RosmcError:
        for _, name in created:
            with contextlib.suppress(RosmcError):
                client.delete_task_marker(name)
        raise
