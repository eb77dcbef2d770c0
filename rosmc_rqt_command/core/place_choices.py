"""The places the command GUI offers, from what it shows: markers, science, site, robots.

Pure functions over the :class:`~.mission_view.MissionView` (no Qt): the parameter panel
lists :func:`offered` places in each location parameter's picker, a skill added from a
robot's Add menu takes :func:`new_skill_places`, and the panel offers
:func:`drive_first_offer` for the shown skill.
"""

from __future__ import annotations

from rosmc_server.core import AgentKind, RosmcError, SkillInstance, SkillSpec
from rosmc_server.core.skills.params import value_to_data
from rosmc_server.core.views.drive_first import DriveFirst, drive_first
from rosmc_server.core.views.places import LANDER, Place, Surroundings, default_place, places_for
from rosmc_server.core.views.science import Science
from rosmc_server.core.world.site_source import SiteInForce

from .mission_view import MissionView


def surroundings(
    view: MissionView, science: Science | None, site: SiteInForce | None
) -> Surroundings:
    """What the window knows around the mission: regions, site, robots' poses, the lander.

    The lander stands where the site map's footprint called ``lander`` is; without one, a
    library with a static agent ``lander`` puts it at the map's origin (the lander defines
    the map frame).
    """
    model = site.site if site is not None else None
    lander: tuple[float, float] | None = None
    footprint = next((o for o in model.obstacles if o.name == LANDER), None) if model else None
    if footprint is not None:
        lander = (footprint.x, footprint.y)
    elif view.library is not None and any(
        a.name == LANDER and a.kind is AgentKind.STATIC for a in view.library.agents
    ):
        lander = (0.0, 0.0)
    robots = {a: s.pose for a, s in view.statuses.items() if s.pose is not None}
    regions = science.regions if science is not None else ()
    return Surroundings(regions, model, robots, lander)


def task_specs(view: MissionView, agent: str) -> list[tuple[SkillInstance, SkillSpec]]:
    """``agent``'s task with each skill's spec (a skill the library lacks is left out)."""
    library = view.library
    found: list[tuple[SkillInstance, SkillSpec]] = []
    if library is None:
        return found
    for skill in view.view(agent).skills:
        try:
            found.append((skill, library.skill(agent, skill.skill)))
        except RosmcError:
            continue
    return found


def offered(
    view: MissionView, around: Surroundings, skill: SkillInstance, param: str
) -> list[Place]:
    """The places ``param`` of ``skill`` can take."""
    if view.library is None:
        return []
    spec = view.library.skill(skill.agent, skill.skill).parameter(param)
    return places_for(spec, skill.agent, list(view.markers.values()), around)


def new_skill_places(
    view: MissionView, around: Surroundings, agent: str, skill: str
) -> tuple[dict[str, object], dict[str, str]]:
    """Parameter values and marker bindings for ``skill`` appended to ``agent``'s task:
    every location parameter at its default place (see
    :func:`~rosmc_server.core.views.places.default_place`)."""
    params: dict[str, object] = {}
    bindings: dict[str, str] = {}
    if view.library is None:
        return params, bindings
    task = task_specs(view, agent)
    markers = list(view.markers.values())
    for spec in view.library.skill(agent, skill).parameters:
        place = default_place(spec, agent, task, markers, around)
        if place is not None:
            values, bound = place.fill(spec.name)
            params.update({k: value_to_data(v) for k, v in values.items()})
            bindings.update(bound)
    return params, bindings


def drive_first_offer(
    view: MissionView, around: Surroundings, skill: SkillInstance
) -> DriveFirst | None:
    """The move to offer before ``skill`` (None: none, or it is not in the blueprint)."""
    if view.library is None or not skill.is_editable:
        return None
    task = task_specs(view, skill.agent)
    index = next((i for i, (s, _) in enumerate(task) if s.id == skill.id), -1)
    if index < 0 or len(task) != len(view.view(skill.agent).skills):
        return None  # the insertion index would not be the task's
    return drive_first(view.library, task, index, around.robots.get(skill.agent))
