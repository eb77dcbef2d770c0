"""What the command GUI offers from what it shows: surroundings, defaults, drive offer, copies."""

from __future__ import annotations

import pytest

from rosmc_rqt_command.core.duplicating import copies
from rosmc_rqt_command.core.mission_view import MissionView
from rosmc_rqt_command.core.place_choices import (
    drive_first_offer,
    new_skill_places,
    surroundings,
)
from rosmc_server.core import (
    AgentStatus,
    InvalidRequest,
    Library,
    MarkerType,
    Mission,
    Pose,
    TaskMarker,
)
from rosmc_server.core.views.science import RegionScience, Science
from rosmc_server.core.world.site import Footprint, Shape, SiteModel
from rosmc_server.core.world.site_source import SiteInForce
from tests.unit.conftest import make_mission
from tests.unit.test_legality import gui_view as mirror_view

ROCK = TaskMarker("rock", MarkerType.POSITION, Pose(7.0, 8.0))
SITE = SiteInForce(
    SiteModel(
        "mars",
        (-40.0, 40.0, -40.0, 40.0),
        (Footprint("lander", Shape.BOX, 1.0, -1.0, size_x=4.0, size_y=4.0),),
    ),
    "/rosmc/sim",
    0.0,
)


def gui_view(mission: Mission) -> MissionView:
    """The command GUI's view of ``mission``, with its library."""
    view = mirror_view(mission)
    view.library = mission.library
    return view


@pytest.fixture
def mars(shipped_library: Library) -> Mission:
    mission = make_mission(shipped_library)
    mission.add_marker(ROCK)
    return mission


def test_surroundings_take_the_science_the_site_and_the_robots_poses(mars: Mission) -> None:
    view = gui_view(mars)
    view.statuses = {"drone": AgentStatus("drone", pose=Pose(2.0, 3.0)), "rover": AgentStatus("x")}
    region = RegionScience("RSS A", 16.0, 9.0, 3.0, 1.0, 3, "")
    around = surroundings(view, Science(0.0, 0, (region,)), SITE)
    assert around.regions == (region,) and around.site is SITE.site
    assert around.robots == {"drone": Pose(2.0, 3.0)}  # a robot without a pose: not a place
    assert around.lander == (1.0, -1.0)  # where the site map has it
    assert surroundings(view, None, None).lander == (0.0, 0.0)  # the library's static lander


def test_a_new_skill_takes_the_robots_latest_marker(mars: Mission) -> None:
    mars.add_skill("science_rover", "navigate_to", bindings={"target": "rock"})
    view = gui_view(mars)
    around = surroundings(view, None, None)
    assert new_skill_places(view, around, "science_rover", "identify_stones") == (
        {},
        {"position": "rock"},
    )
    # another robot with no task and no pose known: the lander, as plain data for the wire
    params, bindings = new_skill_places(view, around, "manipulator_rover", "pick_stone")
    assert bindings == {} and params["position"] == Pose().to_dict()
    assert new_skill_places(view, around, "drone", "take_off") == ({}, {})  # no location


def test_the_drive_offer_follows_the_task(mars: Mission) -> None:
    pick = mars.add_skill("manipulator_rover", "pick_stone", bindings={"position": "rock"})
    view = gui_view(mars)
    skill = view.skill(pick.change.put_skills[0].skill.id)
    assert skill is not None
    offer = drive_first_offer(view, surroundings(view, None, None), skill)
    assert offer is not None and offer.bindings == {"target": "rock"} and offer.index == 0
    mars.add_skill("manipulator_rover", "navigate_to", bindings={"target": "rock"}, index=0)
    view = gui_view(mars)
    assert drive_first_offer(view, surroundings(view, None, None), skill) is None


def test_copies_go_after_the_selection_with_values_and_bindings(mars: Mission) -> None:
    ids = [
        mars.add_skill("manipulator_rover", name, bindings=bound).change.put_skills[0].skill.id
        for name, bound in (
            ("navigate_to", {"target": "rock"}),
            ("pick_stone", {"position": "rock"}),
            ("deposit_at_lander", {}),
            ("recharge", {}),
        )
    ]
    view = gui_view(mars)
    made = copies(view, view.skills([ids[2], ids[0]]))  # in task order, whatever the clicks
    assert [(c.source, c.index) for c in made] == [(ids[0], 3), (ids[2], 4)]
    assert made[0].bindings == {"target": "rock"} and "target" not in made[0].params
    assert made[0].params["speed"] == 0.5


def test_copies_refused_in_one_sentence(mars: Mission) -> None:
    one = mars.add_skill("drone", "take_off").change.put_skills[0].skill.id
    two = mars.add_skill("science_rover", "explore").change.put_skills[0].skill.id
    view = gui_view(mars)
    with pytest.raises(InvalidRequest, match="one robot's skills at a time"):
        copies(view, view.skills([one, two]))
    with pytest.raises(InvalidRequest, match="select the planned skills"):
        copies(view, [])
    mars.synchronize("drone")
    view = gui_view(mars)
    with pytest.raises(InvalidRequest, match="only planned skills"):
        copies(view, view.skills([one]))
