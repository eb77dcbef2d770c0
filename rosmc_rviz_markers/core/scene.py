"""The whole picture: which interactive markers a mission shows, and which an update touches.

:class:`Scene` answers two questions for the node: *what does marker X look like now*
(:meth:`Scene.specs_for`) and *which markers does this mirror update touch*
(:meth:`Scene.touched`). The node republishes only the touched ones whose spec changed,
so an event costs what it changes, not the size of the mission. Laying the labels out
(:meth:`Scene.relayout`) looks at every task marker, but is plain arithmetic, and only
the markers whose label moved are republished. It depends on the task markers alone:
robots move all the time, so their status blocks keep clear of the task labels
(:attr:`Scene.label_boxes`), not the other way round; a robot driving by (and its
telemetry at 10 Hz) then costs no task marker anything.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field, replace

from rosmc_server.core.live.updates import (
    AgentStatusChanged,
    MarkerPut,
    MarkerRemoved,
    MirrorUpdate,
    MissionReset,
    SkillAdded,
    SkillChanged,
    SkillRemoved,
)
from rosmc_server.core.model.model import SkillInstance
from rosmc_server.core.model.state import MissionState
from rosmc_server.core.robots.agent_status import AgentStatus
from rosmc_server.core.skills.library import AgentKind, Library
from rosmc_server.core.views import geometry as geo
from rosmc_server.interface import MAP_FRAME

from .labels import Box, Label, layout
from .menus import (
    OBJECT_WORD,
    ROBOT_WORD,
    UNDO_MENU,
    flatten,
    robot_menu,
    static_agent_menu,
    task_marker_menu,
    title_menu,
)
from .specs import MarkerSpec, agent_spec, describe, task_label, task_specs
from .styling import is_locked, marker_use

LABEL_STEP = 0.25  # task labels move south by whole steps (m)
UNHEARD_AT = (-5.0, 3.0)  # where agents without TF or a reported pose wait (m, map frame),
UNHEARD_STEP = 3.0  # side by side southwards, beside the lander at the origin


@dataclass(frozen=True)
class Selection:
    """What an operator selected (``rosmc/Selection``): skills and task markers."""

    skill_ids: frozenset[str] = frozenset()
    marker_names: frozenset[str] = frozenset()


@dataclass
class Touched:
    """What an update touched: task marker names, agents (bodies) and agents (icons)."""

    everything: bool = False
    markers: set[str] = field(default_factory=set)
    agents: set[str] = field(default_factory=set)
    icons: set[str] = field(default_factory=set)

    def __bool__(self) -> bool:
        return self.everything or bool(self.markers or self.agents or self.icons)


class Scene:
    """Computes marker specs from the library, the mission, robot statuses and the selection.

    Args:
        library: The mission's skill library.
        read_only: A replay view: no menus, nothing draggable.
        follow_tf: Agents follow their TF frames (live); otherwise they are placed in the
            map frame at the pose their status reports (a replay has no TF). An agent
            whose frame is missing (:meth:`set_tf_missing`: not started, powered off) is
            placed so too, labelled "not heard": rviz holds back every marker of an update
            until it can transform each one, so one missing frame would hide them all.
    """

    def __init__(self, library: Library, *, read_only: bool = False, follow_tf: bool = True):
        self.library = library
        self.read_only = read_only
        self.follow_tf = follow_tf
        self.selection = Selection()
        self.label_south: dict[str, float] = {}  # task marker -> its label moved south (m)
        self.label_boxes: tuple[Box, ...] = ()  # where the task labels are, as laid out
        self._labels: dict[str, Label] = {}  # task marker -> its label before the layout
        self.tf_missing: frozenset[str] = frozenset()  # agents whose TF frame is not there

    def set_tf_missing(self, agents: Iterable[str]) -> Touched:
        """Take the agents whose TF frame is missing; returns those whose body changes."""
        old, self.tf_missing = self.tf_missing, frozenset(agents)
        return Touched(agents=set(old ^ self.tf_missing), icons=set(old ^ self.tf_missing))

    # -- which markers an update touches -------------------------------------------------------
    def touched(self, update: MirrorUpdate) -> Touched:
        """The markers and icons ``update`` may have changed."""
        out = Touched()
        for change in update.changes:
            if isinstance(change, MissionReset):
                out.everything = True
            elif isinstance(change, (SkillAdded, SkillRemoved)):
                out.markers.update(change.skill.bindings.values())
                out.icons.add(change.skill.agent)
            elif isinstance(change, SkillChanged):
                old, new = change.old, change.new
                if (old.status, old.transfer, old.bindings) != (
                    new.status,
                    new.transfer,
                    new.bindings,
                ):
                    out.markers.update(old.bindings.values())
                    out.markers.update(new.bindings.values())
                if old.label != new.label:
                    out.icons.add(new.agent)
            elif isinstance(change, MarkerPut):
                out.markers.add(change.new.name)
                if change.old is not None:
                    out.markers.add(change.old.name)
            elif isinstance(change, MarkerRemoved):
                out.markers.add(change.marker.name)
            elif isinstance(change, AgentStatusChanged):
                out.icons.add(change.new.agent)
                if not self.follow_tf or change.new.agent in self.tf_missing:
                    out.agents.add(change.new.agent)
        return out

    def select(self, selection: Selection, state: MissionState | None) -> Touched:
        """Take a new selection; returns the markers whose highlight changes."""
        old, self.selection = self.selection, selection
        out = Touched()
        for sel in (old, selection):
            out.markers.update(sel.marker_names)
            if state is None:
                continue
            for skill_id in sel.skill_ids:
                if state.has_skill(skill_id):
                    skill = state.skill(skill_id)
                    out.markers.update(skill.bindings.values())
                    out.agents.add(skill.agent)
        return out

    # -- what a marker looks like -------------------------------------------------------------
    def agents(self) -> list[str]:
        """Every agent of the library (robots and static agents)."""
        return [a.name for a in self.library.agents]

    def agent_spec(
        self, agent: str, state: MissionState | None, status: AgentStatus | None
    ) -> MarkerSpec:
        """The marker of robot or static agent ``agent``."""
        spec = self.library.agent(agent)
        robot = spec.kind is AgentKind.DYNAMIC
        if self.read_only:
            menu = flatten(())
        elif robot:
            title = title_menu(agent, ROBOT_WORD)
            menu = flatten((title, *robot_menu(self.library, agent), *UNDO_MENU))
        else:
            title = title_menu(agent, OBJECT_WORD)
            menu = flatten((title, *static_agent_menu(self.library, agent), *UNDO_MENU))
        highlighted = state is not None and any(
            state.has_skill(s) and state.skill(s).agent == agent for s in self.selection.skill_ids
        )
        unheard = self.follow_tf and agent in self.tf_missing
        frame, position, yaw = None, (0.0, 0.0, 0.0), 0.0
        if not self.follow_tf or unheard:
            frame = MAP_FRAME
            if status is not None and status.pose is not None:
                position = (status.pose.x, status.pose.y, status.pose.z)
                yaw = status.pose.yaw
            elif unheard:
                index = [a for a in self.agents() if a in self.tf_missing].index(agent)
                position = (UNHEARD_AT[0], UNHEARD_AT[1] - UNHEARD_STEP * index, 0.0)
        made = agent_spec(
            agent,
            geo.body_kind(spec.model),
            menu,
            robot=robot,
            highlighted=highlighted,
            frame=frame,
            position=position,
            yaw=yaw,
        )
        return replace(made, description=f"{agent}: not heard") if unheard else made

    def relayout(self, state: MissionState, names: Iterable[str] | None = None) -> set[str]:
        """Lay the task markers' labels out clear of each other; returns the markers whose
        label moved (their specs changed).

        ``names``: the task markers that may have changed (None: any). Labels that did
        not change keep their place, and the changed ones find room around them (where
        they are drawn, if their marker did not move and it is still clear): an isolated
        edit moves its own label only. The robots' status blocks are laid out after, clear of
        :attr:`label_boxes`.
        """
        if names is None:
            self._labels = {}
            names = [marker.name for marker in state.markers]
        changed = set()
        keep, prefer = dict(self.label_south), {}
        for name in names:
            label, was = self._label(state, name), self._labels.get(name)
            if label == was:
                continue
            changed.add(name)
            keep.pop(name, None)
            if label is None:
                self._labels.pop(name, None)
                continue
            self._labels[name] = label
            if was is not None and was.x == label.x and name in self.label_south:
                # its marker did not move (new words, locked): the label stays where it is
                # drawn if that is still clear, rather than push its neighbours about
                south = self.label_south[name] + label.y - was.y
                if south >= 0:
                    prefer[name] = south
        if not changed:
            return set()  # no label changed its text or place: the layout stands
        labels = list(self._labels.values())
        # whole quarter metres, so that a marker dragged a little does not redraw its column
        new = layout(labels, step=LABEL_STEP, keep=keep, prefer=prefer)
        old, self.label_south = self.label_south, new
        self.label_boxes = tuple(label.box(new[label.key]) for label in labels)
        return {name for name in old.keys() | new.keys() if old.get(name) != new.get(name)}

    def _label(self, state: MissionState, name: str) -> Label | None:
        """Task marker ``name``'s label where it stands before the layout (None: no marker)."""
        if not state.has_marker(name):
            return None
        marker = state.marker(name)
        bound = state.bound_to(name)
        locked = is_locked(bound)
        text = describe(marker, marker_use(bound), locked)
        return task_label(marker, text, movable=not locked and not self.read_only)

    def marker_specs(self, state: MissionState, name: str) -> list[MarkerSpec]:
        """The interactive markers of task marker ``name`` (none if it does not exist)."""
        if not state.has_marker(name):
            return []
        marker = state.marker(name)
        bound = state.bound_to(name)
        locked = is_locked(bound)
        menu = flatten(
            ()
            if self.read_only
            else (
                title_menu(name, marker.type.name.lower()),
                *task_marker_menu(self.library, state, marker, bound, locked),
                *UNDO_MENU,
            )
        )
        return task_specs(
            marker,
            bound,
            marker_use(bound),
            menu,
            locked=locked,
            read_only=self.read_only,
            highlighted=self._highlighted(name, bound),
            label_south=self.label_south.get(name, 0.0),
        )

    def _highlighted(self, name: str, bound: Iterable[SkillInstance]) -> bool:
        if name in self.selection.marker_names:
            return True
        return any(skill.id in self.selection.skill_ids for skill in bound)
