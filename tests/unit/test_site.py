"""The site model and the skill-target checks the mission runs against it (core/world/site.py).

Geometry of obstacle footprints, what each named check refuses and says, the library's
``check`` key, and the mission refusing an add, edit, marker move or load whose target
the site rules out, unchanged, with one sentence (and skipping the checks, once said, while
no site is known).
"""

from __future__ import annotations

import itertools
import logging
import math
from dataclasses import replace
from typing import Any

import pytest

from rosmc_server.core import (
    InvalidRequest,
    LibraryError,
    MarkerType,
    Mission,
    MissionContent,
    Pose,
    RuleViolation,
    SkillInstance,
    SkillStatus,
    TaskMarker,
)
from rosmc_server.core.skills.library import library_from_dict
from rosmc_server.core.world.site import (
    Footprint,
    GroundRobot,
    Shape,
    SiteCheck,
    SiteModel,
    check_site,
)
from rosmc_server.core.world.site_source import NO_SITE, SiteInForce, site_line

ON_SITE, GROUND = SiteCheck.ON_SITE, SiteCheck.REACHABLE_GROUND
ROCK = Footprint("rock_3", Shape.CYLINDER, 12.0, 3.5, radius=2.0, height=2.5)
# A 10 m x 2 m wall centred on (0, 20), turned 90 degrees: it runs along y from 15 to 25.
WALL = Footprint("wall", Shape.BOX, 0.0, 20.0, size_x=10.0, size_y=2.0, yaw=math.pi / 2)
SITE = SiteModel(
    "test_site",
    (-40.0, 40.0, -30.0, 30.0),
    (ROCK, WALL),
    (GroundRobot("alpha", "rover", clearance=1.5, edge_margin=1.0),),
)


# -- geometry ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("point", "distance"),
    [((12.0, 3.5), 0.0), ((13.9, 3.5), 0.0), ((15.0, 3.5), 1.0), ((12.0, 8.5), 3.0)],
)
def test_a_cylinder_footprint_is_a_disc(point: tuple[float, float], distance: float) -> None:
    assert ROCK.distance(*point) == pytest.approx(distance)


@pytest.mark.parametrize(
    ("point", "distance"),
    [((0.0, 24.9), 0.0), ((0.9, 20.0), 0.0), ((2.0, 20.0), 1.0), ((0.0, 27.0), 2.0)],
)
def test_a_box_footprint_turns_with_its_yaw(point: tuple[float, float], distance: float) -> None:
    assert WALL.distance(*point) == pytest.approx(distance, abs=1e-9)


# -- what each check says -------------------------------------------------------------------
@pytest.mark.parametrize(
    ("check", "agent", "point", "problem"),
    [
        (ON_SITE, "alpha", (12.0, 3.5), ""),  # flying over the rock is fine
        (
            ON_SITE,
            "alpha",
            (50.0, 0.0),
            "lies off the site 'test_site' (x -40 to 40 m, y -30 to 30 m); pick a point on it",
        ),
        (GROUND, "alpha", (12.0, 3.5), "lies inside obstacle 'rock_3'; pick a point outside it"),
        (GROUND, "alpha", (0.5, 16.0), "lies inside obstacle 'wall'; pick a point outside it"),
        (
            GROUND,
            "alpha",
            (15.0, 3.5),
            "lies 1.0 m from obstacle 'rock_3', closer than alpha keeps (1.5 m); "
            "pick a point farther from it",
        ),
        (
            GROUND,
            "alpha",
            (39.5, 0.0),
            "lies 0.5 m from the site's edge, closer than alpha keeps (1.0 m); "
            "pick a point farther inside",
        ),
        (GROUND, "alpha", (15.6, 3.5), ""),
        (GROUND, "bravo", (15.0, 3.5), ""),  # the site names no clearance for bravo
        (GROUND, "bravo", (13.0, 3.5), "lies inside obstacle 'rock_3'; pick a point outside it"),
    ],
)
def test_problems_name_the_place_and_what_to_pick(
    check: SiteCheck, agent: str, point: tuple[float, float], problem: str
) -> None:
    assert SITE.problem(check, agent, *point) == problem


@pytest.mark.parametrize(
    ("site", "fragment"),
    [
        (SiteModel("s", (1.0, 1.0, 0.0, 5.0)), "bounds with no area"),
        (SiteModel("s", (0.0, math.inf, 0.0, 5.0)), "not finite"),
        (SiteModel("s", (0.0, 5.0, 0.0, 5.0), (Footprint("r", Shape.CYLINDER, 1, 1, -1),)), "r'"),
        (SiteModel("s", (0.0, 5.0, 0.0, 5.0), (), (GroundRobot("a", clearance=-1.0),)), "'a'"),
        (  # one obstacle this wide once refused every ground target
            SiteModel("s", (0.0, 5.0, 0.0, 5.0), (Footprint("r", Shape.CYLINDER, 1, 1, 1e308),)),
            "obstacle 'r' of site 's' holds 1e[+]308, beyond the 100000 m a site map may use",
        ),
        (SiteModel("s", (-1e6, 5.0, 0.0, 5.0)), "its bounds of site 's' holds -1e[+]06"),
        (SiteModel("s", (0.0, 5.0, 0.0, 5.0), (), (GroundRobot("a", clearance=2e5),)), "'a'"),
        (
            SiteModel("s", (0.0, 5.0, 0.0, 5.0), (Footprint("r", Shape.BOX, 1, 1),) * 2001),
            "site 's' has 2001 obstacles, more than the 2000 a mission checks targets against",
        ),
        (SiteModel("s", (0.0, 5.0, 0.0, 5.0), (), (GroundRobot("a"),) * 201), "201 robots"),
    ],
)
def test_a_site_no_check_can_trust_is_refused(site: SiteModel, fragment: str) -> None:
    with pytest.raises(InvalidRequest, match=fragment):
        check_site(site)


def test_a_site_at_the_limits_is_taken() -> None:
    box = Footprint("r", Shape.BOX, 1e5, -1e5, size_x=1e5, size_y=1.0)
    site = SiteModel("s", (-1e5, 1e5, -1e5, 1e5), (box,) * 2000, (GroundRobot("a"),) * 200)
    assert check_site(site) is site


# -- the library's check key ------------------------------------------------------------------
def checked_library(library_data: dict[str, Any]) -> Any:
    skills = library_data["models"]["walker"]["skills"]
    skills["move"]["parameters"]["target"]["check"] = "reachable_ground"
    skills["scan"]["parameters"]["area"]["check"] = "on_site"
    return library_from_dict(library_data, "checked.yaml")


def test_the_library_declares_checks_per_parameter(library_data: dict[str, Any]) -> None:
    move = checked_library(library_data).skill("alpha", "move")
    scan = checked_library(library_data).skill("alpha", "scan")
    assert move.parameter("target").check_target is GROUND
    assert scan.parameter("area").check_target is ON_SITE
    assert scan.parameter("point").check_target is None


@pytest.mark.parametrize(
    ("skill", "param", "check", "fragment"),
    [
        ("move", "target", "walkable", "check: must be one of on_site, reachable_ground"),
        ("move", "speed", "on_site", "applies to pose parameters and areas"),
        ("wait", "options", "on_site", "applies to pose parameters and areas"),
        ("scan", "area", "reachable_ground", "reachable_ground checks one point"),
    ],
)
def test_a_check_the_library_cannot_run_is_refused(
    library_data: dict[str, Any], skill: str, param: str, check: str, fragment: str
) -> None:
    library_data["models"]["walker"]["skills"][skill]["parameters"][param]["check"] = check
    with pytest.raises(LibraryError, match=fragment):
        library_from_dict(library_data, "bad.yaml")


# -- the mission runs the checks ---------------------------------------------------------------
@pytest.fixture
def sited(library_data: dict[str, Any]) -> Mission:
    """A mission whose walkers' targets are checked, against SITE."""
    counter = itertools.count(1)
    mission = Mission(
        checked_library(library_data),
        clock=lambda: 1.0,
        new_id=lambda prefix: f"{prefix}-{next(counter)}",
    )
    mission.site.update(SITE)
    return mission


def target(x: float, y: float) -> dict[str, Any]:
    return {"target": {"x": x, "y": y}}


def target_params(skill: SkillInstance, x: float, y: float) -> dict[str, Any]:
    return {**skill.params, "target": Pose(x, y)}


def test_an_add_with_a_target_inside_an_obstacle_is_refused(sited: Mission, rejected: Any) -> None:
    error = rejected(sited, RuleViolation, sited.add_skill, "alpha", "move", target(12.0, 3.5))
    assert str(error) == (
        "target (12.0, 3.5) of alpha's 'move' lies inside obstacle 'rock_3'; "
        "pick a point outside it"
    )
    sited.add_skill("alpha", "move", target(20.0, 3.5))


def test_an_area_with_a_corner_off_the_site_is_refused(sited: Mission, rejected: Any) -> None:
    area = [{"x": 0, "y": 0}, {"x": 45, "y": 0}, {"x": 0, "y": 10}]
    error = rejected(sited, RuleViolation, sited.add_skill, "alpha", "scan", {"area": area})
    assert str(error).startswith("corner 2 (45.0, 0.0) of area of alpha's 'scan' lies off")
    area[1]["x"] = 12.0  # inside the rock: an area only needs to be on the site
    sited.add_skill("alpha", "scan", {"area": area})


def test_an_edit_is_checked_and_names_the_skill(sited: Mission, rejected: Any) -> None:
    skill_id = sited.add_skill("alpha", "move", target(20.0, 3.5)).change.put_skills[0].skill.id
    error = rejected(sited, RuleViolation, sited.edit_skill, skill_id, target(0.0, 26.0))
    assert str(error).startswith(f"target (0.0, 26.0) of alpha's 'move' ({skill_id}) lies 1.0 m")
    sited.edit_skill(skill_id, target(20.0, 10.0))


def test_only_targets_the_change_sets_are_checked(library_data: dict[str, Any]) -> None:
    mission = Mission(checked_library(library_data), clock=lambda: 1.0)
    skill_id = mission.add_skill("alpha", "move", target(12.0, 3.5)).change.put_skills[0].skill.id
    mission.site.update(SITE)  # the map arrives after the skill was added
    mission.edit_skill(skill_id, {"speed": 0.5}, label="slow")  # its target is not set anew
    with pytest.raises(RuleViolation, match="inside obstacle 'rock_3'"):
        mission.edit_skill(skill_id, target(12.5, 3.5))


def test_moving_a_bound_marker_onto_an_obstacle_is_refused(sited: Mission, rejected: Any) -> None:
    sited.add_marker(TaskMarker("goal", MarkerType.POSE, Pose(20.0, 3.5)))
    added = sited.add_skill("alpha", "move", bindings={"target": "goal"})
    bound = added.change.put_skills[0].skill.id
    error = rejected(sited, RuleViolation, sited.move_marker, "goal", Pose(0.0, 18.0))
    assert str(error) == (
        f"target (0.0, 18.0) of alpha's 'move' ({bound}), bound to marker 'goal', lies inside "
        "obstacle 'wall'; pick a point outside it"
    )
    sited.move_marker("goal", Pose(-20.0, 0.0))


def test_a_loaded_blueprint_is_checked_but_finished_skills_are_not(
    sited: Mission, rejected: Any
) -> None:
    added = sited.add_skill("alpha", "move", target(20.0, 3.5)).change.put_skills[0].skill
    # What ran stays as a log, wherever it went; what is still to run is checked.
    ran = replace(
        added, id="old", params=target_params(added, 12.0, 3.5), status=SkillStatus.SUCCESS
    )
    planned = replace(added, id="next", params=target_params(added, 60.0, 0.0))
    content = MissionContent(
        sited.state.library, {"alpha": [ran, planned], "bravo": [], "charlie": []}
    )
    error = rejected(sited, RuleViolation, sited.load, content, "plan.yaml")
    assert str(error).startswith("target (60.0, 0.0) of alpha's 'move' (next) lies off the site")
    del content.tasks["alpha"][1]
    sited.load(content, "plan.yaml")


def test_without_a_site_the_checks_are_skipped_and_that_is_said_once(
    library_data: dict[str, Any], caplog: pytest.LogCaptureFixture
) -> None:
    mission = Mission(checked_library(library_data), clock=lambda: 1.0)
    with caplog.at_level(logging.INFO, logger="rosmc_server.core.rules.site_guard"):
        mission.add_skill("alpha", "move", target(12.0, 3.5))
        mission.add_skill("alpha", "move", target(99.0, 0.0))
        mission.add_skill("alpha", "noop")
    said = [r.getMessage() for r in caplog.records]
    assert said == [
        "skill targets are not checked against the site: no site map is known yet "
        "(the simulator or a map provider publishes one)"
    ]


def test_the_map_in_force_says_whose_it_is_and_since_when() -> None:
    site = SiteModel("mars", (0.0, 5.0, 0.0, 5.0), (Footprint("r", Shape.BOX, 1, 1),))
    assert site_line(None) == NO_SITE
    wall = SiteInForce(site, "/rosmc/sim", 1_700_000_000.0)  # 2023-11-14 22:13:20 UTC
    assert site_line(wall) == (
        "site 'mars' from /rosmc/sim at 22:13:20 UTC: 1 obstacles, 0 ground robots"
    )
    assert (
        SiteInForce(site, "", 12.25)
        .line()
        .startswith("site 'mars' from an unknown node at t=12.2 s")
    )
