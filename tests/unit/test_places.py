"""Places for location parameters, a new skill's default place, and "drive there first"."""

from __future__ import annotations

import math

import pytest

from rosmc_server.core import Library, MarkerType, Pose, SkillInstance, TaskMarker, load_library
from rosmc_server.core.views.drive_first import drive_first, move_skill
from rosmc_server.core.views.places import (
    LANDER,
    PlaceKind,
    Surroundings,
    default_place,
    places_for,
)
from rosmc_server.core.views.science import RegionScience
from rosmc_server.core.world.site import Footprint, GroundRobot, Shape, SiteModel
from tests.unit.conftest import SHIPPED_LIBRARY

ROCK = TaskMarker("rock", MarkerType.POSITION, Pose(7.0, 8.0))
FIELD = TaskMarker(
    "field",
    MarkerType.AREA,
    Pose(10.0, 0.0),
    (Pose(8.0, -2.0), Pose(12.0, -2.0), Pose(12.0, 2.0), Pose(8.0, 2.0)),
)
RSS_A = RegionScience("RSS A", 16.0, 9.0, 3.0, 1.0, 3, "")
SITE = SiteModel(
    "mars",
    (-40.0, 40.0, -40.0, 40.0),
    (Footprint(LANDER, Shape.BOX, 0.0, 0.0, size_x=4.0, size_y=4.0),),
    (GroundRobot("science_rover", clearance=1.0),),
)
AROUND = Surroundings(
    regions=(RSS_A,),
    site=SITE,
    robots={"science_rover": Pose(3.0, -4.0, 0.0, 0.0, 0.0, 0.5), "drone": Pose(1.0, 1.0)},
    lander=(0.0, 0.0),
)


@pytest.fixture(scope="module")
def library() -> Library:
    return load_library(SHIPPED_LIBRARY)


def skill(library: Library, agent: str, name: str, sid: str, **kwargs: object) -> tuple:
    spec = library.skill(agent, name)
    params = {**spec.defaults(), **kwargs.pop("params", {})}  # type: ignore[dict-item]
    return SkillInstance(sid, agent, name, "", params, **kwargs), spec  # type: ignore[arg-type]


def test_a_point_parameter_offers_markers_area_centres_regions_lander_and_robots(
    library: Library,
) -> None:
    param = library.skill("science_rover", "identify_stones").parameter("position")
    places = places_for(param, "science_rover", [ROCK, FIELD], AROUND)
    assert [(p.name, p.kind) for p in places] == [
        ("rock", PlaceKind.MARKER),
        ("field", PlaceKind.AREA_CENTRE),
        ("RSS A", PlaceKind.REGION),
        (LANDER, PlaceKind.LANDER),
        ("science_rover", PlaceKind.ROBOT),  # its own position before the others
        ("drone", PlaceKind.ROBOT),
    ]
    rock, centre, region, lander, own, _ = places
    assert rock.fill("position") == ({}, {"position": "rock"})  # a marker binds
    assert centre.fill("position") == ({"position": Pose(10.0, 0.0)}, {})  # others fill
    assert region.value == Pose(16.0, 9.0) and region.label == "RSS A \u2014 region (16, 9)"
    assert lander.value == Pose(0.0, 0.0) and lander.label == "lander (0, 0)"  # on_site: itself
    assert own.value == Pose(3.0, -4.0)  # a point has no heading


def test_a_ground_target_at_the_lander_stands_beside_it_facing_the_robot(
    library: Library,
) -> None:
    param = library.skill("science_rover", "navigate_to").parameter("target")
    lander = next(
        p for p in places_for(param, "science_rover", [], AROUND) if p.kind is PlaceKind.LANDER
    )
    assert isinstance(lander.value, Pose)
    # half the lander's diagonal + the rover's clearance + the stand-off, towards the rover
    distance = math.hypot(4.0, 4.0) / 2 + 1.0 + 0.5
    assert math.hypot(lander.x, lander.y) == pytest.approx(distance)
    assert math.atan2(lander.y, lander.x) == pytest.approx(math.atan2(-4.0, 3.0))
    assert SITE.problem(param.check_target, "science_rover", lander.x, lander.y) == ""  # type: ignore[arg-type]


def test_an_area_parameter_offers_area_markers_regions_and_robots_not_points(
    library: Library,
) -> None:
    param = library.skill("drone", "fly_over").parameter("area")
    places = places_for(param, "drone", [ROCK, FIELD], AROUND)
    assert [(p.name, p.kind) for p in places] == [
        ("field", PlaceKind.MARKER),
        ("RSS A", PlaceKind.REGION),
        ("drone", PlaceKind.ROBOT),
        ("science_rover", PlaceKind.ROBOT),
    ]
    region = places[1].value
    assert isinstance(region, list) and len(region) == 4
    xs = [c["x"] for c in region]
    assert min(xs) == pytest.approx(16.0 - 4.0) and max(xs) == pytest.approx(16.0 + 4.0)
    library.skill("drone", "fly_over").parameter("area").check(region, "fly_over")


def test_a_region_with_a_marker_of_its_name_is_offered_once_as_the_marker(
    library: Library,
) -> None:
    param = library.skill("science_rover", "identify_stones").parameter("position")
    marker = TaskMarker("RSS A", MarkerType.POSITION, Pose(16.0, 9.5))
    places = places_for(param, "science_rover", [marker], Surroundings(regions=(RSS_A,)))
    assert [(p.name, p.kind) for p in places] == [("RSS A", PlaceKind.MARKER)]


def test_a_non_location_parameter_has_no_places(library: Library) -> None:
    param = library.skill("science_rover", "identify_stones").parameter("radius")
    assert places_for(param, "science_rover", [ROCK], AROUND) == []
    assert default_place(param, "science_rover", [], [ROCK], AROUND) is None


def test_default_is_the_marker_of_the_robots_latest_place(library: Library) -> None:
    param = library.skill("manipulator_rover", "pick_stone").parameter("position")
    task = [
        skill(library, "manipulator_rover", "navigate_to", "a", bindings={"target": "rock"}),
        skill(library, "manipulator_rover", "pick_box", "b"),  # no place: looked past
    ]
    chosen = default_place(param, "manipulator_rover", task, [ROCK], AROUND)
    assert chosen is not None and chosen.marker == "rock"


def test_default_from_an_area_marker_is_its_centre(library: Library) -> None:
    param = library.skill("science_rover", "identify_stones").parameter("position")
    task = [skill(library, "science_rover", "explore", "b", bindings={"area": "field"})]
    chosen = default_place(param, "science_rover", task, [FIELD], AROUND)
    assert chosen is not None and chosen.kind is PlaceKind.AREA_CENTRE  # a point binds no area
    assert chosen.value == Pose(10.0, 0.0) and chosen.fill("position")[1] == {}


def test_default_is_the_latest_typed_place_when_it_has_no_marker(library: Library) -> None:
    param = library.skill("drone", "fly_over").parameter("area")
    task = [skill(library, "drone", "navigate_to", "a", params={"target": Pose(2.0, 3.0)})]
    chosen = default_place(param, "drone", task, [FIELD], AROUND)
    assert chosen is not None and chosen.kind is PlaceKind.TASK and (chosen.x, chosen.y) == (2, 3)
    assert isinstance(chosen.value, list) and len(chosen.value) == 4  # an area around it


def test_default_without_a_task_is_the_robot_then_the_lander(library: Library) -> None:
    param = library.skill("science_rover", "identify_stones").parameter("position")
    chosen = default_place(param, "science_rover", [], [], AROUND)
    assert chosen is not None and chosen.kind is PlaceKind.ROBOT and chosen.value == Pose(3, -4)
    alone = Surroundings(lander=(0.0, 0.0))
    chosen = default_place(param, "science_rover", [], [], alone)
    assert chosen is not None and chosen.kind is PlaceKind.LANDER
    assert default_place(param, "science_rover", [], [], Surroundings()) is None


def test_move_skill_of_each_robot(library: Library) -> None:
    assert move_skill(library, "drone") == ("navigate_to", "target")
    assert move_skill(library, "manipulator_rover") == ("navigate_to", "target")


def test_drive_first_is_offered_bound_to_the_same_marker(library: Library) -> None:
    task = [
        skill(library, "manipulator_rover", "pick_box", "a"),
        skill(
            library,
            "manipulator_rover",
            "pick_stone",
            "b",
            params={"position": Pose(7.0, 8.0)},
            bindings={"position": "rock"},
        ),
    ]
    offer = drive_first(library, task, 1, Pose(0.0, 0.0))
    assert offer is not None
    assert (offer.agent, offer.skill, offer.index) == ("manipulator_rover", "navigate_to", 1)
    assert offer.bindings == {"target": "rock"} and offer.params == {}
    assert "marker 'rock'" in offer.words


def test_drive_first_with_a_typed_point_gives_the_point(library: Library) -> None:
    task = [
        skill(library, "science_rover", "identify_stones", "a", params={"position": Pose(9, 1)})
    ]
    offer = drive_first(library, task, 0, None)  # where the robot is: unknown
    assert offer is not None and offer.params == {"target": Pose(9.0, 1.0)}


def test_drive_first_not_offered_when_the_robot_is_already_going_there(
    library: Library,
) -> None:
    at = {"params": {"position": Pose(7.0, 8.0)}}
    going = [
        skill(library, "science_rover", "navigate_to", "a", params={"target": Pose(7.2, 8.1)}),
        skill(library, "science_rover", "identify_stones", "b", **at),  # type: ignore[arg-type]
    ]
    assert drive_first(library, going, 1, None) is None
    there = [skill(library, "science_rover", "identify_stones", "b", **at)]  # type: ignore[arg-type]
    assert drive_first(library, there, 0, Pose(7.5, 8.0)) is None
    assert drive_first(library, there, 0, Pose(0.0, 0.0)) is not None


def test_drive_first_not_offered_for_moves_or_skills_without_a_point(library: Library) -> None:
    move = [skill(library, "science_rover", "navigate_to", "a", params={"target": Pose(9, 9)})]
    assert drive_first(library, move, 0, None) is None
    area = [skill(library, "science_rover", "explore", "a")]
    assert drive_first(library, area, 0, None) is None


def test_default_skips_places_the_site_refuses(library: Library) -> None:
    param = library.skill("science_rover", "navigate_to").parameter("target")
    inside = Pose(0.5, 0.5)  # on the lander: no ground target
    task = [skill(library, "science_rover", "navigate_to", "a", params={"target": inside})]
    around = Surroundings(site=SITE, robots={"science_rover": Pose(0.2, 0.0)}, lander=(0.0, 0.0))
    chosen = default_place(param, "science_rover", task, [], around)
    assert chosen is not None and chosen.kind is PlaceKind.LANDER  # beside it, not on it
    assert SITE.problem(param.check_target, "science_rover", chosen.x, chosen.y) == ""  # type: ignore[arg-type]
