"""Safe lost-link behaviour by default: library defaults, the idle trigger, return to link."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rosmc_server.core import (
    InvalidRequest,
    Library,
    LibraryError,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    ParamType,
    Pose,
    SkillStatus,
)
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.skills.library import library_from_dict
from rosmc_server.core.skills.policy import options_argument, options_from_argument
from rosmc_server.executor.core import Engine, SkillType
from rosmc_server.executor.core.engine import Mode
from rosmc_server.executor.core.lost_link import LINK_MARGIN
from rosmc_server.executor.core.state_file import load_state, save_state

from .test_executor_engine import SKILL_TYPES, FakeClock, Recorder, Robot, Timed, make_skill

K = CommandKind
RETURN = LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 60.0, "goto", when=LostLinkTrigger.IDLE)


# -- the policy and the library ---------------------------------------------------
def test_the_shipped_library_returns_rovers_and_flies_the_drone_home(
    shipped_library: Library,
) -> None:
    rover = shipped_library.default_policy("manipulator_rover")
    assert rover is not None
    assert (rover.kind, rover.skill, rover.after, rover.when) == (
        LostLinkKind.RETURN_TO_LINK, "navigate_to", 60.0, LostLinkTrigger.IDLE
    )  # fmt: skip
    assert "target" not in rover.params  # the robot fills it in
    drone = shipped_library.default_policy("drone")
    assert drone is not None and drone.skill == "return_to_lander"
    assert drone.when is LostLinkTrigger.IDLE and drone.after < rover.after
    assert rover.describe() == (
        "on link loss: return to the last link position (navigate_to) "
        "after 60 s idle without a link, then hold"
    )


def policy_words(engine: Any) -> str:
    """The policy in force as the engine's snapshot reports it, in words."""
    policy = engine.snapshot().policy
    assert policy is not None, "a whole snapshot says the policy"
    return str(policy.describe())


POSE = {"type": "pose", "default": {"x": 0.0, "y": 0.0}}


def _library(lost_link: object) -> dict[str, Any]:
    return {
        "rosmc_library": 1,
        "name": "t",
        "models": {
            "rover": {
                "lost_link": lost_link,
                "skills": {
                    "go": {"parameters": {"target": POSE}},
                    "spin": {"parameters": {"a": POSE, "b": POSE}},
                },
            }
        },
        "agents": {"r": {"kind": "dynamic", "model": "rover"}},
    }


@pytest.mark.parametrize(
    ("lost_link", "needle"),
    [
        ({"policy": "return_to_link", "skill": "fly"}, "lost_link.skill: names no skill"),
        ({"policy": "return_to_link", "skill": "spin"}, "exactly one pose parameter"),
        ({"policy": "hold", "when": "later"}, "silent or idle"),
        ("hold", "must be an object"),
    ],
)
def test_a_library_with_a_bad_default_policy_is_refused(lost_link: object, needle: str) -> None:
    with pytest.raises(LibraryError) as caught:
        library_from_dict(_library(lost_link))
    assert "models.rover.lost_link" in str(caught.value) and needle in str(caught.value)


def test_a_model_without_a_default_has_none() -> None:
    library = library_from_dict(_library({"policy": "return_to_link", "skill": "go"}))
    assert library.default_policy("r") == LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, skill="go")
    data = _library(None)
    del data["models"]["rover"]["lost_link"]
    assert library_from_dict(data).default_policy("r") is None


def test_the_idle_trigger_and_the_default_flag_travel_on_the_wire() -> None:
    policy, default = options_from_argument(options_argument(RETURN, default=True))
    assert (policy, default) == (RETURN, True)
    assert options_from_argument(options_argument(RETURN)) == (RETURN, False)
    assert json.loads(options_argument(RETURN))["lost_link"]["when"] == "idle"
    with pytest.raises(InvalidRequest, match="'default' must be true or false"):
        options_from_argument('{"lost_link": {}, "default": 1}')
    assert LostLinkPolicy(LostLinkKind.HOLD).leaves_robot_out()
    assert not RETURN.leaves_robot_out()


# -- on the robot ---------------------------------------------------------------------
class Rover(Robot):
    """A robot whose pose source the test moves."""

    def __init__(self) -> None:
        self.pose: Pose | None = Pose(1.0, 2.0, 0.0, 0.0, 0.0, 0.5)
        self.clock = FakeClock()
        self.out = Recorder()
        self.engine = Engine("r1", SKILL_TYPES, self.clock, self.out, lambda: self.pose)
        self.seq = 0

    def set_policy(self, policy: LostLinkPolicy, default: bool = False) -> Any:
        return self.send(K.SET_OPTIONS, argument=options_argument(policy, default))


@pytest.fixture
def rover() -> Rover:
    Timed.instances.clear()
    return Rover()


def test_an_idle_policy_waits_for_the_robot_to_finish_and_then_returns(rover: Rover) -> None:
    rover.set_policy(RETURN)
    rover.upload(make_skill("a", params={"duration": 100.0}))
    rover.send(K.START)  # the ground was last heard here, at (1, 2)
    rover.pose = Pose(25.0, 2.0)  # the skill drives it out of coverage
    rover.run_for(90.0)
    assert rover.engine.lost_link.contingency is None  # still working: no trigger
    rover.run_for(20.0)  # done after 100 s, idle since
    assert rover.status("a") is SkillStatus.SUCCESS
    rover.run_for(45.0)
    assert rover.engine.lost_link.contingency is None  # 55 s idle without a link
    rover.run_for(5.5)
    ret = Timed.instances[-1]
    assert rover.engine.lost_link.contingency is ret
    assert ret.ctx is not None and ret.ctx.params["target"] == Pose(1.0, 2.0, 0.0, 0.0, 0.0, 0.5)
    assert rover.engine.state_name() == "contingency"
    assert "returning to the last link position (1.0, 2.0)" in policy_words(rover.engine)
    rover.run_for(2.0)  # the return skill takes one second
    assert rover.engine.mode is Mode.PAUSED
    assert policy_words(rover.engine).endswith("(done); holding")


def assert_returns_to(rover: Rover, back: Pose) -> None:
    """The rover remembers ``back`` and, left out of contact, its return skill drives there."""
    assert rover.engine.lost_link.last_link_pose == back
    rover.pose = Pose(30.0, 5.0)
    rover.run_for(61.0)
    ret = Timed.instances[-1]
    assert ret.ctx is not None and ret.ctx.params["target"] == back


def test_the_robot_returns_to_where_it_was_a_margin_before_the_last_contact(
    rover: Rover,
) -> None:
    rover.set_policy(RETURN)
    for x in range(20):  # driving out at 1 m/s, hearing the ground every second
        rover.pose = Pose(float(x), 5.0)
        rover.engine.report_acknowledged(0)
        rover.clock.now += 1.0
    # Last heard at x = 19 (perhaps already beyond the edge): it goes back LINK_MARGIN s.
    assert_returns_to(rover, Pose(19.0 - LINK_MARGIN, 5.0))


def test_a_robot_that_hears_the_ground_rarely_still_returns_a_margin_before_the_last_contact(
    rover: Rover,
) -> None:
    """Contacts seconds apart (a poor radio, a fast sim) do not send it back to the start."""
    rover.set_policy(RETURN)  # heard here, at x = 0
    for x in range(1, 20):  # driving out at 1 m/s; the robot ticks, the ground is silent
        rover.pose = Pose(float(x), 5.0)
        rover.run_for(1.0)
    rover.engine.report_acknowledged(0)  # heard once more, at x = 19
    assert_returns_to(rover, Pose(19.0 - LINK_MARGIN, 5.0))


def test_without_a_known_position_the_robot_holds(rover: Rover) -> None:
    rover.pose = None
    rover.set_policy(RETURN)
    rover.run_for(61.0)
    assert not Timed.instances and rover.engine.mode is Mode.PAUSED
    assert "no position with a link is known" in policy_words(rover.engine)


def test_a_silent_policy_still_acts_while_the_robot_works(rover: Rover) -> None:
    rover.set_policy(LostLinkPolicy(LostLinkKind.HOLD, 5.0))
    rover.upload(make_skill("a", params={"duration": 100.0}))
    rover.send(K.START)
    rover.run_for(6.0)
    assert rover.status("a") is SkillStatus.PAUSED  # the old meaning: silence alone counts


def test_continue_leaves_an_idle_robot_where_it_is(rover: Rover) -> None:
    rover.set_policy(LostLinkPolicy())
    rover.run_for(600.0)
    assert not Timed.instances and rover.engine.mode is Mode.STOPPED


def test_a_library_default_never_replaces_an_operators_choice(rover: Rover) -> None:
    assert rover.set_policy(RETURN, default=True).error == ""
    assert policy_words(rover.engine).startswith("on link loss: return")
    assert "(library default)" in policy_words(rover.engine)
    hold = LostLinkPolicy(LostLinkKind.HOLD, 5.0)
    rover.set_policy(hold)
    assert rover.set_policy(RETURN, default=True).error == ""  # taken, but not applied
    assert rover.engine.lost_link.policy == hold
    assert policy_words(rover.engine) == "on link loss: hold after 5 s"


def test_a_return_skill_without_one_pose_parameter_is_refused(rover: Rover) -> None:
    ack = rover.set_policy(LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, skill="timed"))
    assert "takes no single pose parameter" in ack.error
    assert rover.engine.lost_link.policy == LostLinkPolicy()


def test_the_default_flag_survives_a_restart(rover: Rover, tmp_path: Path) -> None:
    rover.set_policy(RETURN, default=True)
    save_state(rover.engine, tmp_path / "state.json")
    fresh = Engine("r1", {"goto": SkillType("goto", Timed, {"target": ParamType.POSE})},
                   FakeClock(), Recorder())  # fmt: skip
    load_state(fresh, tmp_path / "state.json")
    assert fresh.lost_link.policy == RETURN and fresh.lost_link.is_default


def test_work_started_while_the_robot_returns_runs_once_it_is_back(rover: Rover) -> None:
    """Contact comes back during the return drive; what waited arrives with a start: the
    robot goes on with it once back, instead of holding."""
    rover.set_policy(RETURN)
    rover.upload(make_skill("a", params={"duration": 1.0}))
    rover.send(K.START)
    rover.pose = Pose(25.0, 2.0)
    rover.run_for(61.5)  # done after 1 s, then idle a minute without a link: it drives back
    assert rover.engine.state_name() == "contingency"
    rover.upload(make_skill("home", params={"duration": 1.0}))  # in contact again
    rover.send(K.START)
    rover.run_for(2.0)  # the return ends; the start it heard meanwhile stands
    assert rover.status("home") is SkillStatus.RUNNING or rover.status("home") is (
        SkillStatus.SUCCESS
    )


def test_silence_is_counted_on_the_link_clock_not_on_mission_time() -> None:
    """A fast or loaded sim runs mission time ahead of the radio: only wall seconds of
    silence count, on the robot as on the ground."""
    Timed.instances.clear()
    mission, wall = FakeClock(), FakeClock()
    out = Recorder()
    engine = Engine("r1", SKILL_TYPES, mission, out, lambda: Pose(3.0, 4.0), link_clock=wall)
    engine.lost_link.adopt(RETURN, default=False)
    engine.lost_link.contact()
    for _ in range(1000):  # 1,000 sim seconds in 10 wall seconds (a factor of 100)
        mission.now += 1.0
        wall.now += 0.01
        engine.tick()
    assert not Timed.instances and engine.mode is not Mode.PAUSED
    for _ in range(510):  # 51 more wall seconds: 60 s idle without the ground
        mission.now += 10.0
        wall.now += 0.1
        engine.tick()
    ret = Timed.instances[-1]
    assert ret.ctx is not None and ret.ctx.params["target"] == Pose(3.0, 4.0)
    assert "after 60 s without ground contact" in policy_words(engine)
