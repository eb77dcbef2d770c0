"""The lost-link policy through ``rosmc/SetLostLinkPolicy`` requests and back (no master)."""

from __future__ import annotations

from io import BytesIO

import pytest
import rosmc.srv as srv

from rosmc_server.conversions import param_to_msg, policy_from_request, policy_to_request
from rosmc_server.core import InvalidRequest, LostLinkKind, LostLinkPolicy, Pose
from rosmc_server.core.skills.policy import DEFAULT_AFTER

POLICIES = [
    LostLinkPolicy(),
    LostLinkPolicy(LostLinkKind.HOLD, 2.5),
    LostLinkPolicy(LostLinkKind.SAFE_SKILL, 30.0, "navigate_to", {"speed": 2.0}),
    LostLinkPolicy(LostLinkKind.SAFE_SKILL, 9.0, "navigate_to", {"target": Pose(1, 2, yaw=0.5)}),
]


def _over_the_wire(request: srv.SetLostLinkPolicyRequest) -> srv.SetLostLinkPolicyRequest:
    buffer = BytesIO()
    request.serialize(buffer)
    back = srv.SetLostLinkPolicyRequest()
    back.deserialize(buffer.getvalue())
    return back


@pytest.mark.parametrize("policy", POLICIES)
def test_every_field_survives(policy: LostLinkPolicy) -> None:
    typed = {n: Pose.from_any(v, n) if isinstance(v, dict) else v for n, v in policy.params.items()}
    parameters = [param_to_msg(name, value) for name, value in typed.items()]
    request = srv.SetLostLinkPolicyRequest(agent="r1", **policy_to_request(policy, parameters))
    assert policy_from_request(_over_the_wire(request)) == policy


def test_an_empty_kind_is_continue() -> None:
    request = srv.SetLostLinkPolicyRequest(agent="r1", after=5.0)
    assert policy_from_request(request) == LostLinkPolicy(after=5.0)


def test_an_omitted_delay_is_the_default_one() -> None:
    # rosservice call /rosmc/set_lost_link_policy "{agent: r1, lost_link_policy: hold}"
    request = srv.SetLostLinkPolicyRequest(agent="r1", lost_link_policy="hold")
    assert policy_from_request(request) == LostLinkPolicy(LostLinkKind.HOLD, DEFAULT_AFTER)


@pytest.mark.parametrize(
    ("fields", "needle"),
    [
        ({"lost_link_policy": "panic", "after": 5.0}, "must be one of"),
        ({"lost_link_policy": "hold", "after": -1.0}, "'after' must be a positive"),
        ({"lost_link_policy": "hold", "after": 1.0, "safe_skill": "x"}, "runs no safe skill"),
        (
            {
                "lost_link_policy": "safe_skill",
                "after": 1.0,
                "safe_skill": "navigate_to",
                "safe_skill_parameters": [param_to_msg("target", 0.0, "RSS A")],
            },
            "cannot be bound to task markers",
        ),
    ],
)
def test_a_bad_request_is_refused(fields: dict[str, object], needle: str) -> None:
    with pytest.raises(InvalidRequest) as caught:
        policy_from_request(srv.SetLostLinkPolicyRequest(agent="r1", **fields))
    assert needle in str(caught.value)
