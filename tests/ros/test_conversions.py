"""Every core <-> message conversion keeps every field (rosmc_server.conversions).

Each core value is built with *every* field set to something other than its default, sent
through its ``x_to_msg``, serialized and read back as the receiver would, and rebuilt with
``x_from_msg``: the result must equal the original. A helper first checks that the value
really differs from the defaults in every field, so a field that a conversion drops (and
that would come back as its default) cannot pass unnoticed. Conversions with one direction
only (agent states, executor commands) are checked field by field from a message in which
every field is set.
"""

from __future__ import annotations

import dataclasses
import io
import math
from typing import Any

import genpy
import pytest
import rosmc.msg as wire

from rosmc_server.conversions import (
    agent_status_from_msg,
    barrier_from_msg,
    barrier_to_msg,
    event_from_msg,
    event_to_msg,
    library_from_msg,
    library_to_msg,
    marker_from_msg,
    marker_to_msg,
    mission_from_msg,
    mission_to_msg,
    param_from_msg,
    param_to_msg,
    policy_in_force_from_msg,
    policy_in_force_to_msg,
    pose_from_msg,
    pose_to_msg,
    site_from_msg,
    site_in_force_from_msg,
    site_in_force_to_msg,
    site_to_msg,
    skill_from_msg,
    skill_to_msg,
)
from rosmc_server.conversions.coverage import (
    prediction_from_msg,
    prediction_to_msg,
    reading_from_telemetry,
)
from rosmc_server.conversions.robot_link import (
    command_from_msg,
    signal_from_msg,
    signal_to_msg,
    snapshot_to_msg,
)
from rosmc_server.conversions.science import science_from_msg, science_to_msg
from rosmc_server.core import (
    AgentKind,
    AgentSpec,
    AgentStatus,
    Barrier,
    Change,
    EventKind,
    InvalidRequest,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    MarkerType,
    MissionContent,
    MissionEvent,
    ParameterSpec,
    ParamType,
    PlacedSkill,
    PolicyInForce,
    Pose,
    Resolution,
    SkillInstance,
    SkillSpec,
    SkillStatus,
    TaskMarker,
    Transfer,
)
from rosmc_server.core.model.changes import SkillMove
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.protocol import Signal, SignalKind, Snapshot
from rosmc_server.core.robots.radio_map import GridSpec, Prediction, Reading
from rosmc_server.core.views.science import RegionScience, Science
from rosmc_server.core.world.site import Footprint, GroundRobot, Shape, SiteCheck, SiteModel
from rosmc_server.core.world.site_source import SiteInForce


def over_the_wire(msg: Any) -> Any:
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return type(msg)().deserialize(buffer.getvalue())


def assert_no_default_field(*values: Any, robot_side: tuple[str, ...] = ()) -> None:
    """Every field with a default differs from it in at least one of the dataclass ``values``.

    ``robot_side`` names fields that never travel (read from the library file by the
    executor alone).
    """
    for field in dataclasses.fields(values[0]):
        if field.name in robot_side:
            continue
        if field.default is not dataclasses.MISSING:
            default = field.default
        elif field.default_factory is not dataclasses.MISSING:
            default = field.default_factory()
        else:
            continue
        assert any(getattr(v, field.name) != default for v in values), (
            f"{type(values[0]).__name__}.{field.name} is left at its default"
        )


POSE = Pose(1.5, -2.25, 0.5, 0.1, -0.2, 1.25)
AREA = (Pose(0, 0), Pose(4, 0), Pose(4, 3), Pose(0, 3))
PARAMS: dict[str, Any] = {
    "flag": True,
    "count": -7,
    "speed": 0.75,
    "note": "avoid the dune ✓",
    "path": [{"x": 1.0, "y": 2.0}, {"x": 3.5, "y": -4.0}],
    "options": {"mode": "scan", "bands": [1, 2]},
    "target": POSE,
}


def full_skill(skill_id: str = "rover-1", agent: str = "rover") -> SkillInstance:
    return SkillInstance(
        id=skill_id,
        agent=agent,
        skill="identify_stones",
        label="look closely",
        params=PARAMS,
        bindings={"target": "rss_a"},
        status=SkillStatus.FAILURE,
        transfer=Transfer.REMOVING,
        resolution=Resolution.RETRIED,
        attempt=3,
        timeout=120.5,
        max_retries=2,
        status_text="wheel slip",
        started=1000.25,
        finished=1010.5,
    )


def test_poses_and_every_parameter_type_survive() -> None:
    assert pose_from_msg(over_the_wire(pose_to_msg(POSE))) == POSE
    for name, value in PARAMS.items():
        assert param_from_msg(over_the_wire(param_to_msg(name, value))) == (name, value), name
    msg = over_the_wire(param_to_msg("target", POSE, "rss_a"))
    assert msg.marker == "rss_a"


def test_a_skill_survives_with_every_field() -> None:
    skill = full_skill()
    assert_no_default_field(skill)
    assert skill_from_msg(over_the_wire(skill_to_msg(skill))) == skill


@pytest.mark.parametrize(
    "marker",
    [
        TaskMarker("rss_a", MarkerType.POSITION, Pose(3, 4, 0.5)),
        TaskMarker("goal", MarkerType.POSE, POSE),
        TaskMarker("survey", MarkerType.AREA, Pose(2, 1.5), AREA),
    ],
    ids=lambda marker: marker.type.name,
)
def test_task_markers_of_each_kind_survive(marker: TaskMarker) -> None:
    assert marker_from_msg(over_the_wire(marker_to_msg(marker))) == marker


def test_barriers_survive_with_their_agents() -> None:
    barrier = Barrier("together", ("drone-1", "rover-2"))
    msg = over_the_wire(barrier_to_msg(barrier, lambda skill_id: skill_id.split("-")[0]))
    assert list(msg.agents) == ["drone", "rover"]
    assert barrier_from_msg(msg) == barrier


def full_content() -> MissionContent:
    drone = dataclasses.replace(full_skill("drone-1", "drone"), status=SkillStatus.SUCCESS)
    rover = full_skill()
    idle = SkillInstance("rover-2", "rover", "explore", "explore", {"speed": 1.0})
    return MissionContent(
        "mars_team",
        {"drone": [drone], "rover": [rover, idle]},
        {"b1": Barrier("b1", ("drone-1", "rover-2"))},
        {
            "rss_a": TaskMarker("rss_a", MarkerType.POSE, POSE),
            "survey": TaskMarker("survey", MarkerType.AREA, Pose(2, 1.5), AREA),
        },
    )


def test_a_mission_snapshot_survives_with_its_revision() -> None:
    content = full_content()
    msg = over_the_wire(mission_to_msg(content, 42, 1234.5))
    assert mission_from_msg(msg) == (content, 42)


def test_an_event_survives_with_every_part_of_its_change() -> None:
    content = full_content()
    change = Change(
        put_skills=(PlacedSkill(1, full_skill()),),
        removed_skill_ids=("rover-9",),
        order_agent="rover",
        blueprint_order=("rover-2", "rover-3"),
        put_barriers=(Barrier("b2", ("drone-1", "rover-1")),),
        removed_barrier_ids=("b0",),
        put_markers=(content.markers["survey"],),
        removed_marker_names=("old",),
        moves=(SkillMove("rover-3", 4), SkillMove("rover-2", 5)),
    )
    event = MissionEvent(43, EventKind.SKILL_EDITED, "rover", "edited rover-1", 1234.5, change)
    agents = {"drone-1": "drone", "rover-1": "rover"}
    msg = over_the_wire(event_to_msg(event, agents.__getitem__))
    assert event_from_msg(msg) == event
    for field in dataclasses.fields(change):
        if field.name != "replacement":  # a replacement travels as a snapshot instead
            assert getattr(change, field.name), field.name


def test_a_replaced_mission_travels_without_its_content() -> None:
    event = MissionEvent(
        7, EventKind.MISSION_REPLACED, "", "loaded", 5.0, Change(replacement=full_content())
    )
    back = event_from_msg(over_the_wire(event_to_msg(event, lambda s: "")))
    assert back == dataclasses.replace(event, change=Change())


def test_the_library_survives_with_every_parameter_attribute() -> None:
    speed = ParameterSpec(
        name="speed",
        type=ParamType.FLOAT,
        default=0.5,
        minimum=0.1,
        maximum=2.0,
        unit="m/s",
        description="Cruise speed.",
    )
    target = ParameterSpec(
        "target",
        ParamType.POSE,
        POSE,
        marker_type=MarkerType.POSE,
        check_target=SiteCheck.REACHABLE_GROUND,
    )
    mode = ParameterSpec("mode", ParamType.STRING, "quick", choices=("quick", "deep"))
    tries = ParameterSpec("tries", ParamType.INT, 2, minimum=1, maximum=5, choices=(1, 2, 5))
    assert_no_default_field(speed, target, mode, tries)
    skill = SkillSpec("drive", (speed, target, mode, tries), "Drive somewhere.", 60.0)
    # A skill's binding to a ROS interface is the executor's business, not the ground's.
    assert_no_default_field(skill, robot_side=("binding",))
    library = Library(
        "mars_team",
        (
            AgentSpec("rover", AgentKind.DYNAMIC, "rover_model", "The rover."),
            AgentSpec("lander", AgentKind.STATIC, "lander", "Home."),
        ),
        {"rover_model": {"drive": skill}},
    )
    back = library_from_msg(over_the_wire(library_to_msg(library)))
    assert back.name == library.name and back.agents == library.agents
    assert back.skills_of("rover") == library.skills_of("rover")


def test_the_site_map_survives_with_every_field() -> None:
    rock = Footprint("rock", Shape.CYLINDER, 9.0, 6.0, radius=1.6, height=1.8)
    ridge = Footprint("ridge", Shape.BOX, 22.0, -9.0, 0.5, 2.0, 14.0, 0.25, 3.0)
    rover = GroundRobot("science_rover", "science_rover", 1.45, 0.9)
    site = SiteModel("mars", (-40.0, 40.0, -30.0, 30.0), (rock, ridge), (rover,))
    assert_no_default_field(rock, ridge)
    assert_no_default_field(rover)
    assert_no_default_field(site)
    msg = over_the_wire(site_to_msg(site, 12.5))
    assert (msg.frame_id, msg.stamp.to_sec()) == ("map", 12.5)
    assert site_from_msg(msg) == site
    source = SiteInForce(site, "/rosmc/sim", 12.5)
    assert site_in_force_from_msg(over_the_wire(site_in_force_to_msg(source))) == source
    assert site_in_force_from_msg(wire.SiteInForce()) is None  # what the server says first


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        ({"frame_id": "odom"}, "is in frame 'odom', not 'map'"),
        ({"x_max": -50.0}, "bounds with no area"),
        ({"y_min": float("nan")}, "not finite"),
    ],
)
def test_a_site_map_the_server_cannot_check_against_is_refused(
    change: dict[str, Any], fragment: str
) -> None:
    msg = site_to_msg(SiteModel("mars", (-40.0, 40.0, -30.0, 30.0)), 0.0)
    for name, value in change.items():
        setattr(msg, name, value)
    with pytest.raises(InvalidRequest, match=fragment):
        site_from_msg(msg)


def test_an_obstacle_of_unknown_shape_is_refused() -> None:
    msg = site_to_msg(SiteModel("mars", (-40.0, 40.0, -30.0, 30.0)), 0.0)
    msg.obstacles = [wire.SiteObstacle(name="blob", shape=7)]
    with pytest.raises(InvalidRequest, match="unknown shape"):
        site_from_msg(msg)


RETURNING = PolicyInForce(
    LostLinkPolicy(
        LostLinkKind.RETURN_TO_LINK, 90.0, "navigate_to", {"speed": 0.5}, LostLinkTrigger.IDLE
    ),
    library_default=True,
    acted="returning to the last link position (18.9, -1.0) after 68 s without ground contact",
)


@pytest.mark.parametrize(
    "in_force",
    [
        PolicyInForce(),
        PolicyInForce(LostLinkPolicy(LostLinkKind.HOLD, 12.5), acted="held after 13 s"),
        PolicyInForce(
            LostLinkPolicy(
                LostLinkKind.SAFE_SKILL,
                60.0,
                "return_to_lander",
                {k: v for k, v in PARAMS.items() if k != "target"}
                | {"target": {"x": 1.0, "y": 2.0}},
            ),
        ),
        RETURNING,
    ],
)
def test_the_policy_in_force_survives_both_ways(in_force: PolicyInForce) -> None:
    msg = over_the_wire(policy_in_force_to_msg(in_force))
    assert msg.kind != wire.LostLinkPolicy.UNSAID
    assert policy_in_force_from_msg(msg) == in_force


def test_a_policy_not_said_is_none_and_unknown_numbers_are_refused() -> None:
    unsaid = over_the_wire(policy_in_force_to_msg(None))
    assert unsaid.kind == wire.LostLinkPolicy.UNSAID
    assert policy_in_force_from_msg(unsaid) is None
    with pytest.raises(InvalidRequest, match="unknown lost-link policy numbers"):
        policy_in_force_from_msg(wire.LostLinkPolicy(kind=9, after=1.0))
    with pytest.raises(InvalidRequest, match="unknown lost-link policy numbers"):
        policy_in_force_from_msg(wire.LostLinkPolicy(kind=wire.LostLinkPolicy.HOLD, when=7))
    with pytest.raises(InvalidRequest, match="positive number of seconds"):
        policy_in_force_from_msg(wire.LostLinkPolicy(kind=wire.LostLinkPolicy.HOLD, after=0.0))


def test_the_executor_snapshot_carries_the_policy_in_force_or_leaves_it_unsaid() -> None:
    snapshot = Snapshot(5.0, 4, 9, "abc", (), "idle", "", "", RETURNING, False, "d1")
    msg = over_the_wire(snapshot_to_msg("rover", snapshot))
    assert policy_in_force_from_msg(msg.policy) == RETURNING
    unsaid = over_the_wire(snapshot_to_msg("rover", dataclasses.replace(snapshot, policy=None)))
    assert unsaid.policy.kind == wire.LostLinkPolicy.UNSAID


def test_an_agent_state_whose_robot_has_not_said_its_policy_has_none() -> None:
    status = agent_status_from_msg(over_the_wire(wire.AgentState(agent="rover")))
    assert status.lost_link is None and status.policy == ""


def test_every_agent_state_field_reaches_the_agent_status() -> None:
    msg = wire.AgentState(
        agent="rover",
        telemetry=wire.Telemetry(
            agent="rover",
            frame_id="map",
            pose=pose_to_msg(POSE),
            battery=0.5,
            wifi_signal=-61.5,
            in_coverage=True,
        ),
        link=wire.LinkState(
            state=wire.LinkState.DOWN,
            last_heard=12.5,
            round_trip=0.25,
            commands_in_flight=3,
            queue_hash="9f2c",
            robot_queue_hash="77aa",
            hash_mismatch=True,
            commands_waiting=2,
            waiting_for=95.0,
            radio_dropped=212,
        ),
        current_skill_id="rover-1",
        current_status=wire.SkillStatus(value=wire.SkillStatus.SYNCWAITING),
        executor_state="waiting",
        waiting_on="drone",
        lost_link=policy_in_force_to_msg(RETURNING),
        coverage_warning="the task ends out of coverage",
        hold="return_point",
        barrier_wait=92.5,
    )
    status = agent_status_from_msg(over_the_wire(msg))
    assert_no_default_field(status)
    assert status == AgentStatus(
        agent="rover",
        link="down",
        last_heard=12.5,
        round_trip=0.25,
        commands_in_flight=3,
        hash_mismatch=True,
        queue_hash="9f2c",
        robot_queue_hash="77aa",
        commands_waiting=2,
        waiting_for=95.0,
        radio_dropped=212,
        battery=0.5,
        wifi_signal=-61.5,
        in_coverage=True,
        pose=POSE,
        current_skill="rover-1",
        current_status=SkillStatus.SYNCWAITING,
        executor_state="waiting",
        waiting_on="drone",
        lost_link=RETURNING,
        coverage_warning="the task ends out of coverage",
        hold=HoldCause.RETURN_POINT,
        barrier_wait=92.5,
    )
    nan = wire.AgentState(agent="lander", telemetry=wire.Telemetry(battery=math.nan))
    assert agent_status_from_msg(nan).battery is None


def test_executor_commands_and_barrier_signals_survive() -> None:
    skills = [full_skill(), full_skill("rover-2")]
    msg = wire.RobotCommand(
        agent="rover",
        seq=9,
        type=int(CommandKind.UPLOAD),
        skills=[skill_to_msg(s) for s in skills],
        skill_ids=["rover-1", "rover-2"],
        barriers=[barrier_to_msg(Barrier("b1", ("drone-1", "rover-1")), lambda s: s[:-2])],
        argument='{"lost_link": {"policy": "hold", "after": 5}}',
    )
    command = command_from_msg(over_the_wire(msg))
    assert command.seq == 9 and command.kind is CommandKind.UPLOAD
    assert list(command.skills) == skills
    assert command.skill_ids == ("rover-1", "rover-2")
    assert command.barriers[0].id == "b1"
    assert command.barriers[0].members == (("drone-1", "drone"), ("rover-1", "rover"))
    assert command.argument == msg.argument
    signal = Signal("rover", "b1", "rover-1", SignalKind.READY, 12.5)
    assert signal_from_msg(over_the_wire(signal_to_msg(signal))) == signal


def test_the_science_state_survives_and_reads_as_sentences() -> None:
    science = Science(
        0.85,
        2,
        (
            RegionScience("RSS A", 16.0, 9.0, 3.0, 1.0, 1, "collaborative"),
            RegionScience("RSS B", 30.0, -16.0, 3.5, 0.8, 2, ""),
        ),
    )
    assert science_from_msg(over_the_wire(science_to_msg(science))) == science
    assert science.lines() == [
        "science score 0.85: 2 stones delivered to the lander; regions discovered: RSS A, RSS B",
        "  RSS A at (16, 9): identified by both rovers, 1 stone left (best 1)",
        "  RSS B at (30, -16): not identified, 2 stones left (best 0.8)",
    ]


def test_a_coverage_grid_survives_with_every_field() -> None:
    grid = GridSpec(-9.5, -4.5, 1.0, 3, 2)
    prediction = Prediction(
        grid, (-40.0, -50.5, -60.0, -70.0, -80.0, -95.0), (True,) * 4 + (False,) * 2
    )
    msg = prediction_to_msg(prediction, "map")
    back = prediction_from_msg(msg)
    assert back.grid == grid and back.covered == prediction.covered
    assert back.signal == pytest.approx(prediction.signal)  # float32 on the wire
    assert msg.frame_id == "map"
    telemetry = wire.Telemetry(agent="rover", stamp=genpy.Time(26, 0), frame_id="map",
                               pose=wire.Pose6D(3.0, 4.0, 0.0, 0.0, 0.0, 0.0),
                               wifi_signal=-72.0, in_coverage=True)  # fmt: skip
    assert reading_from_telemetry(telemetry) == Reading("rover", 3.0, 4.0, -72.0, True, 26.0)
