"""Property-based tests: random operator requests and robot reports against the mission rules.

A hypothesis state machine drives one :class:`Mission` with random sequences
of every operation (valid and invalid) and of robot-side answers and status
reports (legal ones that follow how a robot executes, and random illegal
ones), and checks after every step that:

* every task is synchronized section, then uploads, then editable blueprint;
  a started skill only follows settled ones;
* ids are unique across the mission;
* SUCCESS/FAILURE skills never change (only their retry/skip resolution, once);
* barrier members exist, sit on distinct agents, each skill is in at most one
  barrier, and the barriers never deadlock;
* the revision grows by exactly one per accepted change (with one event of the
  right kind) and not at all on a rejection, which leaves the mission identical;
* save -> load reproduces the mission exactly;
* replaying all events on a fresh mission gives the same mission;
* the typed changes the one applier describes, taken by a view with no rule of the core,
  give the same mission.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    rule,
)

from rosmc_server.core import (
    EventKind,
    MarkerType,
    Mission,
    MissionEvent,
    ParamType,
    Pose,
    Resolution,
    RosmcError,
    SkillInstance,
    SkillStatus,
    StaleRevision,
    TaskMarker,
    Transfer,
    dump_mission,
    load_library,
    mission_to_dict,
    parse_mission,
)
from rosmc_server.core.files.persistence import mission_from_dict
from rosmc_server.core.live.updates import apply_event
from rosmc_server.core.model.changes import SkillMove
from rosmc_server.core.model.state import MissionState
from rosmc_server.core.rules.barriers import find_deadlock
from tests.unit.described_view import DescribedView

S = SkillStatus
REPO = Path(__file__).resolve().parents[2]
LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
AGENTS = LIBRARY.dynamic_agents
MARKER_NAMES = ["rock", "site", "zone", "Pose 1", ""]

# How a robot moves its current skill on (the specification of legal reports).
ROBOT_NEXT = {
    S.IDLE_SYNCHRONIZED: [S.SYNCWAITING, S.RUNNING, S.RUNNING, S.RUNNING, S.FAILURE],
    S.SYNCWAITING: [S.RUNNING, S.RUNNING, S.PAUSED, S.IDLE_SYNCHRONIZED, S.FAILURE],
    S.RUNNING: [S.RUNNING, S.PAUSED, S.SUCCESS, S.SUCCESS, S.SUCCESS, S.FAILURE, S.FAILURE,
                S.IDLE_SYNCHRONIZED],
    S.PAUSED: [S.RUNNING, S.RUNNING, S.SYNCWAITING, S.IDLE_SYNCHRONIZED, S.FAILURE],
}  # fmt: skip

# A take-back during an unanswered upload cancels the upload (legality.take_back_refusal).
ALSO = {"unsynchronize": (EventKind.UPLOAD_CANCELLED,)}
# The event each operation emits when it is accepted.
KIND = {
    "add_skill": EventKind.SKILL_ADDED,
    "edit_skill": EventKind.SKILL_EDITED,
    "delete_skills": EventKind.SKILL_DELETED,
    "reorder": EventKind.SKILLS_REORDERED,
    "move_skills": EventKind.SKILLS_REORDERED,
    "synchronize": EventKind.SYNC_REQUESTED,
    "confirm_synchronized": EventKind.SYNC_CONFIRMED,
    "decline_synchronize": EventKind.SYNC_DECLINED,
    "cancel_uploads": EventKind.UPLOAD_CANCELLED,
    "unsynchronize": EventKind.UNSYNC_REQUESTED,
    "confirm_unsynchronized": EventKind.UNSYNC_CONFIRMED,
    "report_status": EventKind.STATUS_CHANGED,
    "stop": EventKind.SKILL_STOPPED,
    "retry": EventKind.SKILL_RETRIED,
    "skip": EventKind.SKILL_SKIPPED,
    "add_barrier": EventKind.BARRIER_ADDED,
    "delete_barrier": EventKind.BARRIER_DELETED,
    "add_marker": EventKind.MARKER_ADDED,
    "move_marker": EventKind.MARKER_MOVED,
    "rename_marker": EventKind.MARKER_RENAMED,
    "delete_marker": EventKind.MARKER_DELETED,
    "new_mission": EventKind.MISSION_REPLACED,
    "load": EventKind.MISSION_REPLACED,
}

coordinates = st.floats(-100.0, 100.0, allow_nan=False, width=32)
poses = st.builds(Pose, x=coordinates, y=coordinates, yaw=st.floats(-3.0, 3.0, width=32))
junk = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-3, 50),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=3),
    st.lists(st.integers(), max_size=2),
    st.dictionaries(st.sampled_from(["x", "y", "w"]), st.floats(allow_nan=True), max_size=2),
)
texts = st.text(alphabet="ab %", max_size=4)


def valid_values(spec: Any) -> st.SearchStrategy[Any]:
    """Values a parameter accepts."""
    if spec.choices:
        return st.sampled_from(spec.choices)
    if spec.type is ParamType.FLOAT:
        low = -1e3 if spec.minimum is None else spec.minimum
        high = 1e3 if spec.maximum is None else spec.maximum
        return st.floats(low, high, allow_nan=False)
    if spec.type is ParamType.INT:
        low = -100 if spec.minimum is None else math.ceil(spec.minimum)
        high = 100 if spec.maximum is None else math.floor(spec.maximum)
        return st.integers(low, high)
    if spec.type is ParamType.BOOL:
        return st.booleans()
    if spec.type is ParamType.STRING:
        return st.text(max_size=4)
    if spec.type is ParamType.POSE:
        return st.fixed_dictionaries({"x": coordinates, "y": coordinates})
    if spec.type is ParamType.LIST:
        points = st.fixed_dictionaries({"x": coordinates, "y": coordinates})
        return st.lists(points, min_size=3 if spec.marker_type else 0, max_size=5)
    return st.dictionaries(st.text(max_size=2), st.integers(), max_size=2)


def deadlocks(tasks: dict[str, list[str]], groups: list[tuple[str, ...]]) -> bool:
    """An independent oracle: merge each barrier into one node and look for a cycle.

    Kahn's algorithm over every "runs before" edge of every task; nodes left
    over once no node without predecessors remains lie on (or behind) a cycle.
    """
    node = {skill_id: f"barrier {n}" for n, group in enumerate(groups) for skill_id in group}
    edges: dict[str, set[str]] = {}
    for ids in tasks.values():
        names = [node.get(skill_id, skill_id) for skill_id in ids]
        for name in names:
            edges.setdefault(name, set())
        for before, after in itertools.pairwise(names):
            edges[before].add(after)
    incoming = {name: 0 for name in edges}
    for targets in edges.values():
        for target in targets:
            incoming[target] += 1
    ready = [name for name, count in incoming.items() if count == 0]
    removed = 0
    while ready:
        name = ready.pop()
        removed += 1
        for target in edges[name]:
            incoming[target] -= 1
            if incoming[target] == 0:
                ready.append(target)
    return removed < len(edges)


def snapshot(mission: Mission) -> str:
    """The mission as data, frozen into text (a fast deep copy to compare against)."""
    return json.dumps(mission_to_dict(mission.state.content(), mission.revision))


class MissionMachine(RuleBasedStateMachine):
    """One mission under random requests and robot behaviour."""

    def __init__(self) -> None:
        super().__init__()
        counter = itertools.count(1)
        self.now = 1000.0
        self.mission = Mission(
            LIBRARY, clock=lambda: self.now, new_id=lambda prefix: f"{prefix}-{next(counter)}"
        )
        self.start = self.mission.state.content()
        self.events: list[MissionEvent] = []
        self.follower = MissionState(self.start, self.mission.revision)  # a client's copy
        self.described = DescribedView(self.follower)
        self.followed = 0  # events the follower has applied
        self.finished: dict[str, SkillInstance] = {}
        self.renamed: dict[str, str] = {}  # markers renamed since the last invariant check
        self.saved_revision = -1

    # -- helpers -------------------------------------------------------------------------
    def attempt(self, name: str, *args: Any, **kwargs: Any) -> MissionEvent | None:
        """Run one request; check the revision/event contract or the rejection contract."""
        self.now += 1.0
        before, revision = snapshot(self.mission), self.mission.revision
        try:
            event = getattr(self.mission, name)(*args, **kwargs)
        except RosmcError as error:
            message = str(error)
            assert message.strip() and "\n" not in message, repr(message)
            assert self.mission.revision == revision, name
            assert snapshot(self.mission) == before, f"rejected {name} changed the mission"
            return None
        assert isinstance(event, MissionEvent)
        assert self.mission.revision == revision + 1 == event.revision, name
        assert event.kind is KIND[name] or event.kind in ALSO.get(name, ()), (name, event.kind)
        assert event.stamp == self.now
        assert event.summary.strip()
        self.events.append(event)
        if event.kind is EventKind.MISSION_REPLACED:
            self.finished = {s.id: s for s in self.mission.state.skills() if s.status.is_final}
        return event

    def skill_ids(self) -> list[str]:
        return [skill.id for skill in self.mission.state.skills()]

    def any_skill(self, data: Any) -> str:
        ids = self.skill_ids()
        return str(data.draw(st.sampled_from([*ids, "ghost"]) if ids else st.just("ghost")))

    def agent(self, data: Any, where: Callable[[list[SkillInstance]], bool] | None = None) -> str:
        """A robot; mostly one whose task satisfies ``where`` (if any does)."""
        agents = list(AGENTS)
        if where is not None and not self.rarely(data):
            fitting = [a for a in AGENTS if where(list(self.mission.state.task(a)))]
            agents = fitting or agents
        return str(data.draw(st.sampled_from(agents)))

    def marker_name(self, data: Any) -> str:
        names = [m.name for m in self.mission.state.markers]
        return str(data.draw(st.sampled_from([*names, *MARKER_NAMES])))

    @staticmethod
    def rarely(data: Any) -> bool:
        """True about one time in eight (hypothesis favours small integers, so not 0)."""
        return bool(data.draw(st.integers(1, 8)) == 5)

    def markers_for(self, param: Any) -> list[str]:
        """Existing markers that may fill ``param``."""
        return [m.name for m in self.mission.state.markers if param.accepts_marker(m.type)]

    def pending(self, agent: str, transfer: Transfer) -> list[str]:
        return [s.id for s in self.mission.state.task(agent) if s.transfer is transfer]

    @initialize(data=st.data())
    def seed(self, data: Any) -> None:
        """Start from a mission with markers of each type and a few skills per robot."""
        seeds = [
            TaskMarker("rock", MarkerType.POSE, Pose(5.0, 5.0)),
            TaskMarker("site", MarkerType.POSITION, Pose(-3.0, 2.0)),
            TaskMarker("zone", MarkerType.AREA, Pose(), (Pose(0, 0), Pose(8, 0), Pose(8, 8))),
        ]
        for marker in seeds:
            assert self.attempt("add_marker", marker)
        for agent in AGENTS:
            skills = LIBRARY.skills_of(agent)
            for _ in range(data.draw(st.integers(1, 4))):
                name = data.draw(st.sampled_from(sorted(skills)))
                bindings = {}
                for param in skills[name].parameters:
                    fitting = self.markers_for(param)
                    if fitting and data.draw(st.booleans()):
                        bindings[param.name] = fitting[0]
                assert self.attempt("add_skill", agent, name, bindings=bindings)
            if data.draw(st.booleans()):
                task = [s.id for s in self.mission.state.task(agent)]
                assert self.attempt("synchronize", agent, data.draw(st.sampled_from(task)))
                uploading = self.pending(agent, Transfer.UPLOADING)
                assert self.attempt("confirm_synchronized", agent, uploading)

    # -- blueprint editing ---------------------------------------------------------------
    @rule(data=st.data())
    def add_skill(self, data: Any) -> None:
        agent = self.agent(data)
        if self.rarely(data):
            agent = data.draw(st.sampled_from(["lander", "zulu"]))
        skills = sorted(LIBRARY.skills_of(agent)) if agent in AGENTS else ["navigate_to"]
        skill = data.draw(st.sampled_from(skills))
        if self.rarely(data):
            skill = "bogus"
        params: dict[str, Any] = {}
        bindings: dict[str, str] = {}
        spec = LIBRARY.skills_of(agent).get(skill) if agent in AGENTS else None
        if spec is not None and spec.parameters and data.draw(st.booleans()):
            param = data.draw(st.sampled_from(spec.parameters))
            bad = self.rarely(data)
            params[param.name] = data.draw(junk if bad else valid_values(param))
        if spec is not None and data.draw(st.booleans()):
            markable = [p for p in spec.parameters if p.marker_type is not None]
            if markable:
                param = data.draw(st.sampled_from(markable))
                fitting = self.markers_for(param)
                if fitting and not self.rarely(data):
                    bindings[param.name] = data.draw(st.sampled_from(fitting))
                else:
                    bindings[param.name] = self.marker_name(data)
                params.pop(param.name, None)
        index = None
        if agent in AGENTS and data.draw(st.booleans()):
            length = len(self.mission.state.task(agent))
            start = self.mission.state.sections(agent).editable_start
            index = data.draw(st.integers(start, length))
            if self.rarely(data):
                index = data.draw(st.sampled_from([-1, length + 1, max(start - 1, 0)]))
        self.attempt("add_skill", agent, skill, params, bindings=bindings, index=index)

    @rule(data=st.data(), count=st.integers(1, 3))
    def add_several(self, data: Any, count: int) -> None:
        agent = self.agent(data)
        for _ in range(count):
            skill = data.draw(st.sampled_from(sorted(LIBRARY.skills_of(agent))))
            assert self.attempt("add_skill", agent, skill)

    @rule(data=st.data())
    def edit_skill(self, data: Any) -> None:
        editable = [s.id for s in self.mission.state.skills() if s.is_editable]
        skill_id = self.any_skill(data)
        if editable and not self.rarely(data):
            skill_id = data.draw(st.sampled_from(editable))
        kwargs: dict[str, Any] = {}
        params: dict[str, Any] = {}
        what = data.draw(st.sampled_from(["param", "param", "label", "bind", "unbind"]))
        if self.rarely(data):
            what = "nothing"
        if self.mission.state.has_skill(skill_id):
            skill = self.mission.state.skill(skill_id)
            spec = LIBRARY.skill(skill.agent, skill.skill)
            if what == "param" and spec.parameters:
                param = data.draw(st.sampled_from(spec.parameters))
                bad = self.rarely(data)
                params[param.name] = data.draw(junk if bad else valid_values(param))
            markable = [p for p in spec.parameters if p.marker_type is not None]
            if what in ("bind", "unbind") and markable:
                param = data.draw(st.sampled_from(markable))
                marker: str | None = None
                if what == "bind":
                    fitting = self.markers_for(param)
                    marker = self.marker_name(data)
                    if fitting and not self.rarely(data):
                        marker = data.draw(st.sampled_from(fitting))
                kwargs["bindings"] = {param.name: marker}
        if what == "label":
            kwargs["label"] = data.draw(st.sampled_from(["new label", "other", "", "a\nb"]))
        self.attempt("edit_skill", skill_id, params, **kwargs)

    @rule(data=st.data())
    def delete_skills(self, data: Any) -> None:
        count = data.draw(st.integers(0, 2))
        self.attempt("delete_skills", [self.any_skill(data) for _ in range(count)])

    @rule(data=st.data())
    def reorder(self, data: Any) -> None:
        agent = self.agent(data)
        start = self.mission.state.sections(agent).editable_start
        order = [s.id for s in self.mission.state.task(agent)[start:]]
        order = data.draw(st.permutations(order)) if order else []
        corruption = "none"
        if self.rarely(data):
            corruption = data.draw(st.sampled_from(["drop", "dup", "foreign"]))
        if corruption == "drop" and order:
            order = order[1:]
        elif corruption == "dup" and order:
            order = [*order[1:], order[1 % len(order)]]
        elif corruption == "foreign":
            order = [*order[1:], self.any_skill(data)]
        self.attempt("reorder", agent, order)

    @rule(data=st.data())
    def move_skills(self, data: Any) -> None:
        agent = self.agent(data)
        task = self.mission.state.task(agent)
        start = self.mission.state.sections(agent).editable_start
        ids = [s.id for s in task[start:]] or ["ghost"]
        indexes = st.integers(start, max(start, len(task) - 1))
        if self.rarely(data):  # another robot's skill, a started one, an index outside
            ids, indexes = [*ids, self.any_skill(data)], st.integers(-1, len(task) + 1)
        moves = st.builds(SkillMove, st.sampled_from(ids), indexes)
        self.attempt("move_skills", agent, data.draw(st.lists(moves, max_size=3)))

    # -- synchronization -----------------------------------------------------------------
    @rule(data=st.data())
    def synchronize(self, data: Any) -> None:
        agent = self.agent(data)
        task = [s.id for s in self.mission.state.task(agent)]
        upto = data.draw(st.sampled_from([None, *task, "ghost"]))
        self.attempt("synchronize", agent, upto)

    @rule(data=st.data())
    def upload(self, data: Any) -> None:
        """Synchronize a prefix and let the robot take it: the common case."""
        agent = self.agent(data, lambda task: any(s.is_editable for s in task))
        start = self.mission.state.sections(agent).editable_start
        editable = [s.id for s in self.mission.state.task(agent)[start:]]
        if self.pending(agent, Transfer.REMOVING) or not editable:
            return
        upto = data.draw(st.sampled_from([None, *editable]))
        assert self.attempt("synchronize", agent, upto)
        assert self.attempt("confirm_synchronized", agent, self.pending(agent, Transfer.UPLOADING))

    @rule(data=st.data())
    def robot_answers_upload(self, data: Any) -> None:
        agent = self.agent(data, lambda task: any(s.transfer is Transfer.UPLOADING for s in task))
        uploading = self.pending(agent, Transfer.UPLOADING)
        how = data.draw(st.sampled_from(["confirm", "confirm", "decline", "cancel"]))
        if self.rarely(data):
            how = "garbage"
        if how == "cancel":
            # The operator gives up waiting for the robot's answer.
            event = self.attempt("cancel_uploads", agent)
            assert (event is not None) == bool(uploading)
            return
        if how == "garbage" or not uploading:
            ids = data.draw(st.lists(st.sampled_from([*uploading, "ghost"]), max_size=3))
            name = "confirm_synchronized" if how == "confirm" else "decline_synchronize"
            args = (agent, ids) if name == "confirm_synchronized" else (agent, ids, "no")
            self.attempt(name, *args)
            return
        count = data.draw(st.integers(1, len(uploading)))
        if how == "confirm":
            assert self.attempt("confirm_synchronized", agent, uploading[:count])
        else:
            assert self.attempt("decline_synchronize", agent, uploading[-count:], "busy")

    @rule(data=st.data())
    def unsynchronize(self, data: Any) -> None:
        agent = self.agent(data, lambda task: any(s.status is S.IDLE_SYNCHRONIZED for s in task))
        task = [s.id for s in self.mission.state.task(agent)]
        self.attempt("unsynchronize", agent, data.draw(st.sampled_from([None, *task, "ghost"])))

    @rule(data=st.data())
    def robot_answers_unsync(self, data: Any) -> None:
        """The robot had started the first few skills asked back; it returns the rest."""
        agent = self.agent(data, lambda task: any(s.transfer is Transfer.REMOVING for s in task))
        removing = self.pending(agent, Transfer.REMOVING)
        if not removing or self.rarely(data):
            ids = data.draw(st.lists(st.sampled_from([*removing, "ghost"]), max_size=3))
            self.attempt("confirm_unsynchronized", agent, ids)
            return
        started = data.draw(st.integers(0, len(removing)))
        for position, skill_id in enumerate(removing[:started]):
            if not self.attempt("report_status", skill_id, S.RUNNING):
                break  # not its turn: the robot cannot have started it
            if position < started - 1:
                assert self.attempt("report_status", skill_id, S.SUCCESS)
        remaining = self.pending(agent, Transfer.REMOVING)
        event = self.attempt("confirm_unsynchronized", agent, remaining)
        # Once the robot has reported every skill asked back as started, nothing is
        # pending any more and its late answer is refused (the ground link skips it).
        assert (event is not None) == bool(remaining)

    # -- robot reports -------------------------------------------------------------------
    @rule(data=st.data(), steps=st.integers(1, 6))
    def robot_progresses(self, data: Any, steps: int) -> None:
        """Legal reports: a robot moves its current skill on, a few times."""
        for _ in range(steps):
            state = self.mission.state
            current = {}
            for agent in AGENTS:
                synced = state.task(agent)[: state.sections(agent).synced_end]
                skill = next((s for s in synced if not s.is_settled), None)
                if skill is not None and skill.status in ROBOT_NEXT:
                    current[agent] = skill
            if not current:
                return
            skill = current[data.draw(st.sampled_from(sorted(current)))]
            status = data.draw(st.sampled_from(ROBOT_NEXT[skill.status]))
            text = f"step {self.now}" if status is skill.status else ""
            attempt = skill.attempt + data.draw(st.sampled_from([0, 0, 0, 1]))
            event = self.attempt("report_status", skill.id, status, attempt=attempt, text=text)
            assert event is not None, f"legal report {skill.status.name} -> {status.name} refused"

    @rule(data=st.data())
    def robot_reports_anything(self, data: Any) -> None:
        """A random, usually illegal, report."""
        kwargs: dict[str, Any] = {}
        if data.draw(st.booleans()):
            kwargs["attempt"] = data.draw(st.integers(0, 4))
        if data.draw(st.booleans()):
            kwargs["text"] = data.draw(texts)
        status = data.draw(st.sampled_from(list(S)))
        self.attempt("report_status", self.any_skill(data), status, **kwargs)

    @rule(data=st.data())
    def stop(self, data: Any) -> None:
        self.attempt("stop", self.agent(data, lambda task: any(s.status.is_active for s in task)))

    @rule(data=st.data())
    def retry_or_skip(self, data: Any) -> None:
        failures = [
            s.id
            for s in self.mission.state.skills()
            if s.status is S.FAILURE and s.resolution is Resolution.NONE
        ]
        skill_id = self.any_skill(data)
        if failures and not self.rarely(data):
            skill_id = data.draw(st.sampled_from(failures))
        operation = data.draw(st.sampled_from(["retry", "skip"]))
        self.attempt(operation, skill_id)

    # -- barriers ------------------------------------------------------------------------
    def add_barrier(self, data: Any) -> None:
        state = self.mission.state
        members = []
        chosen = data.draw(st.lists(st.sampled_from(AGENTS), min_size=2, max_size=3, unique=True))
        for agent in chosen:
            task = [
                s.id
                for s in state.task(agent)
                if s.status in (S.IDLE, S.IDLE_SYNCHRONIZED) and state.barrier_of(s.id) is None
            ]
            if self.rarely(data):
                task = [s.id for s in state.task(agent)]
            if task:
                members.append(data.draw(st.sampled_from(task)))
        if self.rarely(data):
            members.append(self.any_skill(data))
        self.attempt("add_barrier", members)

    def delete_barrier(self, data: Any) -> None:
        ids = [b.id for b in self.mission.state.barriers]
        self.attempt("delete_barrier", data.draw(st.sampled_from([*ids, *ids, "ghost"])))

    # -- markers -------------------------------------------------------------------------
    def add_marker(self, data: Any) -> None:
        kind = data.draw(st.sampled_from(list(MarkerType)))
        count = (3, 5) if kind is MarkerType.AREA else (0, 0)
        if self.rarely(data):
            count = (0, 2) if kind is MarkerType.AREA else (1, 3)
        vertices = data.draw(st.lists(poses, min_size=count[0], max_size=count[1]))
        name = data.draw(st.sampled_from(MARKER_NAMES))
        self.attempt("add_marker", TaskMarker(name, kind, data.draw(poses), tuple(vertices)))

    def move_marker(self, data: Any) -> None:
        name = self.marker_name(data)
        vertices: list[Pose] = []
        if self.mission.state.has_marker(name):
            area = self.mission.state.marker(name).type is MarkerType.AREA
            if area != self.rarely(data):
                vertices = data.draw(st.lists(poses, min_size=3, max_size=5))
        self.attempt("move_marker", name, data.draw(poses), vertices)

    def rename_marker(self, data: Any) -> None:
        old, new = self.marker_name(data), self.marker_name(data)
        if self.attempt("rename_marker", old, new) is not None:
            self.renamed[old] = new

    def delete_marker(self, data: Any) -> None:
        self.attempt("delete_marker", self.marker_name(data))

    # -- whole missions and conflicts --------------------------------------------------------
    def stale_request(self, data: Any) -> None:
        """A request made before another operator's change (or from the future) is refused."""
        revision, newest = self.mission.revision, self.mission.operator_revision
        if newest == 0:
            return
        base = data.draw(st.sampled_from([newest - 1, 0, revision + 1]))
        requests: list[Callable[[], object]] = [
            lambda: self.mission.add_skill("drone", "land", base_revision=base),
            lambda: self.mission.new_mission(base_revision=base),
            lambda: self.mission.add_marker(
                TaskMarker("", MarkerType.POSE, Pose()), base_revision=base
            ),
            lambda: self.mission.stop("drone", base_revision=base),
        ]
        before = snapshot(self.mission)
        try:
            data.draw(st.sampled_from(requests))()
        except StaleRevision as error:
            assert (error.base_revision, error.current_revision) == (base, revision)
            assert f"revision {base}" in str(error) and f"revision {revision}" in str(error)
        else:
            raise AssertionError(f"a request based on revision {base} was accepted")
        assert snapshot(self.mission) == before and self.mission.revision == revision

    def request_after_robot_progress(self, data: Any) -> None:
        """A request based on any revision since the last operator change goes through."""
        base = data.draw(st.integers(self.mission.operator_revision, self.mission.revision))
        assert self.attempt("add_skill", "drone", "land", base_revision=base)

    def new_mission(self, data: Any) -> None:
        if self.rarely(data):
            self.attempt("new_mission", keep_markers=data.draw(st.booleans()))

    def reload(self, data: Any) -> None:
        if self.rarely(data):
            text = dump_mission(self.mission.state.content(), self.mission.revision)
            content, _ = parse_mission(text, LIBRARY, "saved.yaml")
            self.attempt("load", content, "saved.yaml")

    # Related requests share one rule, so that hypothesis (which picks rules evenly)
    # spends most steps on building skills and running them.
    @rule(data=st.data())
    def barrier_request(self, data: Any) -> None:
        name = data.draw(st.sampled_from(["add_barrier", "add_barrier", "delete_barrier"]))
        getattr(self, name)(data)

    @rule(data=st.data())
    def marker_request(self, data: Any) -> None:
        names = ["add_marker", "move_marker", "rename_marker", "delete_marker"]
        getattr(self, data.draw(st.sampled_from(names)))(data)

    @rule(data=st.data())
    def revision_check(self, data: Any) -> None:
        names = ["stale_request", "request_after_robot_progress"]
        getattr(self, data.draw(st.sampled_from(names)))(data)

    @rule(data=st.data())
    def replace_mission(self, data: Any) -> None:
        getattr(self, data.draw(st.sampled_from(["new_mission", "reload"])))(data)

    # -- invariants ------------------------------------------------------------------------
    @invariant()
    def sections_are_ordered(self) -> None:
        state = self.mission.state
        for agent in state.agents:
            task = state.task(agent)
            rank = [0 if s.status is not S.IDLE else (1 if s.transfer is Transfer.UPLOADING else 2)
                    for s in task]  # fmt: skip
            assert rank == sorted(rank), (agent, [(s.status.name, s.transfer.name) for s in task])
            sections = state.sections(agent)
            assert rank.count(0) == sections.synced_end
            assert rank.count(0) + rank.count(1) == sections.editable_start
            unsettled = False
            for skill in task:
                assert skill.agent == agent
                if skill.transfer is Transfer.REMOVING:
                    assert skill.status is S.IDLE_SYNCHRONIZED
                if skill.status.has_started:
                    assert not unsettled, f"{skill.id} started before an earlier skill was done"
                unsettled = unsettled or not skill.is_settled
                if skill.resolution is not Resolution.NONE:
                    assert skill.status is S.FAILURE

    @invariant()
    def ids_are_unique_and_indexed(self) -> None:
        state = self.mission.state
        ids = self.skill_ids()
        barrier_ids = [b.id for b in state.barriers]
        assert len(set(ids)) == len(ids)
        assert len(set(ids + barrier_ids)) == len(ids) + len(barrier_ids)
        for skill_id in ids:
            agent, index = state.locate(skill_id)
            assert state.task(agent)[index].id == skill_id
        for marker in state.markers:
            bound = {s.id for s in state.skills() if marker.name in s.bindings.values()}
            assert {s.id for s in state.bound_to(marker.name)} == bound
        for skill in state.skills():
            for marker_name in skill.bindings.values():
                assert state.has_marker(marker_name), (skill.id, marker_name)

    @invariant()
    def finished_skills_never_change(self) -> None:
        """A finished skill is a log: only its resolution changes, and the name of a marker
        it is bound to follows a rename (bindings always name an existing marker)."""
        present = {s.id: s for s in self.mission.state.skills()}
        for skill_id, recorded in self.finished.items():
            assert skill_id in present, f"finished skill {skill_id} disappeared"
            now = present[skill_id]
            followed = {param: self.renamed.get(m, m) for param, m in recorded.bindings.items()}
            assert now.bindings == followed, (skill_id, recorded.bindings, now.bindings)
            recorded = replace(recorded, bindings=now.bindings)
            if recorded.resolution is not Resolution.NONE:
                assert now == recorded
            else:
                assert now.resolution in (Resolution.NONE, Resolution.RETRIED, Resolution.SKIPPED)
                assert now == replace(recorded, resolution=now.resolution)
        self.finished = {s.id: s for s in self.mission.state.skills() if s.status.is_final}
        self.renamed = {}

    @invariant()
    def barriers_are_sound(self) -> None:
        state = self.mission.state
        members: list[str] = []
        for barrier in state.barriers:
            assert len(barrier.skill_ids) >= 2
            agents = [state.locate(skill_id)[0] for skill_id in barrier.skill_ids]
            assert len(set(agents)) == len(agents)
            members += barrier.skill_ids
            for skill_id in barrier.skill_ids:
                assert state.barrier_of(skill_id) == barrier
        assert len(set(members)) == len(members)
        tasks = {agent: [s.id for s in state.task(agent)] for agent in state.agents}
        groups = [b.skill_ids for b in state.barriers]
        assert not deadlocks(tasks, groups)
        assert find_deadlock(tasks, groups) is None

    @invariant()
    def indexes_match_the_tasks(self) -> None:
        """Positions and each task's barrier members, as the state keeps them, match a scan."""
        state = self.mission.state
        members = {s for barrier in state.barriers for s in barrier.skill_ids}
        for agent in state.agents:
            ids = [s.id for s in state.task(agent)]
            assert [state.locate(s) for s in ids] == [(agent, i) for i in range(len(ids))]
            ordered = [None, *(s for s in ids if s in members), None]
            for before, member, after in zip(ordered, ordered[1:-1], ordered[2:], strict=False):
                assert member is not None and state.members_around(member) == (before, after)

    @invariant()
    def save_and_load_reproduce_the_mission(self) -> None:
        """The file form holds the whole mission: checked on the data after every change."""
        content, revision = self.mission.state.content(), self.mission.revision
        if revision == self.saved_revision:
            return  # unchanged since the last check (rejections leave it identical)
        self.saved_revision = revision
        data = mission_to_dict(content, revision)
        assert mission_from_dict(data, LIBRARY, "property.yaml") == (
            content,
            revision,
        )

    def teardown(self) -> None:
        """The YAML text itself (slow with PyYAML) is checked once per example, at the end."""
        content, revision = self.mission.state.content(), self.mission.revision
        text = dump_mission(content, revision)
        loaded, loaded_revision = parse_mission(text, LIBRARY, "property.yaml")
        assert (loaded, loaded_revision) == (content, revision)
        assert dump_mission(loaded, loaded_revision) == text

    @invariant()
    def described_changes_rebuild_the_mission(self) -> None:
        """New events through the one applier, as a client applies them: its state and the
        view kept from the changes it describes are the server's mission."""
        for event in self.events[self.followed :]:
            self.described.take(apply_event(self.follower, event))
        self.followed = len(self.events)
        assert self.follower.revision == self.mission.revision
        assert self.described.matches(self.mission.state)

    @invariant()
    def replay_rebuilds_the_mission(self) -> None:
        fresh = Mission(LIBRARY, content=self.start)
        for event in self.events:
            fresh.replay(event)
        assert fresh.revision == self.mission.revision
        assert fresh.operator_revision == self.mission.operator_revision <= self.mission.revision
        assert snapshot(fresh) == snapshot(self.mission)


MissionMachine.TestCase.settings = settings(
    max_examples=100,
    stateful_step_count=35,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
TestMission = MissionMachine.TestCase


@st.composite
def barrier_layouts(draw: Any) -> tuple[dict[str, list[str]], list[tuple[str, ...]]]:
    """Tasks of 2-4 agents and disjoint barriers over skills of distinct agents."""
    agents = [f"r{n}" for n in range(draw(st.integers(2, 4)))]
    tasks = {a: [f"{a}s{i}" for i in range(draw(st.integers(0, 6)))] for a in agents}
    free = {a: list(ids) for a, ids in tasks.items()}
    groups: list[tuple[str, ...]] = []
    for _ in range(draw(st.integers(0, 5))):
        candidates = [a for a in agents if free[a]]
        if len(candidates) < 2:
            break
        chosen = draw(st.lists(st.sampled_from(candidates), min_size=2, max_size=4, unique=True))
        group = []
        for agent in chosen:
            skill = draw(st.sampled_from(free[agent]))
            free[agent].remove(skill)
            group.append(skill)
        groups.append(tuple(group))
    return tasks, groups


@settings(max_examples=300, deadline=None)
@given(barrier_layouts())
def test_find_deadlock_agrees_with_an_independent_check(layout: Any) -> None:
    tasks, groups = layout
    cycle = find_deadlock(tasks, groups)
    assert (cycle is not None) == deadlocks(tasks, groups)
    if cycle is not None:
        # The named cycle is real: each edge follows its task's order and the
        # edges chain through shared barriers back to the start.
        point = {s: n for n, group in enumerate(groups) for s in group}
        for edge in cycle:
            ids = tasks[edge.agent]
            assert ids.index(edge.before) < ids.index(edge.after)
        for first, second in itertools.pairwise([*cycle, cycle[0]]):
            assert point.get(first.after, first.after) == point.get(second.before, second.before)
