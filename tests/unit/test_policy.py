"""The lost-link policy (core/skills/policy.py): checks, plain data, the command argument."""

from __future__ import annotations

import json
from typing import Any

import pytest

from rosmc_server.core import (
    AgentStatus,
    InvalidRequest,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    NotFound,
    PolicyInForce,
    Pose,
)
from rosmc_server.core.skills.policy import (
    DEFAULT_AFTER,
    ground_contact_period,
    options_argument,
    policy_from_argument,
)

HOME = LostLinkPolicy(LostLinkKind.SAFE_SKILL, 30.0, "navigate_to", {"speed": 2.0})


def test_the_default_policy_continues() -> None:
    policy = LostLinkPolicy()
    assert (policy.kind, policy.after, policy.skill, policy.params) == (
        LostLinkKind.CONTINUE,
        DEFAULT_AFTER,
        "",
        {},
    )
    assert policy.describe() == "on link loss: continue"


def test_descriptions() -> None:
    assert LostLinkPolicy(LostLinkKind.HOLD, 30).describe() == "on link loss: hold after 30 s"
    assert HOME.describe() == "on link loss: run navigate_to after 30 s, then hold"


def test_the_policy_in_force_words_the_policy_its_default_and_what_it_did() -> None:
    hold = LostLinkPolicy(LostLinkKind.HOLD, 30)
    assert PolicyInForce(hold).describe() == "on link loss: hold after 30 s"
    assert PolicyInForce(HOME, library_default=True, acted="held after 31 s").describe() == (
        "on link loss: run navigate_to after 30 s, then hold (library default); held after 31 s"
    )
    assert PolicyInForce() == PolicyInForce(LostLinkPolicy())


def test_an_agent_status_carries_the_policy_typed_and_words_it() -> None:
    in_force = PolicyInForce(HOME, acted="ran 'navigate_to' after 30 s without ground contact")
    status = AgentStatus("r1", lost_link=in_force)
    assert status.lost_link == in_force and status.policy == in_force.describe()
    assert AgentStatus("r1").lost_link is None and AgentStatus("r1").policy == ""
    assert AgentStatus("r1", lost_link=in_force).news_since(AgentStatus("r1"))
    assert not AgentStatus("r1", lost_link=in_force).news_since(status)


def test_a_policy_sent_is_taken_when_the_robot_reports_it_completed() -> None:
    sent = LostLinkPolicy(LostLinkKind.SAFE_SKILL, 30.0, "navigate_to", when=LostLinkTrigger.IDLE)
    # The server filled in the skill's defaults before sending it.
    completed = LostLinkPolicy(
        LostLinkKind.SAFE_SKILL, 30.0, "navigate_to", {"speed": 1.0}, LostLinkTrigger.IDLE
    )
    assert sent.taken_as(completed)
    assert HOME.taken_as(HOME)
    assert not HOME.taken_as(completed)  # speed 2.0 was asked for
    assert not sent.taken_as(LostLinkPolicy(LostLinkKind.SAFE_SKILL, 30.0, "navigate_to"))
    assert not sent.taken_as(LostLinkPolicy(LostLinkKind.HOLD, 30.0, when=LostLinkTrigger.IDLE))
    assert not LostLinkPolicy(LostLinkKind.HOLD, 30.0).taken_as(LostLinkPolicy(LostLinkKind.HOLD))


def test_a_kind_given_by_name_is_read() -> None:
    assert LostLinkPolicy("hold", 5.0).kind is LostLinkKind.HOLD  # type: ignore[arg-type]
    assert LostLinkKind.parse("safe_skill") is LostLinkKind.SAFE_SKILL


@pytest.mark.parametrize(
    ("fields", "needle"),
    [
        ({"kind": "panic"}, "hold, safe_skill, return_to_link, got 'panic'"),
        ({"after": 0.0}, "'after' must be a positive number"),
        ({"after": -1.0}, "'after' must be a positive number"),
        ({"after": float("nan")}, "'after' must be a positive number"),
        ({"after": float("inf")}, "'after' must be a positive number"),
        ({"after": True}, "'after' must be a positive number"),
        ({"after": "5"}, "'after' must be a positive number"),
        ({"kind": LostLinkKind.SAFE_SKILL}, "names its safe skill"),
        ({"kind": LostLinkKind.HOLD, "skill": "home"}, "runs no safe skill"),
        ({"kind": LostLinkKind.CONTINUE, "params": {"a": 1}}, "runs no safe skill"),
        ({"kind": LostLinkKind.SAFE_SKILL, "skill": "home", "params": 3}, "'params'"),
        ({"kind": LostLinkKind.SAFE_SKILL, "skill": "home", "params": {"a": object()}}, "data"),
        ({"kind": LostLinkKind.SAFE_SKILL, "skill": 7}, "skill name"),
    ],
)
def test_a_malformed_policy_is_refused(fields: dict[str, Any], needle: str) -> None:
    with pytest.raises(InvalidRequest) as caught:
        LostLinkPolicy(**fields)
    assert needle in str(caught.value)


def test_params_are_a_copy_and_poses_become_mappings() -> None:
    params: dict[str, Any] = {"target": Pose(1.0, 2.0), "route": [1, 2]}
    policy = LostLinkPolicy(LostLinkKind.SAFE_SKILL, 5, "navigate_to", params)
    params["route"].append(3)
    assert policy.params == {"target": Pose(1.0, 2.0).to_dict(), "route": [1, 2]}
    assert isinstance(policy.after, float)


@pytest.mark.parametrize(
    "policy", [LostLinkPolicy(), LostLinkPolicy(LostLinkKind.HOLD, 12.5), HOME]
)
def test_plain_data_and_the_command_argument_round_trip(policy: LostLinkPolicy) -> None:
    assert LostLinkPolicy.from_dict(json.loads(json.dumps(policy.to_dict()))) == policy
    assert policy_from_argument(options_argument(policy)) == policy


def test_the_command_argument_keeps_its_wire_form() -> None:
    """Executors of any version read it: {"lost_link": {"policy", "after", "skill", "params"}}."""
    assert json.loads(options_argument(HOME)) == {
        "lost_link": {
            "policy": "safe_skill",
            "after": 30.0,
            "skill": "navigate_to",
            "params": {"speed": 2.0},
        }
    }
    assert policy_from_argument("") == LostLinkPolicy()
    assert policy_from_argument('{"lost_link": {"policy": "hold"}}').after == DEFAULT_AFTER


@pytest.mark.parametrize(
    ("argument", "needle"),
    [
        ("{", "not valid JSON"),
        ("[1]", "must be an object with a 'lost_link' object"),
        ('{"lost_link": 3}', "must be an object with a 'lost_link' object"),
        ('{"lost_link": {"policy": 3}}', "given by name"),
        ('{"lost_link": {"policy": "hold", "whence": 3}}', "no field 'whence'"),
        ('{"lost_link": {"policy": "hold", "when": 3}}', "trigger must be given by name"),
        ('{"lost_link": {"policy": "hold", "when": "soon"}}', "silent or idle"),
        ("[" * 100_000, "not valid JSON"),
    ],
)
def test_a_malformed_argument_is_refused(argument: str, needle: str) -> None:
    with pytest.raises(InvalidRequest) as caught:
        policy_from_argument(argument)
    assert needle in str(caught.value)


def test_checked_fills_defaults_and_checks_against_the_library(shipped_library: Library) -> None:
    checked = HOME.checked(shipped_library, "drone")
    assert checked.params == {"target": {"x": 0.0, "y": 0.0, "z": 0.0, "roll": 0.0,
                                         "pitch": 0.0, "yaw": 0.0}, "speed": 2.0}  # fmt: skip
    assert checked.skill == "navigate_to" and checked.after == 30.0
    hold = LostLinkPolicy(LostLinkKind.HOLD, 3)
    assert hold.checked(shipped_library, "drone") is hold
    with pytest.raises(NotFound):
        LostLinkPolicy(LostLinkKind.SAFE_SKILL, 3, "teleport").checked(shipped_library, "drone")
    with pytest.raises(InvalidRequest):
        LostLinkPolicy(LostLinkKind.SAFE_SKILL, 3, "navigate_to", {"speed": 99.0}).checked(
            shipped_library, "drone"
        )


@pytest.mark.parametrize(
    ("afters", "period"),
    [
        ((), 2.0),  # nothing known: the slowest beat
        ((None, None), 2.0),  # continue never acts
        ((60.0,), 2.0),  # a long policy: still every 2 s, so an idle robot knows its link
        ((4.0,), 1.0),  # four beats within the policy's silence
        ((1.0,), 0.25),
        ((0.1,), 0.25),  # never faster than four a second
        ((60.0, 2.0), 0.5),  # asked and reported differ: the shorter holds until settled
        ((None, 6.0), 1.5),
    ],
)
def test_the_ground_beats_often_enough_for_the_shortest_policy(
    afters: tuple[float | None, ...], period: float
) -> None:
    assert ground_contact_period(*afters) == period


def test_only_a_policy_that_acts_has_a_silence() -> None:
    assert LostLinkPolicy(LostLinkKind.CONTINUE, 5.0).acts_after is None
    assert LostLinkPolicy(LostLinkKind.HOLD, 5.0).acts_after == 5.0
    assert HOME.acts_after == 30.0
