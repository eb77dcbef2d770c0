"""The click menus of robots, static agents and task markers, computed from library and mission.

* Robot: ``Add skill ▸ <skill>`` (exactly that robot's skills). Pose parameters default to
  the robot's pose; a parameter that takes a task marker gets a new marker in front of the
  robot, already bound. Then ``Resume`` (what frees a robot holding after its lost-link
  policy acted).
* Static agent (lander, payload box): ``Add skill ▸ <robot> ▸ <skill>`` for the skills that
  take that object: a text parameter whose choices name it (``pick_box box=wifi_box``), or a
  skill whose name or description mentions it (``return_to_lander``, ``recharge``: "at the
  lander").
* Task marker: ``Add skill here ▸ <robot> ▸ <skill>`` for skills with a parameter that
  accepts the marker's kind (the new skill is bound to the marker); a skill that works at a
  point is offered a second time as ``<skill>, driving there first`` (the robot's move to
  the marker, then the skill, both bound) unless the robot's task already ends there;
  ``Rename ▸ <suggestion>`` and ``Delete`` (only when no skill uses it; rename only while it
  is not locked).
* Every one of them starts with an entry that names what was clicked, ``drone — robot``,
  ``RSS North — area`` (:func:`title_menu`; choosing it selects the object), and ends with
  ``Undo my last change`` and ``Redo`` (:data:`UNDO_MENU`).

Entries are numbered depth first from 1, as ``visualization_msgs/MenuEntry`` wants.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

from rosmc_server.core.model.model import SkillInstance, TaskMarker
from rosmc_server.core.model.state import MissionState
from rosmc_server.core.rules.edit_rules import MarkerAction, marker_refusal
from rosmc_server.core.rules.markers import generated_name
from rosmc_server.core.skills.library import AgentKind, Library, SkillSpec
from rosmc_server.core.skills.params import MarkerType, ParamType, Value
from rosmc_server.core.views.drive_first import ARRIVED, move_skill
from rosmc_server.core.views.places import first_location, location_xy


@dataclass(frozen=True)
class AddSkill:
    """Add ``skill`` to ``agent``'s blueprint.

    ``bind``: the parameter the clicked task marker fills (None: none). ``values``: fixed
    parameter values (a static agent's name). ``from_robot``: the robot's menu, so pose
    parameters take its pose and marker parameters get new markers in front of it.
    ``drive``: the robot's move skill and its target parameter, added (bound to the
    clicked marker) just before the skill.
    """

    agent: str
    skill: str
    bind: str | None = None
    values: tuple[tuple[str, Value], ...] = ()
    from_robot: bool = False
    drive: tuple[str, str] | None = None


@dataclass(frozen=True)
class RenameMarker:
    """Rename the clicked task marker to ``new_name``."""

    new_name: str


@dataclass(frozen=True)
class DeleteMarker:
    """Delete the clicked task marker."""


@dataclass(frozen=True)
class UndoEdit:
    """Undo the newest edit made in this rviz (``redo``: take back the newest undo)."""

    redo: bool = False


@dataclass(frozen=True)
class SelectObject:
    """Select the clicked object (the menu's first entry, the one that names it)."""


@dataclass(frozen=True)
class ResumeRobot:
    """Resume ``agent``: what frees a robot holding after its lost-link policy acted."""

    agent: str


EditAction = AddSkill | RenameMarker | DeleteMarker
MenuAction = EditAction | UndoEdit | SelectObject | ResumeRobot


@dataclass(frozen=True)
class Menu:
    """One menu entry: an action, or a submenu of ``children``."""

    title: str
    action: MenuAction | None = None
    children: tuple[Menu, ...] = ()


UNDO_MENU = (Menu("Undo my last change", UndoEdit()), Menu("Redo", UndoEdit(redo=True)))
"""Every marker's menu ends with these (see :mod:`rosmc_server.core.live.edit_history`)."""

ROBOT_WORD = "robot"
OBJECT_WORD = "object"


def title_menu(name: str, what: str) -> Menu:
    """The first entry of a menu: which object it belongs to (``drone — robot``).

    rviz opens a menu where the mouse is and shows no title: among robots, flags and
    labels close together the operator could not tell whose menu opened.
    """
    return Menu(f"{name} \u2014 {what}", SelectObject())


@dataclass(frozen=True)
class FlatEntry:
    """A numbered entry as rviz wants it (``parent`` 0: top level)."""

    id: int
    parent: int
    title: str
    action: MenuAction | None = None


@dataclass(frozen=True)
class FlatMenu:
    """A menu numbered for ``visualization_msgs/MenuEntry``, with its actions by id."""

    entries: tuple[FlatEntry, ...] = ()
    actions: Mapping[int, MenuAction] = field(default_factory=dict)


def flatten(menus: Sequence[Menu]) -> FlatMenu:
    """Number ``menus`` depth first from 1."""
    entries: list[FlatEntry] = []

    def visit(menu: Menu, parent: int) -> None:
        entry = FlatEntry(len(entries) + 1, parent, menu.title, menu.action)
        entries.append(entry)
        for child in menu.children:
            visit(child, entry.id)

    for menu in menus:
        visit(menu, 0)
    return FlatMenu(tuple(entries), {e.id: e.action for e in entries if e.action is not None})


def _skill_title(skill: str, param: str, several: bool) -> str:
    return f"{skill} ({param})" if several else skill


def robot_menu(library: Library, agent: str) -> tuple[Menu, ...]:
    """``Add skill ▸ <skill>`` for every skill of ``agent``, alphabetical, then ``Resume``.

    ``Resume`` is always there (the menu does not change with the robot's state): a robot
    holding after its lost-link policy says "Resume from its menu" on its label.
    """
    resume = Menu("Resume", ResumeRobot(agent))
    skills = sorted(library.skills_of(agent))
    if not skills:
        return (resume,)
    children = tuple(Menu(s, AddSkill(agent, s, from_robot=True)) for s in skills)
    return (Menu("Add skill", children=children), resume)


def _mentions(spec: SkillSpec, name: str) -> bool:
    words = name.replace("_", " ").lower()
    text = f"{spec.name.replace('_', ' ')} {spec.description}".lower()
    return re.search(rf"\b{re.escape(words)}\b", text) is not None


def object_skills(library: Library, obj: str) -> list[AddSkill]:
    """The skills any robot can do with static agent ``obj``."""
    found: list[AddSkill] = []
    for robot in library.dynamic_agents:
        for name, spec in sorted(library.skills_of(robot).items()):
            chosen = [
                p.name for p in spec.parameters if p.type is ParamType.STRING and obj in p.choices
            ]
            if chosen:
                found.append(AddSkill(robot, name, values=((chosen[0], obj),)))
            elif _mentions(spec, obj):
                found.append(AddSkill(robot, name))
    return found


def _by_robot(
    actions: Sequence[AddSkill], titles: Sequence[str], title: str = "Add skill"
) -> tuple[Menu, ...]:
    robots: dict[str, list[Menu]] = {}
    for action, name in zip(actions, titles, strict=True):
        robots.setdefault(action.agent, []).append(Menu(name, action))
    if not robots:
        return ()
    return (
        Menu(
            title,
            children=tuple(Menu(robot, children=tuple(items)) for robot, items in robots.items()),
        ),
    )


def static_agent_menu(library: Library, obj: str) -> tuple[Menu, ...]:
    """``Add skill ▸ <robot> ▸ <skill>`` for the skills that take static agent ``obj``."""
    actions = object_skills(library, obj)
    return _by_robot(actions, [a.skill for a in actions])


def marker_skills(library: Library, marker_type: MarkerType) -> list[tuple[AddSkill, str]]:
    """Every (robot, skill, parameter) a marker of ``marker_type`` can fill, with a title."""
    found: list[tuple[AddSkill, str]] = []
    for robot in library.dynamic_agents:
        for name, spec in sorted(library.skills_of(robot).items()):
            params = [p.name for p in spec.parameters if p.accepts_marker(marker_type)]
            for param in params:
                found.append(
                    (AddSkill(robot, name, bind=param), _skill_title(name, param, len(params) > 1))
                )
    return found


ADD_HERE = "Add skill here"
DRIVING = ", driving there first"


def with_drives(
    library: Library, state: MissionState, marker: TaskMarker, pairs: Sequence[tuple[AddSkill, str]]
) -> list[tuple[AddSkill, str]]:
    """``pairs``, each skill that works at a point followed by its "driving there first"."""
    out: list[tuple[AddSkill, str]] = []
    there: dict[str, bool] = {}  # per robot: its task already ends at the marker
    for action, title in pairs:
        out.append((action, title))
        move = move_skill(library, action.agent)
        param = library.skill(action.agent, action.skill).parameter(action.bind or "")
        if move is None or action.skill == move[0] or param.marker_type is MarkerType.AREA:
            continue
        if action.agent not in there:
            there[action.agent] = _ends_at(library, state, action.agent, marker)
        if not there[action.agent]:
            out.append((replace(action, drive=move), title + DRIVING))
    return out


def _ends_at(library: Library, state: MissionState, agent: str, marker: TaskMarker) -> bool:
    """Whether ``agent``'s task already takes it to ``marker`` (its latest place is there)."""
    skills = library.skills_of(agent)
    for skill in reversed(state.task(agent)):  # from the end: the latest place is near it
        spec = skills.get(skill.skill)
        name = first_location(spec) if spec is not None else ""
        if not name:
            continue
        if skill.bindings.get(name) == marker.name:
            return True
        xy = location_xy(skill.params.get(name))
        return xy is not None and math.dist(xy, (marker.pose.x, marker.pose.y)) <= ARRIVED
    return False


def rename_suggestions(
    state: MissionState, marker: TaskMarker, bound: Sequence[SkillInstance]
) -> list[str]:
    """Names to offer for a marker: after its first skill, its place, the next free number."""
    kind = marker.type.name.capitalize()
    candidates = []
    if bound:
        candidates.append(f"{bound[0].agent} {bound[0].skill}")
    candidates.append(f"{kind} at ({marker.pose.x:.0f}, {marker.pose.y:.0f})")
    candidates.append(generated_name(state, marker.type))
    taken = {m.name for m in state.markers}
    out: list[str] = []
    for name in candidates:
        if name not in taken and name not in out:
            out.append(name)
    return out


def task_marker_menu(
    library: Library,
    state: MissionState,
    marker: TaskMarker,
    bound: Sequence[SkillInstance],
    locked: bool,
) -> tuple[Menu, ...]:
    """The menu of a task marker (see the module docstring)."""
    pairs = with_drives(library, state, marker, marker_skills(library, marker.type))
    menus = list(_by_robot([a for a, _ in pairs], [t for _, t in pairs], ADD_HERE))
    if not locked:
        names = rename_suggestions(state, marker, bound)
        if names:
            menus.append(Menu("Rename", children=tuple(Menu(n, RenameMarker(n)) for n in names)))
    if marker_refusal(marker.name, bound, MarkerAction.DELETE) is None:  # the server's rule
        menus.append(Menu("Delete", DeleteMarker()))
    return tuple(menus)


def is_robot(library: Library, agent: str) -> bool:
    """Whether ``agent`` executes skills (a dynamic agent)."""
    return library.agent(agent).kind is AgentKind.DYNAMIC
